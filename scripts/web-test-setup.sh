#!/usr/bin/env bash
# Installs what the browser viewer's tests drive chromium with: playwright-core from the npm registry into
# tests/web/node_modules, at the version package-lock.json pins. It never downloads a browser: the tests
# start Debian's chromium (scripts/install-deps.sh). Idempotent: skips npm when the pinned version is there.
set -euo pipefail
cd "$(dirname "$0")/../tests/web"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "web-test-setup: node and npm are needed for the browser tests (Node.js 20 or later)" >&2
  exit 1
fi
pinned=$(node -p "require('./package-lock.json').packages['node_modules/playwright-core'].version")
installed=$(node -p "try { require('./node_modules/playwright-core/package.json').version } catch { '' }")
if [ "$pinned" = "$installed" ]; then
  echo "web-test-setup: playwright-core $installed present"
  exit 0
fi
echo "web-test-setup: installing playwright-core $pinned"
# No browser download: playwright-core has no install script, and this says so to any that would run.
PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error
