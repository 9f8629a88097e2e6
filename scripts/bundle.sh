#!/usr/bin/env bash
# Builds the release: dist/spillway-VERSION-linux-x86_64.tar.zst, a folder that runs on any x86-64
# Linux with glibc 2.36 or newer and nothing else installed (README.md, "Releases").
#
#   scripts/bundle.sh [--out DIR]      # default DIR: dist/
#
# Steps: the packages it builds with (install-deps.sh --bundle); OpenImageIO built lean from
# Debian's source (build-lean-oiio.sh); Spillway built against it (build-bundle/spillway); then
# the folder: bin/ (spillway, Open MPI's mpirun, device-bench), lib/ (every library those load
# but the C runtime, found through RUNPATH $ORIGIN/../lib), lib/openmpi3 and lib/pmix (Open MPI's
# and PMIx's components), share/ (their help texts), scenes/ (the sample scenes and the device
# bench's textured scene) and a README. Prints the archive's path and size; exits 1 when the
# archive passes 48 MiB or a library cannot be found.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dist="$root/dist"
while [ $# -gt 0 ]; do
  case "$1" in
    -h | --help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --out)
      [ $# -ge 2 ] || { echo "bundle: --out needs a folder" >&2; exit 2; }
      dist="$(realpath -m "$2")"
      shift 2
      ;;
    *) echo "bundle: unknown argument '$1' (scripts/bundle.sh [--out DIR])" >&2; exit 2 ;;
  esac
done
work="$root/build-bundle"
limit_mib=48

"$root/scripts/install-deps.sh" --bundle
"$root/scripts/build-lean-oiio.sh" "$root/build-oiio"
cmake -S "$root" -B "$work/spillway" -G Ninja -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
  -DOpenImageIO_DIR="$root/build-oiio/lib/cmake/OpenImageIO" >/dev/null
cmake --build "$work/spillway" --target spillway --parallel "$(nproc)"

version="$("$work/spillway/spillway" --version | awk '{print $2}')"
name="spillway-$version-linux-x86_64"
stage="$work/stage/$name"
rm -rf "$work/stage" && mkdir -p "$stage"/{bin,lib,share,etc}

# glibc is the C runtime every Linux has; everything else a program loads travels with it.
is_c_runtime() {
  case "$(basename "$1")" in
    ld-linux-x86-64.so.* | libc.so.* | libm.so.* | libpthread.so.* | libdl.so.* | librt.so.* | \
      libutil.so.* | libresolv.so.* | libanl.so.* | linux-vdso.so.*) return 0 ;;
  esac
  return 1
}
# Copies into lib/ every library the ELF files FILE... need, as ldd resolves them here.
copy_closure() {
  local f lib missing
  for f in "$@"; do
    missing="$(ldd "$f" | grep "not found" || true)"
    [ -z "$missing" ] || { echo "bundle: $f needs$missing" >&2; exit 1; }
    for lib in $(ldd "$f" | awk '/=>/ && $3 ~ /^\// {print $3}'); do
      is_c_runtime "$lib" && continue
      [ -f "$stage/lib/$(basename "$lib")" ] || cp -L "$lib" "$stage/lib/"
    done
  done
}

# The renderer and Open MPI's launcher (orterun, run through the mpirun wrapper below).
ompi_lib=/usr/lib/x86_64-linux-gnu/openmpi/lib
cp "$work/spillway/spillway" "$stage/bin/spillway"
cp "$(readlink -f "$(command -v orterun)")" "$stage/bin/orterun"
copy_closure "$stage/bin/spillway" "$stage/bin/orterun"

# Open MPI's components, less those for fabrics a single box or a TCP cluster has no use for
# (UCX, libfabric, InfiniBand verbs, PSM) and OpenSHMEM's: their libraries are most of Open MPI's
# closure, and Debian's own configuration turns most of them off (etc/openmpi/).
heavy='libuc[pstm]\.|libfabric\.|libibverbs\.|librdmacm\.|libpsm|libnl-|libefa\.|liboshmem\.|libhcoll'
mkdir -p "$stage/lib/openmpi3" "$stage/lib/pmix"
for c in "$ompi_lib"/openmpi3/mca_*.so; do
  needs="$(ldd "$c")" # whole, then searched: grep -q closing ldd's pipe early fails under pipefail
  grep -Eq "$heavy" <<<"$needs" && continue
  cp "$c" "$stage/lib/openmpi3/"
