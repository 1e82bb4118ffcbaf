#!/usr/bin/env bash
# Configure and build bodyfit (Release) into ./build. Usage: scripts/build.sh [extra cmake args]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${BODYFIT_BUILD_DIR:-$ROOT/build}"
JOBS="${BODYFIT_JOBS:-$(nproc)}"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$BUILD" -j "$JOBS"

# The Python module: Debian's /usr/bin/python3 imports bodyfit from this build, through a .pth file
# in its directory of local packages (the last build set up wins). Needs root or sudo; without, the
# line to add to PYTHONPATH is printed.
if [[ -f "$BUILD/python/bodyfit/__init__.py" && -x /usr/bin/python3 ]]; then
  site=$(/usr/bin/python3 -c 'import site; print(site.getsitepackages()[0])')
  pth="$site/bodyfit.pth"
  if [[ "$(cat "$pth" 2>/dev/null)" != "$BUILD/python" ]]; then
    SUDO=""
    [[ $(id -u) -ne 0 ]] && SUDO="sudo -n"
    if $SUDO mkdir -p "$site" 2>/dev/null && echo "$BUILD/python" | $SUDO tee "$pth" > /dev/null 2>&1; then
      echo "build.sh: /usr/bin/python3 imports bodyfit from $BUILD/python ($pth)"
    else
      echo "build.sh: cannot write $pth: use PYTHONPATH=$BUILD/python to import bodyfit" >&2
    fi
  fi
fi
