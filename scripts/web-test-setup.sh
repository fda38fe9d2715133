#!/usr/bin/env bash
# Installs what the browser viewer's tests drive chromium with, playwright-core, and the independent LAZ
# decoder the LAZ writer's tests check files with, laz-perf (WebAssembly, run by node), and the COPC
# reader copc.js ("copc", over laz-perf) that checks the octree builder's COPC files, from the npm
# registry into tests/web/node_modules, at the versions package-lock.json pins. It never downloads a
# browser: the tests start Debian's chromium (scripts/install-deps.sh). Idempotent: skips npm when the
# pinned versions are there.
set -euo pipefail
cd "$(dirname "$0")/../tests/web"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "web-test-setup: node and npm are needed for the browser tests (Node.js 20 or later)" >&2
  exit 1
fi
installedAll=1
for package in playwright-core laz-perf copc; do
  pinned=$(node -p "require('./package-lock.json').packages['node_modules/$package'].version")
  installed=$(node -p "try { require('./node_modules/$package/package.json').version } catch { '' }")
  if [ "$pinned" != "$installed" ]; then installedAll=0; fi
done
if [ "$installedAll" = 1 ]; then
  echo "web-test-setup: playwright-core, laz-perf and copc present"
  exit 0
fi
echo "web-test-setup: installing playwright-core, laz-perf and copc"
# No browser download: playwright-core has no install script, and this says so to any that would run.
PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error
