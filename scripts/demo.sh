#!/usr/bin/env bash
# The main job on the bundled examples: build each cell's store, query it, call a service of
# its profile, validate it, and export the harness topology for the detection system.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cadkg=.venv/bin/cadkg

# IEMA switchgear: the cabinet, its pins and the next connection.
$cadkg build examples/iema-switchgear/manifest.toml --store build/iema-store
$cadkg query build/iema-store wires-of-component label=F1500.1
$cadkg call build/iema-store cad_service label=F1500.1
$cadkg call build/iema-store rail_scanner
$cadkg validate build/iema-store

# ELVEZ harness assembly: a guide's frames in the robot base frame, and the action plan.
$cadkg build examples/elvez-cell/manifest.toml --store build/elvez-store
$cadkg call build/elvez-store guide_info name=G4
$cadkg query build/elvez-store elvez-plan
$cadkg validate build/elvez-store

# ELIMCO pin workbench: pin positions around their centroid, and a cable's path.
$cadkg build examples/elimco-bench/manifest.toml --store build/elimco-store
$cadkg call build/elimco-store get_pin_positions use_centroid=true
$cadkg call build/elimco-store get_path_positions cable=A4351-1677

# Volkswagen harness: topology as GraphML for the detection system.
$cadkg build examples/vw-harness/manifest.toml --store build/vw-store
$cadkg export build/vw-store --format graphml --view topology --harness DOOR-L -o build/door-l.graphml

# ENKI hose: the product parameters the cell needs.
$cadkg build examples/enki-hose/manifest.toml --store build/enki-store
$cadkg call build/enki-store hose_info product=HX-25
