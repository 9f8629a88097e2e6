#!/usr/bin/env bash
# Proves a release runs on a bare Linux box, without a GPU: unpacks it into a Debian root that has
# none of Spillway's dependencies (debootstrap --variant=minbase, made once into
# build-bundle/bare-root) and there checks, in order:
#   1. ldd resolves every library of every program and library in the release;
#   2. `spillway devices` runs, and says why it picks what it picks, with no Vulkan driver;
#   3. the Cornell box renders with reference, and every sample scene (scenes/*.yaml) with cpu,
#      each equal bit for bit to the build tree's render (build/spillway, scripts/build.sh);
#   4. mpirun -np 2 from the release equals one process, bit for bit;
#   5. a glTF file with image textures renders, equal to the build tree's render;
#   6. with the host's lavapipe installed into the root the way a GPU driver is (its ICD manifest
#      and libraries in the system folders), `devices` lists it and vulkan renders the Cornell box
#      equal to the build tree's; and the device bench's --quick run passes from the release.
# Needs root (chroot, mount). Exits 1 naming what is missing or differs.
#
#   scripts/test-bundle.sh [dist/spillway-VERSION-linux-x86_64.tar.zst]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
case "${1:-}" in
  -h | --help) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
esac
archive="${1:-$(ls -t "$root"/dist/spillway-*-linux-x86_64.tar.zst 2>/dev/null | head -1 || true)}"
[ -f "$archive" ] || { echo "test-bundle: no release (run scripts/bundle.sh)" >&2; exit 2; }
archive="$(realpath "$archive")"
host_spillway="$root/build/spillway"
[ -x "$host_spillway" ] || { echo "test-bundle: no build/spillway (run scripts/build.sh)" >&2; exit 2; }
[ "$(id -u)" = 0 ] || { echo "test-bundle: needs root (chroot)" >&2; exit 2; }

bare="$root/build-bundle/bare-root"
if [ ! -x "$bare/bin/bash" ]; then
  echo "test-bundle: making a bare Debian 12 root in $bare (debootstrap, a few minutes)" >&2
  rm -rf "$bare.tmp"
  debootstrap --variant=minbase bookworm "$bare.tmp" http://deb.debian.org/debian >/dev/null
  mv "$bare.tmp" "$bare"
fi
# The root is used through a throw-away copy, so a driver installed in step 6 never stays.
jail="$(mktemp -d /tmp/spillway-bare.XXXXXX)"
work="$(mktemp -d /tmp/spillway-test-bundle.XXXXXX)"
cleanup() {
  for m in dev/shm dev sys proc; do mountpoint -q "$jail/$m" && umount -l "$jail/$m"; done
  rm -rf "$jail" "$work"
}
trap cleanup EXIT
cp -a "$bare/." "$jail/"
mount -t proc proc "$jail/proc"
mount -t sysfs sysfs "$jail/sys"
mount --bind /dev "$jail/dev"
mount -t tmpfs tmpfs "$jail/dev/shm"

fail() { echo "test-bundle: FAIL: $*" >&2; exit 1; }
pass() { echo "test-bundle: ok: $*" >&2; }
in_jail() { chroot "$jail" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root "$@"; }
# 0 when A and B are equal pixel for pixel (spillway compare, maximum absolute difference 0).
same() {
  local m
  m="$("$host_spillway" compare "$1" "$2" --json | grep -o '"maxabs": [-0-9.eE+]*' | sed 's/.*: //')"
  awk -v m="$m" 'BEGIN{exit !(m == 0)}'
}

# The root must not have what the release brings.
for lib in libembree3 libOpenImageIO libvulkan libmpi libtbb libyaml-cpp libstdc++ libglfw; do
  ! ls "$jail"/usr/lib/x86_64-linux-gnu/"$lib".so* >/dev/null 2>&1 ||
    [ "$lib" = libstdc++ ] || fail "the bare root already has $lib"
done
tar -C "$jail/opt" -xf "$archive" --zstd
name="$(basename "$archive" .tar.zst)"
opt="/opt/$name"
[ -x "$jail$opt/bin/spillway" ] || fail "$name/bin/spillway is not in the release"

