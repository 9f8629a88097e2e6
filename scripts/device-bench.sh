#!/usr/bin/env bash
# Measures a machine in one command: its Vulkan devices, the three backends on the Cornell box at
# 512² and 2048² and on a textured many-shader scene, the vulkan backend's device time, traffic
# and waits, the error between the backends' images, and the cpu backend's Open MPI strong
# scaling. Needs bash and coreutils only, so it runs from an unpacked release on a bare machine.
#
#   bin/device-bench [--quick] [--out DIR] [--spillway BIN] [--mpirun BIN]
#
#   --quick     small images and few samples on at most 2 ranks: about a minute on lavapipe, for
#               the test suite (scripts/device-bench.sh --quick --spillway build/spillway)
#   --out DIR   where device-bench.json, device-bench.md and the images go (default: ./device-bench)
#
# The JSON's keys are listed in docs/performance.md ("The device bench"). Exits 1, naming the
# step, when a render fails or two renders that must be equal are not.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
quick=0 out="device-bench" spillway="" mpirun=""
# The value of option $1, the next argument $2 (refused where there is none).
value() {
  [ $# -ge 2 ] || { echo "device-bench: $1 needs a value" >&2; exit 2; }
  printf '%s' "$2"
}
while (($#)); do
  case "$1" in
    -h | --help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --quick) quick=1 ;;
    --out) out="$(value "$@")"; shift ;;
    --spillway) spillway="$(value "$@")"; shift ;;
    --mpirun) mpirun="$(value "$@")"; shift ;;
    *) echo "device-bench: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done

# In a release, bin/ holds spillway, mpirun and this script, and scenes/ sits beside bin/; in the
# source tree the script is in scripts/ and the binary in build/.
root="$(cd "$here/.." && pwd)"
if [ -z "$spillway" ]; then
  for c in "$here/spillway" "$root/build/spillway"; do [ -x "$c" ] && { spillway="$c"; break; }; done
fi
[ -x "${spillway:-}" ] || { echo "device-bench: no spillway binary (--spillway BIN)" >&2; exit 2; }
if [ -z "$mpirun" ]; then
  if [ -x "$here/mpirun" ]; then mpirun="$here/mpirun"; else mpirun="$(command -v mpirun || true)"; fi
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"
cores="$(nproc)"

