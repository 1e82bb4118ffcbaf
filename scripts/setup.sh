#!/usr/bin/env bash
# Install the Debian 12 packages bodyfit needs to build, test and run its examples.
# Idempotent: packages already present are skipped; apt is only called when something is missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libopenmesh-dev libeigen3-dev libsuitesparse-dev libtet1.5-dev
  libopenblas0  # CHOLMOD's supernodal factorisation: 2.6x faster than with Debian's reference BLAS
  libfmt-dev libspdlog-dev doctest-dev libtomlplusplus-dev libcli11-dev libtbb-dev
  libpng-dev libgdal-dev
  libcairo2-dev  # maps (app/map, a module loaded on first use)
  libopenmpi-dev openmpi-bin  # bodyfit ensemble on MPI ranks (the module app/mpi; mpirun in its test)
  gdal-bin  # gdal_translate: the GeoTIFF test converts an .asc to .tif with it
  python3  # scripts/docs.py: the manual's generated pages and figures (CTest docs_up_to_date)
  python3-vtk9 python3-meshio  # tests/test_io.cpp cross-checks VTU and Medit files (skipped when absent)
  python3-dev pybind11-dev python3-numpy  # the Python module (python/)
  python3-pytest python3-scipy python3-pandas python3-matplotlib  # its tests; sparse matrices, histories, plots
  clang libclang-rt-14-dev llvm  # the sanitize and fuzz stages of run_tests.sh: ASan/UBSan, libFuzzer, llvm-symbolizer
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all build dependencies present"
fi

# Public meshes (meshes/public/README.md): CGAL's example meshes, extracted from Debian's own
# libcgal-demo package, not installed (it would pull in CGAL). fandisk.off is a thermal case's part;
# the others are bench_real_meshes's set (docs/validation/real_meshes.md).
PUBLIC="$(cd "$(dirname "$0")/.." && pwd)/meshes/public"
PUBLIC_MESHES=(fandisk anchor blade bull ChineseDragon-10kv cheese couplingdown elephant elephant-with-holes femur
               joint knot1 mushroom)
absent=()
for m in "${PUBLIC_MESHES[@]}"; do [[ -s "$PUBLIC/$m.off" ]] || absent+=("$m"); done
if ((${#absent[@]})); then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  download() { (cd "$work" && apt-get download -qq libcgal-demo 2> /dev/null); }
  SUDO=""
  [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  download || { $SUDO apt-get update -qq && download; } || { echo "setup: cannot download libcgal-demo" >&2; exit 1; }
  dpkg-deb --fsys-tarfile "$work"/libcgal-demo_*.deb | tar -xO ./usr/share/doc/libcgal-dev/data.tar.gz > "$work/data.tar.gz"
  for m in "${absent[@]}"; do
    tar -xzOf "$work/data.tar.gz" "data/meshes/$m.off" > "$work/$m.off"
    [[ -s "$work/$m.off" ]] || { echo "setup: $m.off not found in libcgal-demo" >&2; exit 1; }
    mv "$work/$m.off" "$PUBLIC/$m.off"
  done
  echo "setup: meshes/public: ${absent[*]} extracted from libcgal-demo"
fi
