# Sourced by scripts/setup.sh and scripts/ros-setup.sh: how a venv is filled. Packages go in
# with uv, pinned here, which installs in seconds what pip takes a minute or more for (the
# venv's dependencies 75 s → 15 s, the ROS wheels 51 s → 8 s, on a 2-core machine with warm
# caches). The platform's certificates, as pip's are. Modules are compiled at install, as pip
# does: where PYTHONDONTWRITEBYTECODE is set (containers, CI) nothing else would, and every
# process would compile each module it imports again (0.5 s more for the endpoint's imports
# alone; the compiling adds about 12 s to the install). Should uv itself fail (it is fetched
# from PyPI like everything else), pip does the install.
UV_VERSION=0.13.9

# venv_install VENV ARGS...: pip-style install ARGS into VENV.
venv_install() {
  local venv=$1
  shift
  if "$venv/bin/python" -m uv --version 2>/dev/null | grep -qx "uv $UV_VERSION.*" \
    || "$venv/bin/python" -m pip install --quiet "uv==$UV_VERSION"; then
    "$venv/bin/python" -m uv pip install --quiet --system-certs --compile-bytecode --python "$venv/bin/python" "$@" && return 0
    echo "uv could not install $*; pip will" >&2
  fi
  "$venv/bin/python" -m pip install --quiet "$@"
}

# compile_sources VENV: cadkg's own modules compiled with VENV's Python, for the same reason
# (an editable install compiles nothing). Quick when they are up to date.
compile_sources() {
  "$1/bin/python" -m compileall -q -j 0 src/cadkg >/dev/null
}
