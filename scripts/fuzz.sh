#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`, clang + ASan + UBSan) and runs each for a bounded
# time on its seed corpus and the inputs that once failed (tests/fuzz/regressions/). Any crash
# fails the run and leaves the input in build/fuzz/crashes/. Leaks inside teem's own error
# paths are suppressed (tests/fuzz/lsan.supp).
# Usage: scripts/fuzz.sh [--seconds N]   (default 20 s per target)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=20
if [ "${1:-}" = "--seconds" ]; then seconds=$2; fi
scripts/install-deps.sh
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$(nproc)"
mkdir -p build/fuzz/crashes
status=0
for target in build/fuzz/fuzz/fuzz_*; do
  name=$(basename "$target")
  corpus_seed="tests/fuzz/corpus/${name#fuzz_}"
  work="build/fuzz/corpus/${name#fuzz_}"
  mkdir -p "$work" "$corpus_seed"
  echo "-- $name for ${seconds}s"
  if ! ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=tests/fuzz/lsan.supp "$target" -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=4096 \
        -artifact_prefix="build/fuzz/crashes/${name}-" "$work" "$corpus_seed" "tests/fuzz/regressions/${name#fuzz_}" 2>"build/fuzz/$name.log"; then
    echo "FAIL $name: see build/fuzz/$name.log and build/fuzz/crashes/"
    tail -30 "build/fuzz/$name.log"
    status=1
  else
    grep -E "^#[0-9]+.*DONE" "build/fuzz/$name.log" | tail -1 || true
  fi
done
exit $status
