#!/usr/bin/env bash
# Installs the studio's web dependencies (three.js for the page, playwright-core for the browser
# tests) into web/node_modules from web/package-lock.json. Idempotent; needs node and npm
# (scripts/install-deps.sh). The browser itself is Debian's chromium, not a downloaded one.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -f web/node_modules/three/build/three.module.js ] && [ -d web/node_modules/playwright-core ]; then
  echo "install-web: web/node_modules present"
  exit 0
fi
npm ci --prefix web --no-audit --no-fund
echo "install-web: done"
