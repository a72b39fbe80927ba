#!/usr/bin/env bash
# Creates .venv with cadkg and its development tools, and builds the web page
# (scripts/build-web.sh). Safe to run again.
#
#   bash scripts/setup.sh          cadkg in .venv and its web page (what the demo and the Use
#                                  commands need)
#   bash scripts/setup.sh --test   the same, and what the whole test suite runs against:
#                                  .venv-ros with real rclpy and the ROS interfaces built
#                                  (scripts/ros-setup.sh), Chromium and its driver
#                                  (scripts/browser-setup.sh), Virtuoso (scripts/virtuoso.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  "$PYTHON" -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -e '.[dev]'
bash scripts/build-web.sh

if [ "${1:-}" = "--test" ]; then
  # Each installs what is missing and says in one line why it cannot; the tests that need
  # it then skip (a machine that cannot install it) or fail (anything else), naming the reason.
  bash scripts/ros-setup.sh || true
  bash scripts/browser-setup.sh || true
  bash scripts/virtuoso.sh install || true
fi
