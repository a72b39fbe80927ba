#!/usr/bin/env bash
# The main job on the bundled examples: set up .venv (scripts/setup.sh), then build each
# example cell's store, query it, call a service of its profile, validate it, and export the
# harness topology for the detection system, printing a short section per use case.
#
#   bash scripts/demo.sh             the summary
#   bash scripts/demo.sh --verbose   every command's whole output, the set-up's too
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p build
if [ "${1:-}" = "--verbose" ]; then
  bash scripts/setup.sh
else
  echo "setting up .venv and the web page (scripts/setup.sh; its output in build/setup.log) ..."
  if ! bash scripts/setup.sh > build/setup.log 2>&1; then
    tail -n 30 build/setup.log >&2
    echo "demo: the set-up failed; its whole output is in build/setup.log" >&2
    exit 1
  fi
fi
exec .venv/bin/python scripts/demo.py "$@"
