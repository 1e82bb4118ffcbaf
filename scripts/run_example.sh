#!/usr/bin/env bash
# Set up (Debian packages), build, and run the main example: a spherical cap growing along its
# conormal on the unit sphere (paper §4.2). Results in out/sphere_cap/ (series.pvd for ParaView,
# PNG snapshots, history.csv, final.mesh).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
"$ROOT/scripts/build.sh"
BUILD="${BODYFIT_BUILD_DIR:-$ROOT/build}"
"$BUILD/bin/bodyfit" run "$ROOT/meshes/cases/sphere_cap.toml" -o "$ROOT/out/sphere_cap" --overwrite
echo "example done: see $ROOT/out/sphere_cap/ (series.pvd, *.png, history.csv)"
