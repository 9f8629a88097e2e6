#!/usr/bin/env bash
# Installs, builds, and runs every test (GoogleTest through ctest), twice: the Release build in
# build/, then the same suite built with clang under AddressSanitizer, UndefinedBehaviorSanitizer
# and LeakSanitizer in build-asan/ (the fuzzing corpus's kept inputs are replayed in both).
#   scripts/test.sh            both
#   scripts/test.sh --release  the Release suite only (quicker, while working)
#   scripts/test.sh --asan     the sanitized suite only
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
mode="${1:-all}"
# Lavapipe: as many worker threads as cores (its default can oversubscribe small machines).
export LP_NUM_THREADS="${LP_NUM_THREADS:-$(nproc)}"
# Cycles' renders of the suite's glTF files, kept by a hash of their inputs
# (scripts/cycles_compare.py's CyclesCache): the sanitized run reuses the Release run's, since
# Blender is the same program under both and only Spillway's side is sanitized.
export SPILLWAY_CYCLES_CACHE="${SPILLWAY_CYCLES_CACHE:-$root/build/cycles-cache}"
# What tests make once for this run and share (runCached in tests/test_util.h: the convergence
# tests' high-spp references): one folder for this run's two suites, removed when it ends, so no
# run reads what another tree made.
if [ -z "${SPILLWAY_TEST_CACHE:-}" ]; then
  SPILLWAY_TEST_CACHE="$(mktemp -d "${TMPDIR:-/tmp}/spillway-test-cache.XXXXXX")"
  trap 'rm -rf "$SPILLWAY_TEST_CACHE"' EXIT
fi
export SPILLWAY_TEST_CACHE

if [ "$mode" = all ] || [ "$mode" = --release ]; then
  "$root/scripts/build.sh"
  ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)" --timeout 900
fi

if [ "$mode" = all ] || [ "$mode" = --asan ]; then
  "$root/scripts/install-deps.sh" --fuzz
  . "$root/scripts/oiio-choice.sh"
  oiio_choose "$root"
  CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSPILLWAY_SANITIZE=ON "${oiio_cmake_args[@]}" >/dev/null
  cmake --build "$root/build-asan" --parallel "$(nproc)"
  # Any sanitizer report fails the test it happens in (the process aborts). Two exceptions, both
  # in libraries: OpenImageIO's TextureSystem::destroy frees with another size than it allocated
  # (new_delete_type_mismatch; only the TextureLookup tests' oracle makes one), and LeakSanitizer ignores the libraries' own process-lifetime
  # allocations (tests/fuzz/lsan.supp).
  asan="abort_on_error=1:strict_string_checks=1:new_delete_type_mismatch=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
  export LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0"
  # Drivers are opened and closed again inside the process: the Vulkan loader closes lavapipe
  # and the validation layer at vkDestroyInstance, GLFW closes Mesa's OpenGL driver at
  # glfwTerminate, Open MPI closes its components at MPI_Finalize. Once a library is unmapped,
  # LeakSanitizer can no longer see its globals and reports what they pointed to as leaked, from
  # an "<unknown module>" that no suppression can name (Mesa 22.3.6: 128 bytes per Vulkan
  # instance). tests/sanitize/keep_modules.c, preloaded into every process of the run, makes
  # dlclose() keep modules mapped: what they still hold at exit stays reachable, and their own
  # real leaks are still reported, by name.
  export LD_PRELOAD="$root/build-asan/libspillway_keep_modules.so${LD_PRELOAD:+ $LD_PRELOAD}"
  # Every test, LeakSanitizer on. The `long-statistics` group takes 4x fewer samples here
  # (kSanitizedFewer in tests/test_util.h; its tolerances are computed from the samples): at the
  # Release run's counts it took 259, 251 and 123 s under ASan, 64 s together now.
  ASAN_OPTIONS="detect_leaks=1:$asan" ctest --test-dir "$root/build-asan" --output-on-failure \
    --parallel "$(nproc)" --timeout 900
fi
