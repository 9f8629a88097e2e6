#!/usr/bin/env bash
# Installs, builds, and renders the Cornell box to out/cornell-box.exr and out/cornell-box.png.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# The binary alone: the test suite's 700 s of compile jobs are the test command's to build.
"$root/scripts/build.sh" --target spillway
mkdir -p "$root/out"
"$root/build/spillway" render "$root/scenes/cornell-box.yaml" -o "$root/out/cornell-box.exr" "$@"
"$root/build/spillway" render "$root/scenes/cornell-box.yaml" -o "$root/out/cornell-box.png" --quiet "$@"
echo "wrote $root/out/cornell-box.exr and $root/out/cornell-box.png"