fail() { echo "device-bench: $*" >&2; exit 1; }
# The first number under KEY in a JSON file that spillway wrote (one key a line), or null.
num() { local v; v="$(grep -m1 -o "\"$1\": [-0-9.eE+]*" "$2" 2>/dev/null | sed 's/.*: //')" || true; echo "${v:-null}"; }
# A figure for the table: 4 significant digits, or a dash where there is none.
fmt() { awk -v v="$1" 'BEGIN{if (v == "null" || v == "") print "–"; else printf "%.4g", v}'; }
json_string() { sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/\t/\\t/g' | awk 'BEGIN{ORS=""} NR>1{print "\\n"} {print}'; }

# The textured many-shader scene: carried by a release (scenes/textured/), made here otherwise.
textured="$root/scenes/textured/scene.yaml"
if [ ! -f "$textured" ]; then
  textured="$out/textured/scene.yaml"
  if [ ! -f "$textured" ]; then
    command -v python3 >/dev/null || fail "no scenes/textured and no python3 to make it"
    "$root/scripts/make_production_scene.py" "$out/textured" --small >/dev/null ||
      fail "making the textured scene failed"
  fi
fi

if ((quick)); then
  cases=("cornell-512 $root/scenes/cornell-box.yaml 64 64 4"
         "cornell-2048 $root/scenes/cornell-box.yaml 128 128 2"
         "textured $textured 64 64 4")
  ranks=(1 2) rank_spp=4 rank_size=64
else
  cases=("cornell-512 $root/scenes/cornell-box.yaml 512 512 64"
         "cornell-2048 $root/scenes/cornell-box.yaml 2048 2048 16"
         "textured $textured 640 360 64")
  ranks=(1 2 4 8 16) rank_spp=16 rank_size=512
fi

echo "device-bench: $spillway on $cores cores, into $out" >&2
"$spillway" devices >"$out/devices.txt" 2>&1 || true
runs="" table=""
for c in "${cases[@]}"; do
  read -r name scene w h spp <<<"$c"
  for backend in reference cpu vulkan; do
    img="$out/$name-$backend.exr" stats="$out/$name-$backend.json"
    echo "device-bench: $name ${w}x$h, $spp spp, $backend" >&2
    "$spillway" render "$scene" --backend "$backend" --width "$w" --height "$h" --spp "$spp" \
      --threads "$cores" --progress none -o "$img" --stats "$stats" 2>"$out/$name-$backend.log" ||
      fail "$name with $backend failed: $(tail -1 "$out/$name-$backend.log")"
  done
  ref="$out/$name-reference.exr"
  for backend in reference cpu vulkan; do
    stats="$out/$name-$backend.json"
    relmse=0
    if [ "$backend" != reference ]; then
      "$spillway" compare "$out/$name-$backend.exr" "$ref" --json >"$out/$name-$backend-compare.json" ||
        fail "comparing $name $backend with the reference failed"
      relmse="$(num relmse "$out/$name-$backend-compare.json")"
    fi
    runs+="${runs:+,}
    {\"scene\": \"$name\", \"backend\": \"$backend\", \"width\": $w, \"height\": $h, \"spp\": $spp,
     \"relmse_vs_reference\": $relmse, \"stats\": $(cat "$stats")}"
    row="| $name | ${w}×$h | $spp | $backend"
    for v in "$(num render_seconds "$stats")" "$(num rays_per_second "$stats")" "$relmse" \
      "$(num per_dispatch "$stats")" "$(num bytes_uploaded "$stats")" \
      "$(num bytes_downloaded "$stats")" "$(num host_wait_seconds "$stats")" \
      "$(num idle_between_submits "$stats")"; do
      row+=" | $(fmt "$v")"
    done
    table+="$row |
"
  done
done

# Strong scaling: the same cpu render on 1, 2, 4, ... ranks of one thread each, placed by Open
# MPI's default binding (a rank to a core, to a socket past two ranks); every image must equal
# the one-rank image bit for bit (spillway's distributed contract). Open MPI's log goes to
# ranks-N.log, and the failure message quotes its last lines.
scaling="" scaling_table="" base=""
if [ -n "$mpirun" ]; then
  for n in "${ranks[@]}"; do
    ((n <= cores)) || continue
    img="$out/ranks-$n.exr" stats="$out/ranks-$n.json"
    echo "device-bench: cpu on $n rank(s)" >&2
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
      "$mpirun" -np "$n" --oversubscribe "$spillway" render "$root/scenes/cornell-box.yaml" \
      --backend cpu --width "$rank_size" --height "$rank_size" --spp "$rank_spp" --threads 1 \
      --progress none -o "$img" --stats "$stats" >"$out/ranks-$n.log" 2>&1 ||
      fail "mpirun -np $n failed: $(grep -v '^-*$' "$out/ranks-$n.log" | tail -3)"
    seconds="$(num render_seconds "$stats")"
    [ -n "$base" ] || base="$seconds"
    "$spillway" compare "$img" "$out/ranks-1.exr" --json >"$out/ranks-$n-compare.json"
    awk -v m="$(num maxabs "$out/ranks-$n-compare.json")" 'BEGIN{exit !(m == 0)}' ||
      fail "$n ranks' image differs from one rank's"
    eff="$(awk -v b="$base" -v s="$seconds" -v n="$n" 'BEGIN{printf "%.3f", b / (n * s)}')"
    scaling+="${scaling:+, }{\"ranks\": $n, \"render_seconds\": $seconds, \"efficiency\": $eff}"
    scaling_table+="| $n | $(fmt "$seconds") | $eff |
"
  done
fi

cat >"$out/device-bench.json" <<EOF
{
  "spillway": "$("$spillway" --version 2>&1 | head -1 | json_string)",
  "quick": $([ $quick = 1 ] && echo true || echo false),
  "cores": $cores,
  "host": "$(uname -srm | json_string)",
  "devices": "$(json_string <"$out/devices.txt")",
  "runs": [$runs
  ],
  "mpi_strong_scaling": {"scene": "cornell-box", "width": $rank_size, "height": $rank_size,
    "spp": $rank_spp, "threads_per_rank": 1, "steps": [$scaling]}
}
EOF
{
  echo "# Device bench: $(uname -n), $cores cores"
  echo
  echo '```'
  cat "$out/devices.txt"
  echo '```'
  echo
  echo "| scene | size | spp | backend | render s | rays/s | relMSE vs reference | GPU s per dispatch | bytes up | bytes down | CPU waits on GPU, s | GPU idle between submits, s |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
  printf "%s" "$table"
  if [ -n "$scaling" ]; then
    echo
    echo "Open MPI strong scaling, cpu backend, Cornell box ${rank_size}², $rank_spp spp, one thread a rank:"
    echo
    echo "| ranks | render s | efficiency |"
    echo "|---|---|---|"
    printf "%s" "$scaling_table"
  fi
} >"$out/device-bench.md"
echo "device-bench: wrote $out/device-bench.json and $out/device-bench.md" >&2
