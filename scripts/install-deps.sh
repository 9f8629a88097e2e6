#!/usr/bin/env bash
# Installs every Spillway dependency from Debian 12 packages. Idempotent: packages already
# present are left alone, so a second run costs one dpkg query.
set -euo pipefail

# What the spillway binary builds and renders with: all that render-cornell.sh installs
# (install-deps.sh --render). libgtest-dev and libopenmpi-dev are here because CMake keeps what
# it first found: a build configured without them would stay without the tests or MPI.
packages=(
  build-essential cmake pkg-config ninja-build
  libembree-dev libtbb-dev                 # ray traversal (Embree 3) and its task scheduler
  libopenimageio-dev                       # textures (lazy, mipmapped) and image output
  libopenexr-dev                           # float EXR through OpenImageIO
  libyaml-cpp-dev                          # the scene format
  libglm-dev                               # vector math shared by C++ and GLSL
  libhwy-dev                               # SIMD shading (Google Highway)
  nlohmann-json3-dev                       # --stats JSON and reading it back in tests
  libtinyobjloader-dev                     # OBJ meshes
  libtinygltf-dev                          # glTF 2.0 files
  libglfw3-dev libgl-dev libx11-dev        # the --preview window (GLFW, OpenGL, X11)
  libopenmpi-dev openmpi-bin               # distributed rendering (mpirun -np N spillway render)
  libgtest-dev                             # the test suite
  libvulkan-dev mesa-vulkan-drivers glslc glslang-tools
)
# The rest: the tests, the benchmarks and the lean OpenImageIO.
if [ "${1:-}" != "--render" ]; then
  packages+=(
    openimageio-tools                      # maketx for the production scene generator
    # What OpenImageIO is built lean with (build-lean-oiio.sh, oiio-choice.sh).
    libboost-thread-dev libboost-filesystem-dev robin-map-dev libfmt-dev libtiff-dev libjpeg-dev
    libpng-dev zlib1g-dev curl xz-utils
    xvfb x11-apps x11-utils                # the preview's test: a virtual display, xwd, xwininfo
    clang-format                           # the test that sources are formatted (.clang-format)
    vulkan-validationlayers                # every Vulkan render in the tests runs under them
    python3 python3-numpy python3-matplotlib # convergence plots
    blender                                # scripts/cycles_compare.py: glTF files in Cycles
  )
fi

# scripts/bundle.sh: the tools that make the release (patchelf, zstd) and test it in a bare root
# (debootstrap).
if [ "${1:-}" = "--bundle" ]; then packages+=(patchelf zstd debootstrap); fi
# scripts/fuzz.sh: clang with libFuzzer and the sanitizer runtimes.
if [ "${1:-}" = "--fuzz" ]; then packages+=(clang libclang-rt-dev); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}" >&2
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
