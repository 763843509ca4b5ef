#!/usr/bin/env bash
# The sanitizer pass (not part of ./dev.sh test: see docs/robustness.md, "Time"):
#   tests/sanitize.sh [FUZZ_SECONDS]
# builds everything with AddressSanitizer and UndefinedBehaviorSanitizer in build-asan (g++,
# -DPLUME_SANITIZE=ON), runs the whole suite there, then every reader's fuzz target for
# FUZZ_SECONDS each (default 5; tests/fuzz/run.sh). Any memory error, undefined operation, leak or
# fuzz finding fails it.
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-5}

jobs=$(nproc)
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DPLUME_SANITIZE=ON >/dev/null
cmake --build build-asan -j"$jobs"
# A report ends the process (exit 1) with a stack trace; leaks are reported at exit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir build-asan --output-on-failure -j"$jobs"

tests/fuzz/run.sh "$fuzz_seconds"
