#!/usr/bin/env bash
# The main job on the bundled example: build the IEMA cell's store, query it, call services, validate it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
.venv/bin/cadkg build examples/iema-switchgear/manifest.toml --store build/iema-store
.venv/bin/cadkg query build/iema-store wires-of-component label=F1500.1
.venv/bin/cadkg call build/iema-store cad_service label=F1500.1
.venv/bin/cadkg call build/iema-store rail_scanner
.venv/bin/cadkg validate build/iema-store
