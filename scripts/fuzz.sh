#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz/) with clang, ASan and UBSan in build-fuzz/ and runs
# each for SECONDS (default 60), all at once: scripts/fuzz.sh [SECONDS [NAME...]] (NAME: scene,
# obj, gltf, checkpoint; default all four). The working corpus grows
# in build-fuzz/corpus/NAME (seeded from tests/fuzz/seeds/NAME); an input that crashes, hangs
# (10 s) or leaks is written to tests/fuzz/crashers/NAME/, where the normal suite replays it.
# Prints each run's executions, coverage and findings; exits 1 if any harness found something.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(scene obj gltf checkpoint)
"$root/scripts/install-deps.sh" --fuzz
build="$root/build-fuzz"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DSPILLWAY_FUZZ=ON -DBUILD_TESTING=OFF >/dev/null
cmake --build "$build" --parallel "$(nproc)" --target "${names[@]/%/_fuzzer}"
# LeakSanitizer: oneTBB's and OpenImageIO's process-lifetime singletons are not leaks of ours.
# The slow unwinder follows allocations through libstdc++, which has no frame pointers: with the
# fast one, a string that OpenImageIO 2.4's PNG reader leaks when libpng longjmps out of a
# truncated image's rows ends its stack at std::string, and no suppression can name it.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:new_delete_type_mismatch=0:fast_unwind_on_malloc=0}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0}"
# Every harness at once, then their reports.
for name in "${names[@]}"; do
  corpus="$build/corpus/$name"
  crashers="$root/tests/fuzz/crashers/$name"
  mkdir -p "$corpus" "$crashers"
  echo "== $name: ${seconds} s" >&2
  dict=()
  [ -f "$root/tests/fuzz/$name.dict" ] && dict=(-dict="$root/tests/fuzz/$name.dict")
  ( status=0
    "$build/${name}_fuzzer" "$corpus" "$root/tests/fuzz/seeds/$name" -max_total_time="$seconds" "${dict[@]}" \
      -timeout=10 -rss_limit_mb=4096 -max_len=65536 -print_final_stats=1 -artifact_prefix="$crashers/" \
      >"$build/$name.log" 2>&1 || status=$?
    echo "$status" >"$build/$name.status" ) &
done
wait
found=0
for name in "${names[@]}"; do
  log="$build/$name.log"
  status="$(cat "$build/$name.status")"
  echo "== $name" >&2
  grep -E '^#[0-9]+[[:space:]]+(INITED|DONE)' "$log" >&2 || true
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)' "$log" >&2 || true
  if [ "$status" -ne 0 ]; then
    found=1
    echo "$name: FOUND a defect (exit $status); the input is in tests/fuzz/crashers/$name, the log in $log" >&2
    grep -E 'ERROR|SUMMARY|unexpected exception' "$log" | head -5 >&2 || true
  else
    echo "$name: nothing found; corpus $(ls "$build/corpus/$name" | wc -l) inputs" >&2
  fi
done
exit "$found"
