#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to the demo: install, build, `cleave demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/build.sh
exec build/release/bin/cleave demo "$@"
