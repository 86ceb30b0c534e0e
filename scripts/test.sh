#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to every test passing: install, build, ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
ctest --preset release "$@"
