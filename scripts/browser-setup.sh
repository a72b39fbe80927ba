#!/usr/bin/env bash
# Installs Debian's chromium and chromium-driver (headless browser for tests/server/test_browser.py)
# when /usr/bin/chromium or /usr/bin/chromedriver is missing. Safe to run again; quiet unless it fails.
# Needs root and apt-get (CI runs as root); the last line of stderr says why when it cannot.
set -euo pipefail
cd "$(dirname "$0")/.."
LOG=${LOG:-build/browser-setup.log}

fail() {
  echo "browser-setup: FAILED: $1${2:+ (log: $2)}" >&2
  exit 1
}

if [ -x /usr/bin/chromium ] && [ -x /usr/bin/chromedriver ]; then
  echo "browser-setup: up to date (/usr/bin/chromium, /usr/bin/chromedriver)"
  exit 0
fi
if ! command -v apt-get >/dev/null; then
  fail "needs apt-get to install chromium and chromium-driver"
fi
if [ "$(id -u)" -ne 0 ]; then
  fail "needs root to install chromium and chromium-driver (apt-get install chromium chromium-driver)"
fi
mkdir -p "$(dirname "$LOG")"
: >"$LOG"
# shellcheck source=scripts/apt.sh
source scripts/apt.sh
apt_get update >>"$LOG" 2>&1 || fail "apt-get update" "$LOG"
apt_get install -y --no-install-recommends chromium chromium-driver fonts-dejavu-core >>"$LOG" 2>&1 \
  || fail "apt-get install chromium chromium-driver" "$LOG"
[ -x /usr/bin/chromium ] || fail "apt-get installed chromium but /usr/bin/chromium is missing" "$LOG"
[ -x /usr/bin/chromedriver ] || fail "apt-get installed chromium-driver but /usr/bin/chromedriver is missing" "$LOG"
echo "browser-setup: installed $(/usr/bin/chromium --version 2>/dev/null || echo chromium)"
