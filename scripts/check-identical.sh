#!/usr/bin/env bash
# Proves that the working tree renders the same images, bit for bit, as another revision:
#   scripts/check-identical.sh [REVISION]     (default: HEAD)
# For a change that must not alter any image (a refactoring, a move, a rename). It builds
# REVISION once in a cached copy (under ${SPILLWAY_IDENTICAL_CACHE:-/tmp/spillway-identical}),
# builds the working tree in build/, renders the Cornell box, scenes/every-model.yaml (Lambert,
# Conductor and Dielectric, a Layered image texture, thin lens, Gaussian filter), scenes/open-box-lights.yaml
# and, where they have been made, the in-core benchmark's textured scene and the glTF test files
# (out/gltf/*.glb) with both binaries on
# every backend and pipeline variant below, and compares the pixels (`spillway compare` says
# "images identical" only when every value is equal). Exit 0 when all are identical, 1 when any
# differs; the Vulkan variants are skipped, and said so, where no Vulkan device exists.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
rev="${1:-HEAD}"
sha="$(git -C "$root" rev-parse --verify "$rev^{commit}")"
cache="${SPILLWAY_IDENTICAL_CACHE:-/tmp/spillway-identical}"
base="$cache/$sha"

if [[ ! -x "$base/build/spillway" ]]; then
    echo "building $rev ($sha) in $base"
    rm -rf "$base"
    mkdir -p "$cache"
    mkdir -p "$base"
    git -C "$root" archive "$sha" | tar -x -C "$base"
    cmake -S "$base" -B "$base/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF >/dev/null
    cmake --build "$base/build" --parallel "$(nproc)" --target spillway >/dev/null
fi
echo "building the working tree in build/"
"$root/scripts/build.sh" >/dev/null

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

variants=(
    "reference|--backend reference"
    "cpu|--backend cpu"
    "cpu-full-rays|--backend cpu --ray-format full"
    "cpu-spilled|--backend cpu --memory-budget 0.001 --bin-exponent 10"
    "cpu-unsorted|--backend cpu --ray-sort off --hit-sort off"
    "vulkan|--backend vulkan"
    "vulkan-megakernel|--backend vulkan --shading megakernel"
)
have_vulkan=1
"$root/build/spillway" devices 2>/dev/null | grep -q usable || have_vulkan=0

# The many-shader textured scene (64 shaders, 7 MIP-mapped 8-bit images each) too where
# `scripts/bench.py incore` has made it.
scenes=(scenes/cornell-box.yaml scenes/every-model.yaml scenes/open-box-lights.yaml)
[[ -f "$root/out/incore-textured/scene.yaml" ]] && scenes+=(out/incore-textured/scene.yaml)
# And the glTF files `scripts/cycles_compare.py --make-test-files out/gltf` makes (materials,
# images, a normal map, an emission image), where they have been made.
for f in "$root"/out/gltf/*.glb; do [[ -f $f ]] && scenes+=("out/gltf/$(basename "$f")"); done

failed=0
for scene in "${scenes[@]}"; do
    for v in "${variants[@]}"; do
        name="${v%%|*}"
        read -r -a flags <<<"${v#*|}"
        if [[ $name == vulkan* && $have_vulkan == 0 ]]; then
            echo "skipped    $scene $name (no Vulkan device)"
            continue
        fi
        tag="$(basename "${scene%.*}")-$name"
        if ! (cd "$root" && "$base/build/spillway" render "$scene" --spp 16 --seed 7 --quiet "${flags[@]}" -o "$out/$tag-base.exr" 2>/dev/null); then
            echo "skipped    $scene $name ($rev cannot render it: a scene newer than the revision)"
            continue
        fi
        (cd "$root" && "$root/build/spillway" render "$scene" --spp 16 --seed 7 --quiet "${flags[@]}" -o "$out/$tag-new.exr")
        if "$root/build/spillway" compare "$out/$tag-new.exr" "$out/$tag-base.exr" | grep -q "images identical"; then
            echo "identical  $scene $name"
        else
            echo "DIFFERENT  $scene $name"
            failed=1
        fi
    done
done
if [[ $failed == 1 ]]; then
    echo "the working tree's images differ from $rev's"
    exit 1
fi
echo "every image is bit-identical to $rev's"
