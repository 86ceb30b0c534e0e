#!/usr/bin/env bash
# Runs every entry of EXPECTED.tsv through the cleave CLI and checks for a clean, named error:
# exit code 2 (InputError), the expected text on stderr, no crash (signal) and no hang (timeout).
# Usage: run_catalogue.sh CLEAVE_BINARY [CATALOGUE_DIR]
set -u
cleave=$1
dir=${2:-$(dirname "$0")}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
passed=0
failed=0
while IFS=$'\t' read -r file command expected; do
  case "$file" in ''|'#'*) continue ;; esac
  if [ "$command" = run ]; then
    args=(run "$dir/$file" --out "$out/run" --quiet)
  else
    args=(info "$dir/$file" --quiet)
  fi
  stderr=$(timeout 60 "$cleave" "${args[@]}" 2>&1 >/dev/null)
  code=$?
  if [ "$code" -eq 2 ] && [[ "$stderr" == *"$expected"* ]] && [ "$(printf '%s\n' "$stderr" | grep -c 'cleave: error:')" -eq 1 ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $file: exit $code, expected exit 2 and '$expected'; got: $stderr"
  fi
done < "$dir/EXPECTED.tsv"
echo "bad inputs: $passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -ge 1 ]