# 1. Every library resolves inside the release (or is the C runtime, which the root has).
while read -r f; do
  missing="$(in_jail ldd "${f#"$jail"}" 2>&1 | grep "not found" || true)"
  [ -z "$missing" ] || fail "${f#"$jail"} needs$(echo "$missing" | head -1)"
done < <(find "$jail$opt/bin" "$jail$opt/lib" -type f \( -name '*.so*' -o -perm -u+x \) \
  ! -name '*.sh' ! -name mpirun ! -name device-bench)
pass "ldd resolves every library in the release"

# 2. devices, with no Vulkan driver installed: exit 1 (no device), saying what auto takes and why.
status=0
out="$(in_jail "$opt/bin/spillway" devices 2>&1)" || status=$?
[ "$status" = 1 ] && grep -q -- "--backend auto takes cpu: no Vulkan device" <<<"$out" ||
  fail "devices without a driver (exit $status): $out"
pass "spillway devices without a driver: $(echo "$out" | tail -1)"

render_args=(--width 96 --height 96 --spp 8 --threads 2 --progress none)
# 3. The Cornell box with reference, and every sample scene with cpu, against the build tree's.
bundle_render() { # SCENE BACKEND OUT: the release's render, in the root
  in_jail sh -c "cd $opt && bin/spillway render scenes/$1 --backend $2 ${render_args[*]} -o $3" ||
    fail "the release's $2 render of $1 failed"
}
host_render() { # SCENE BACKEND OUT
  "$host_spillway" render "$root/scenes/$1" --backend "$2" "${render_args[@]}" -o "$3" 2>/dev/null
}
runs=("cornell-box.yaml reference")
for scene in "$root"/scenes/*.yaml; do runs+=("$(basename "$scene") cpu"); done
for r in "${runs[@]}"; do
  read -r scene backend <<<"$r"
  host_render "$scene" "$backend" "$work/host.exr"
  bundle_render "$scene" "$backend" /tmp/bundle.exr
  same "$jail/tmp/bundle.exr" "$work/host.exr" ||
    fail "the release's $backend render of $scene differs from build/spillway's"
  pass "$scene, $backend: equal to build/spillway's"
done
bundle_render cornell-box.yaml cpu /tmp/cpu.exr # one process, for step 4

# 4. Two ranks through the release's mpirun equal one process.
in_jail sh -c "cd $opt && OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
  bin/mpirun -np 2 --oversubscribe bin/spillway render scenes/cornell-box.yaml --backend cpu \
  --width 96 --height 96 --spp 8 --threads 1 --progress none -o /tmp/mpi.exr" ||
  fail "mpirun -np 2 from the release failed"
same "$jail/tmp/mpi.exr" "$jail/tmp/cpu.exr" || fail "mpirun -np 2 differs from one process"
pass "mpirun -np 2 from the release: equal to one process"

# 5. A glTF file with image textures (made by the project's own generator).
gltf_dir="$root/out/gltf"
[ -f "$gltf_dir/textured.glb" ] ||
  python3 "$root/scripts/cycles_compare.py" --make-test-files "$gltf_dir" >/dev/null
cp "$gltf_dir/textured.glb" "$jail/tmp/"
"$host_spillway" render "$gltf_dir/textured.glb" "${render_args[@]}" --backend cpu \
  -o "$work/host-gltf.exr" 2>/dev/null
in_jail "$opt/bin/spillway" render /tmp/textured.glb "${render_args[@]}" --backend cpu \
  -o /tmp/gltf.exr || fail "the release's glTF render failed"
same "$jail/tmp/gltf.exr" "$work/host-gltf.exr" || fail "the glTF render differs from build/spillway's"
pass "textured glTF file: equal to build/spillway's"

# 6. lavapipe installed as a driver is: its manifest and its libraries in the root's system folders.
icd="$(ls /usr/share/vulkan/icd.d/lvp_icd.x86_64.json)"
driver="$(grep -o '"library_path": *"[^"]*"' "$icd" | sed 's/.*: *"//; s/"$//')"
mkdir -p "$jail/usr/share/vulkan/icd.d"
cp "$icd" "$jail/usr/share/vulkan/icd.d/"
for lib in "$driver" $(ldd "$driver" | awk '/=>/ && $3 ~ /^\// {print $3}'); do
  [ -e "$jail$lib" ] || { mkdir -p "$jail$(dirname "$lib")"; cp -L "$lib" "$jail$lib"; }
done
out="$(in_jail "$opt/bin/spillway" devices 2>&1)" || fail "devices with lavapipe: $out"
grep -q llvmpipe <<<"$out" || fail "devices does not list lavapipe: $out"
host_render cornell-box.yaml vulkan "$work/host-vulkan.exr"
bundle_render cornell-box.yaml vulkan /tmp/vulkan.exr
same "$jail/tmp/vulkan.exr" "$work/host-vulkan.exr" ||
  fail "the release's vulkan render differs from build/spillway's"
pass "Cornell box, vulkan on lavapipe: equal to build/spillway's"
in_jail sh -c "cd /tmp && $opt/bin/device-bench --quick --out /tmp/bench" >"$work/bench.log" 2>&1 ||
  fail "device-bench --quick from the release: $(tail -2 "$work/bench.log")"
pass "device-bench --quick from the release: $(grep -c '^| ' "$jail/tmp/bench/device-bench.md") table rows"
echo "test-bundle: $name passes in a bare Debian 12 root" >&2
