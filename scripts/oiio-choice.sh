# Sourced by build.sh and test.sh: which OpenImageIO Spillway builds against.
#
# Debian's binary OpenImageIO links OpenCV, FFmpeg, GDAL and OpenVDB: 260 of the 275 libraries
# build/spillway loaded, and binding them took 0.16-0.18 s of every run before the scene was read
# (`spillway --version`: 0.18 s against 0.02 s lean). So OpenImageIO is built lean from Debian's
# source package into build-oiio/ (build-lean-oiio.sh: the formats Spillway reads and writes, and
# nothing else; once, about 4 minutes on 2 cores) and every build links that. Where it cannot be
# built (no Debian mirror, no compiler for it), or with SPILLWAY_SYSTEM_OIIO=1, the build links
# Debian's OpenImageIO instead: the same images, a slower start. So does the first image
# (SPILLWAY_FIRST_IMAGE=1, render-cornell.sh) until the lean one is built: building it is about
# half the minutes a fresh machine takes to its first image.
#
# Sets oiio_cmake_args, the CMake arguments that choose it.
oiio_choose() {
  local root="$1" lean="$1/build-oiio"
  local system="${SPILLWAY_SYSTEM_OIIO:-0}"
  if [ "${SPILLWAY_FIRST_IMAGE:-0}" = 1 ] && [ ! -f "$lean/.spillway-lean-oiio" ]; then system=1; fi
  if [ "$system" != 1 ] && "$root/scripts/build-lean-oiio.sh" "$lean" >&2; then
    oiio_cmake_args=(-DOpenImageIO_DIR="$lean/lib/cmake/OpenImageIO")
  else
    [ "$system" = 1 ] ||
      echo "build: OpenImageIO could not be built lean; linking Debian's (every run starts 0.16 s later)" >&2
    oiio_cmake_args=(-UOpenImageIO_DIR)
  fi
}
