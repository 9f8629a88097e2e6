#!/usr/bin/env bash
# Installs the Debian packages Spillway needs (if missing), builds OpenImageIO lean once
# (oiio-choice.sh) and builds Spillway in build/ (Release): every target, or those the arguments
# name (they go to `cmake --build`: render-cornell.sh passes --target spillway, the binary alone,
# with SPILLWAY_FIRST_IMAGE=1: the binary's packages only, and Debian's OpenImageIO unless the
# lean one is built already).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
# SPILLWAY_FIRST_IMAGE=1 (render-cornell.sh): the packages the binary needs, no more.
if [ "${SPILLWAY_FIRST_IMAGE:-0}" = 1 ]; then
  "$root/scripts/install-deps.sh" --render
else
  "$root/scripts/install-deps.sh"
fi
. "$root/scripts/oiio-choice.sh"
oiio_choose "$root"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${oiio_cmake_args[@]}" >/dev/null
cmake --build "$root/build" --parallel "$(nproc)" "$@"
