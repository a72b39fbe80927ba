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
#
# Every step runs as a job (scripts/jobs.sh), so however this script ends (a failed step, a
# signal to it alone or to its group) the set-ups still running end with it.
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}
for_tests=false
[ "${1:-}" = "--test" ] && for_tests=true
# shellcheck source=scripts/jobs.sh
source scripts/jobs.sh
# shellcheck source=scripts/venv.sh
source scripts/venv.sh

venv_setup() {
  if [ ! -x .venv/bin/python ]; then
    "$PYTHON" -m venv .venv
  fi
  if $for_tests; then
    # The ROS set-up, running meanwhile, installs this checkout into .venv-ros too: one
    # editable install at a time, since both write src/cadkg.egg-info.
    { flock 9 && venv_install .venv -e '.[dev]'; } 9>build/editable-install.lock
  else
    venv_install .venv -e '.[dev]'
  fi
  compile_sources .venv
  bash scripts/build-web.sh
}

ros_setup() {
  bash scripts/ros-setup.sh >build/ros-setup.out 2>&1
}

apt_setups() {
  { bash scripts/browser-setup.sh || true; bash scripts/virtuoso.sh install || true; } >build/apt-setups.out 2>&1
}

if $for_tests; then
  # Each installs what is missing and says in one line why it cannot; the tests that need
  # it then skip (a machine that cannot install it) or fail (anything else), naming the reason.
  # They run beside .venv's set-up: the ROS one mostly compiles, the other two mostly download
  # (their apt-get calls take turns, scripts/apt.sh). What each says comes at the end.
  mkdir -p build
  background ros_setup
  ros=$!
  background apt_setups
  others=$!
fi
background venv_setup
wait "$!"
if $for_tests; then
  wait "$ros" || true
  wait "$others" || true
  cat build/ros-setup.out build/apt-setups.out
fi
