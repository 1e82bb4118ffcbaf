#!/usr/bin/env bash
# The engine (core/) knows no application: it includes no header of the application library
# (<bodyfit/app/...>) and no GDAL, MPI or Cairo header, its library needs none of those libraries,
# and its code and comments name no model, no raster format and no fire concept. A word added to
# core/ that belongs above it fails here.
#   usage: engine_boundary.sh <source dir> <libbodyfit_core.so>
set -euo pipefail
source=$1
library=$(realpath "$2")
status=0
fail() { echo "FAILED: $*" >&2; status=1; }

cd "$source/core"
files=$(find include internal src -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.in' \) | sort)

# 1. Includes: the engine's own headers, the standard library and its dependencies only.
for file in $files; do
  while IFS= read -r line; do
    header=$(sed -E 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"]([^>"]*)[>"].*/\1/' <<< "$line")
    case $header in
      bodyfit/*) [[ -f include/$header || -f internal/$header || -f include/$header.in ]] ||
                   fail "$file includes <$header>, which is not an engine header" ;;
      *gdal*|*ogr*|*cpl_*|mpi.h|*cairo*) fail "$file includes <$header>" ;;
    esac
  done < <(grep -E '^[[:space:]]*#[[:space:]]*include' "$file")
done

# 2. The library links none of the application's libraries.
if needed=$(readelf -d "$library" | grep NEEDED | grep -Ei 'bodyfit_app|gdal|mpi|cairo|png'); then
  fail "$library needs an application library: $needed"
fi

# 3. No model, raster format or fire concept named in the engine (code and comments).
words='fire|fires|fuel|fuels|arrival|ignitions?|burn(t|ing|s)?|wildfire|balbi|rothermel|thermal|rasters?|geotiff|esri|dem|dems|gdal|mpi|cairo|slurm|wind|terrain|terrains'
if hits=$(grep -nwiE "$words" $files CMakeLists.txt); then
  fail "the engine names what belongs to the application or a model:"
  echo "$hits" | head -40 >&2
fi
exit $status
