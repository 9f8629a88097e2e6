#!/usr/bin/env bash
# Installs, builds, and renders the Cornell box to out/cornell-box.exr and out/cornell-box.png.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
mkdir -p "$root/out"
"$root/build/spillway" render "$root/scenes/cornell-box.yaml" -o "$root/out/cornell-box.exr" "$@"
"$root/build/spillway" render "$root/scenes/cornell-box.yaml" -o "$root/out/cornell-box.png" --quiet "$@"
echo "wrote $root/out/cornell-box.exr and $root/out/cornell-box.png"
