#!/usr/bin/env bash
# Builds the web page of `cadkg serve` from web/ into src/cadkg/server/static/dist/ (git-ignored):
# npm ci installs the exact versions of web/package-lock.json, Vite bundles them with the page's
# own sources. Needs Node.js 20+ and npm; nothing is fetched at run time. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/../web"
if ! command -v npm >/dev/null; then
  echo "build-web: npm not found: install Node.js 20 or later and npm, then run scripts/build-web.sh" >&2
  exit 1
fi
npm ci --no-audit --no-fund --loglevel=error
npm run --silent build -- --logLevel warn
test -f ../src/cadkg/server/static/dist/index.html
echo "build-web: built src/cadkg/server/static/dist/"
