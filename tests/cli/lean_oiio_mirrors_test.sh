#!/usr/bin/env bash
# scripts/build-lean-oiio.sh fetches OpenImageIO's source from the mirrors apt is configured
# with, in apt's order (sources.list, then sources.list.d's one-line .list and deb822 .sources
# files), the security archive left out and deb.debian.org last. Run by ctest as
# Scripts.LeanOiioFetchesFromAptsMirrors, against an apt configuration of its own (APT_CONFIG).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/parts"
cat >"$dir/apt.conf" <<CONF
Dir::Etc::sourcelist "$dir/sources.list";
Dir::Etc::sourceparts "$dir/parts";
CONF
cat >"$dir/sources.list" <<'LIST'
# a comment
deb [arch=amd64 signed-by=/k.gpg] http://mirror.example.com/debian/ bookworm main
deb http://security.example.com/debian-security bookworm-security main
LIST
echo "deb-src file:///srv/local-cache/debian bookworm main" >"$dir/parts/local.list"
printf 'Types: deb\nURIs: https://company.example.com/debian http://mirror.example.com/debian\n' \
  >"$dir/parts/company.sources"
expected="http://mirror.example.com/debian
file:///srv/local-cache/debian
https://company.example.com/debian
http://deb.debian.org/debian"
got="$(APT_CONFIG="$dir/apt.conf" "$root/scripts/build-lean-oiio.sh" --mirrors)"
if [ "$got" != "$expected" ]; then
  printf 'build-lean-oiio.sh --mirrors printed\n%s\nnot\n%s\n' "$got" "$expected" >&2
  exit 1
fi
# No mirror configured at all: deb.debian.org alone.
: >"$dir/sources.list"; rm -f "$dir/parts"/*
got="$(APT_CONFIG="$dir/apt.conf" "$root/scripts/build-lean-oiio.sh" --mirrors)"
[ "$got" = "http://deb.debian.org/debian" ] || { echo "with no mirror: $got" >&2; exit 1; }
echo "build-lean-oiio.sh takes apt's mirrors in apt's order"
