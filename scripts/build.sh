#!/usr/bin/env bash
# Installs missing Debian packages and the studio's npm packages, and builds the release preset (library, CLI, studio, tests).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/install-web.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
