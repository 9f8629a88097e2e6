#!/usr/bin/env bash
# Installs, builds, and renders the Cornell box to out/cornell-box.exr and out/cornell-box.png.
# Extra arguments go to both renders (a later --spp overrides the 512 below).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# The binary alone, with its packages alone, against Debian's OpenImageIO unless the lean one is
# built (build.sh): the test suite's compile jobs, the lean build and the packages for the tests
# and benchmarks (Blender's among them) are the test command's.
SPILLWAY_FIRST_IMAGE=1 "$root/scripts/build.sh" --target spillway
mkdir -p "$root/out"
# 512 samples per pixel, not the scene's 64 (whose noise is the first thing a newcomer would see):
# about 8 times the render time, some 20 s on 2 cores. The PNG is the same render written again
# from its checkpoint (a resume with nothing left to render), bit for bit a render of its own.
state="$(mktemp -d)"
trap 'rm -rf "$state"' EXIT
scene="$root/scenes/cornell-box.yaml"
"$root/build/spillway" render "$scene" --spp 512 -o "$root/out/cornell-box.exr" \
  --checkpoint "$state/cornell-box.exr" "$@"
"$root/build/spillway" render "$scene" --spp 512 --resume "$state/cornell-box.exr" \
  -o "$root/out/cornell-box.png" --quiet "$@"
echo "wrote $root/out/cornell-box.exr and $root/out/cornell-box.png"
