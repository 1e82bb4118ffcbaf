#!/usr/bin/env bash
# Configure and build bodyfit (Release) into ./build. Usage: scripts/build.sh [extra cmake args]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BODYFIT_BUILD_DIR:-$ROOT/build}"
JOBS="${BODYFIT_JOBS:-$(nproc)}"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$BUILD" -j "$JOBS"