done
cp /usr/lib/x86_64-linux-gnu/pmix2/lib/pmix/*.so "$stage/lib/pmix/"
copy_closure "$stage"/lib/openmpi3/*.so "$stage"/lib/pmix/*.so
cp -r /usr/share/openmpi "$stage/share/openmpi"
[ -d /usr/share/pmix ] && cp -r /usr/share/pmix "$stage/share/pmix"
mkdir -p "$stage/etc/openmpi"
cp /etc/openmpi/openmpi-mca-params.conf "$stage/etc/openmpi/"
# The closure of the libraries copied above (a library's own needs), until nothing new comes.
while :; do
  before="$(ls "$stage/lib" | wc -l)"
  copy_closure "$stage"/lib/*.so*
  [ "$(ls "$stage/lib" | wc -l)" = "$before" ] && break
done

# Every ELF finds the bundle's libraries through its RUNPATH, relative to itself.
patchelf --set-rpath '$ORIGIN/../lib' "$stage/bin/spillway" "$stage/bin/orterun"
for f in "$stage"/lib/*.so*; do patchelf --set-rpath '$ORIGIN' "$f"; done
for f in "$stage"/lib/openmpi3/*.so "$stage"/lib/pmix/*.so; do patchelf --set-rpath '$ORIGIN/..' "$f"; done

# mpirun: Open MPI relocates through OPAL_PREFIX and its directory variables (the documented way);
# the processes it starts inherit them, so their components come from the bundle too.
cat >"$stage/bin/mpirun" <<'EOF'
#!/bin/sh
# Open MPI's mpirun from this release: every path it reads is inside the release.
here="$(cd "$(dirname "$0")/.." && pwd)"
export OPAL_PREFIX="$here" OPAL_EXEC_PREFIX="$here" OPAL_BINDIR="$here/bin" \
  OPAL_LIBDIR="$here/lib" OPAL_PKGLIBDIR="$here/lib/openmpi3" OPAL_DATAROOTDIR="$here/share" \
  OPAL_DATADIR="$here/share" OPAL_PKGDATADIR="$here/share/openmpi" \
  OPAL_SYSCONFDIR="$here/etc/openmpi" PMIX_INSTALL_PREFIX="$here" \
  PMIX_MCA_mca_base_component_path="$here/lib/pmix"
# Without ssh or rsh (a bare box, a container) Open MPI refuses to start even a job on this machine
# alone; it needs the agent only to reach other hosts, so name one that exists.
if [ -z "${OMPI_MCA_plm_rsh_agent:-}" ] && ! command -v ssh >/dev/null && ! command -v rsh >/dev/null; then
  export OMPI_MCA_plm_rsh_agent=false
fi
exec "$here/bin/orterun" "$@"
EOF
chmod +x "$stage/bin/mpirun"
cp "$root/scripts/device-bench.sh" "$stage/bin/device-bench"

# Scenes: the samples, and the device bench's textured many-shader scene, made here.
cp -r "$root/scenes" "$stage/scenes"
"$root/scripts/make_production_scene.py" "$stage/scenes/textured" --models 16 --triangles 40000 \
  --texture-res 128 --width 640 --height 360 --spp 16 >/dev/null
cp "$root/scripts/release-README.md" "$stage/README.md"

# Everything a program in bin/ loads must now resolve inside the bundle.
for f in "$stage/bin/spillway" "$stage/bin/orterun" "$stage"/lib/*.so* "$stage"/lib/*/*.so; do
  missing="$(ldd "$f" | grep "not found" || true)"
  [ -z "$missing" ] || { echo "bundle: $f:$(head -1 <<<"$missing")" >&2; exit 1; }
done

mkdir -p "$dist"
archive="$dist/$name.tar.zst"
tar -C "$work/stage" --owner=0 --group=0 --sort=name -cf - "$name" | zstd -19 -T0 -q -o "$archive.part" -f
mv "$archive.part" "$archive"
bytes="$(stat -c %s "$archive")"
echo "bundle: $archive: $(awk -v b="$bytes" 'BEGIN{printf "%.1f MiB", b / 1048576}'), $(ls "$stage/lib" | wc -l) libraries"
if ((bytes > limit_mib * 1048576)); then
  echo "bundle: the archive passes $limit_mib MiB" >&2
  exit 1
fi
