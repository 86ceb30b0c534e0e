#!/usr/bin/env bash
# Runs every libFuzzer target for a bounded time on its seed corpus and the inputs that once
# failed (tests/fuzz/regressions/). The targets come from the `asan` preset (clang + ASan + UBSan +
# libFuzzer coverage), the same instrumented build that scripts/test-sanitizers.sh tests, so CI
# compiles the library once for both. Any crash fails the run and leaves the input in
# build/asan/fuzz-runs/crashes/. Leaks inside teem's own error paths are suppressed (tests/fuzz/lsan.supp).
# Each input may take at most 10 s (a slow input is a finding too), and each target is stopped
# 60 s past its budget whatever happens, so the run's length is bounded.
# Usage: scripts/fuzz.sh [--seconds N]   (default 20 s per target)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=20
if [ "${1:-}" = "--seconds" ]; then seconds=$2; fi
scripts/install-deps.sh
cmake --preset asan >/dev/null
cmake --build --preset asan -j "$(nproc)"
out=build/asan/fuzz-runs
mkdir -p "$out/crashes"
status=0
for target in build/asan/fuzz/fuzz_*; do
  name=$(basename "$target")
  corpus_seed="tests/fuzz/corpus/${name#fuzz_}"
  work="$out/corpus/${name#fuzz_}"
  mkdir -p "$work" "$corpus_seed"
  echo "-- $name for ${seconds}s"
  if ! ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=tests/fuzz/lsan.supp \
        timeout --kill-after=10 $((seconds + 60)) "$target" -max_total_time="$seconds" -timeout=10 \
        -max_len=65536 -rss_limit_mb=4096 -artifact_prefix="$out/crashes/${name}-" \
        "$work" "$corpus_seed" "tests/fuzz/regressions/${name#fuzz_}" 2>"$out/$name.log"; then
    echo "FAIL $name: see $out/$name.log and $out/crashes/"
    tail -30 "$out/$name.log"
    status=1
  else
    grep -E "^#[0-9]+.*DONE" "$out/$name.log" | tail -1 || true
  fi
done
exit $status
