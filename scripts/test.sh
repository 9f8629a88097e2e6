#!/usr/bin/env bash
# Installs, builds, and runs every test (GoogleTest through ctest).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
# Lavapipe: as many worker threads as cores (its default can oversubscribe small machines).
export LP_NUM_THREADS="${LP_NUM_THREADS:-$(nproc)}"
ctest --test-dir "$root/build" --output-on-failure --parallel "$(nproc)" --timeout 900
