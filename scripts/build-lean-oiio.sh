#!/usr/bin/env bash
# Builds OpenImageIO lean, for every build (oiio-choice.sh) and the release bundle: from Debian's
# source package, with the image formats Spillway reads and writes and nothing else (formats=,
# below: OpenEXR, TIFF, PNG, JPEG, Radiance HDR, and the uncompressed PNM, Targa and BMP that
# sample scenes and asset libraries' textures come in; none of them needs a library of its own
# beyond zlib, libpng, libjpeg, libtiff and OpenEXR), so nothing loads the OpenCV, FFmpeg, GDAL,
# OpenVDB and codec closure that Debian's binary package links.
#
#   scripts/build-lean-oiio.sh PREFIX      # installs into PREFIX (lib/, include/, lib/cmake/)
#   scripts/build-lean-oiio.sh --mirrors   # prints the archive roots it fetches from, in order
#
# The source is Debian's openimageio package, fetched from the Debian mirrors apt is configured
# with (its sources.list and sources.list.d, as `apt-config` names them: a company mirror or a
# local cache works as apt does), then from deb.debian.org. Bookworm's own source (2.4.7.1) is
# tried first; the Debian mirror this project's machines reach serves only trixie's (2.5.18.0),
# so that one is the fallback, pinned by its SHA-256 from trixie's Sources index. Either builds
# against bookworm's libraries. Set OIIO_TARBALL to a Debian orig tarball already on disk to skip
# the download. Idempotent: a PREFIX that already holds this build is left alone.
set -euo pipefail
# The archive roots apt fetches from, in its configuration's order, the security archive aside
# (it holds no source of this package); deb.debian.org last.
apt_mirrors() {
  local list="/etc/apt/sources.list" parts="/etc/apt/sources.list.d/"
  eval "$(apt-config shell list Dir::Etc::sourcelist/f parts Dir::Etc::sourceparts/d \
    2>/dev/null)" || true
  local one_line='s/^deb(-src)?[[:space:]]+(\[[^]]*\][[:space:]]+)?([^[:space:]]+).*/\3/p'
  {
    cat "$list" "$parts"/*.list 2>/dev/null | sed -nE "$one_line"
    cat "$parts"/*.sources 2>/dev/null | sed -n 's/^URIs:[[:space:]]*//p' | tr ' ' '\n'
    echo "http://deb.debian.org/debian"
  } | grep -E '^(https?|file)://' | grep -v -- '-security/*$' | sed 's:/*$::' |
    awk '!seen[$0]++' || true
}
mapfile -t mirrors < <(apt_mirrors)
if [ "${1:-}" = "--mirrors" ]; then printf '%s\n' "${mirrors[@]}"; exit 0; fi
prefix="$(realpath -m "${1:?usage: build-lean-oiio.sh PREFIX}")"
work="$prefix.build"
stamp="$prefix/.spillway-lean-oiio"
formats="openexr tiff png jpeg hdr pnm targa bmp"
# Built as Debian builds it (CMAKE_BUILD_TYPE=None, -O2, NDEBUG not defined), so it behaves as
# Debian's library does: a Release build (NDEBUG) raises any ImageCache bound under 10 MB to 10 MB,
# and --texture-cache 1 would hold 10 MiB.
flags="-O2"
if [ -f "$stamp" ] && [ "$(tail -1 "$stamp")" = "$formats | $flags" ]; then
  echo "build-lean-oiio: $prefix is built ($(head -1 "$stamp"))"
  exit 0
fi

candidates=(
  # version                 sha256 of openimageio_VERSION.orig.tar.xz (bookworm's and trixie's .dsc)
  "2.4.7.1+dfsg  9c9cfe65acd55e14d12344009f30515c0d336b96976af2a2ea18a695a5a1c930"
  "2.5.18.0+dfsg 0dc2185aac5e01a2e5a1a804f558c1190ea048650a7fedef1033a1616abcac80"
)
mkdir -p "$work"
tarball="${OIIO_TARBALL:-}"
if [ -z "$tarball" ]; then
  for c in "${candidates[@]}"; do
    read -r version sha <<<"$c"
    file="$work/openimageio_${version}.orig.tar.xz"
    for mirror in "${mirrors[@]}"; do
      [ -f "$file" ] && break
      url="$mirror/pool/main/o/openimageio/openimageio_${version/+/%2b}.orig.tar.xz"
      curl -fsS -o "$file.part" "$url" 2>/dev/null && mv "$file.part" "$file" || {
        rm -f "$file.part"; echo "build-lean-oiio: $url is not served; trying the next" >&2; }
    done
    [ -f "$file" ] || continue
    if [ "$(sha256sum "$file" | cut -d' ' -f1)" != "$sha" ]; then
      echo "build-lean-oiio: $file does not match its SHA-256 $sha" >&2; rm -f "$file"; exit 1
    fi
    tarball="$file"; break
  done
fi
[ -n "$tarball" ] || {
  echo "build-lean-oiio: no OpenImageIO source package could be fetched" >&2; exit 1; }

src="$work/src"
rm -rf "$src" "$work/build" "$prefix" && mkdir -p "$src"
tar -xf "$tarball" -C "$src" --strip-components=1

# Every format plugin off but those above; the null reader too (a scene must never open an image
# that is not there).
off=()
for dir in "$src"/src/*.imageio; do
  name="$(basename "$dir" .imageio)"
  [[ " $formats " == *" $name "* ]] || off+=("-DENABLE_${name}=OFF")
done
deps_off=()
for pkg in OpenColorIO OpenCV TBB DCMTK FFmpeg GIF Libheif LibRaw OpenJPEG OpenVDB Ptex WebP \
  Freetype Nuke R3DSDK Qt5 Qt6 OpenGL Python pybind11 libuhdr JXL; do
  deps_off+=("-DENABLE_${pkg}=OFF")
done

cmake -S "$src" -B "$work/build" -G Ninja \
  -DCMAKE_BUILD_TYPE=None -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib \
  -DOIIO_BUILD_TOOLS=OFF -DOIIO_BUILD_TESTS=OFF -DBUILD_DOCS=OFF -DINSTALL_DOCS=OFF \
  -DINSTALL_FONTS=OFF -DUSE_PYTHON=OFF -DUSE_QT=OFF -DEMBEDPLUGINS=ON -DUSE_CCACHE=OFF \
  -DSTOP_ON_WARNING=OFF -DBUILD_MISSING_FMT=OFF -DBUILD_MISSING_ROBINMAP=OFF \
  -DCMAKE_INSTALL_RPATH='$ORIGIN' \
  "${deps_off[@]}" "${off[@]}" >"$work/configure.log"
cmake --build "$work/build" --parallel "$(nproc)"
cmake --install "$work/build" >/dev/null
rm -rf "$src" "$work/build"   # 170 MB; the source tarball stays, for a rebuild without the network
printf '%s\n%s\n' "$(basename "$tarball")" "$formats | $flags" >"$stamp"
echo "build-lean-oiio: installed $(basename "$tarball") into $prefix"
