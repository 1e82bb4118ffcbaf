#!/usr/bin/env bash
# Set up (Debian packages), build, and run the whole test suite.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$ROOT/scripts/setup.sh"
"$ROOT/scripts/build.sh"
cd "${BODYFIT_BUILD_DIR:-$ROOT/build}"
ctest --output-on-failure -j "${BODYFIT_JOBS:-$(nproc)}" --timeout 600
