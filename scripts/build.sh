#!/usr/bin/env bash
# Installs the Debian packages Spillway needs (if missing), builds OpenImageIO lean once
# (oiio-choice.sh) and builds Spillway in build/ (Release): every target, or those the arguments
# name (they go to `cmake --build`: render-cornell.sh passes --target spillway, the binary alone).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
. "$root/scripts/oiio-choice.sh"
oiio_choose "$root"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${oiio_cmake_args[@]}" >/dev/null
cmake --build "$root/build" --parallel "$(nproc)" "$@"
