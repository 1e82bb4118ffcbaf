#!/usr/bin/env bash
# Run the shipped cases with one bodyfit and record what they write, to compare two builds' outputs
# byte for byte (a restructuring must not change a single output byte).
#
#   scripts/compare_outputs.sh record BODYFIT DIR [CASE.toml ...]   run each case (default: every
#        meshes/cases/*.toml) into DIR/<case>/ (`bodyfit run`, and `bodyfit ensemble` into
#        DIR/<case>.ensemble/ for a case with an [ensemble] table), and list the SHA-256 of every file
#        written in DIR/<case>.sums
#   scripts/compare_outputs.sh compare DIR_A DIR_B                 compare two records: exit 1 and name
#        the files when any differs (a file renamed with the same bytes is reported, not a difference)
#
# Every file is compared whole except history.csv, whose ms_* columns are wall-clock stage timings:
# they are removed before hashing. The case file is given by its absolute path (it is quoted in the
# run's case.toml). BODYFIT_COMPARE_JOBS sets the ensemble's --jobs (default 2).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

usage() { sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }

# history.csv without its ms_* columns.
strip_timings() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) keep[i] = ($i !~ /^ms_/) }
           { line = ""; first = 1
             for (i = 1; i <= NF; ++i) if (keep[i]) { line = line (first ? "" : ",") $i; first = 0 }
             print line }' "$1"
}

sums_of() {
  local dir=$1
  (cd "$dir" && find . -type f | LC_ALL=C sort | while read -r file; do
     if [[ $(basename "$file") == history.csv ]]; then
       printf '%s  %s\n' "$(strip_timings "$file" | sha256sum | cut -d' ' -f1)" "$file"
     else
       sha256sum "$file"
     fi
   done)
}

record() {
  local bodyfit dir
  bodyfit=$(realpath "$1")
  dir=$2
  shift 2
  local cases=("$@")
  ((${#cases[@]})) || cases=("$ROOT"/meshes/cases/*.toml)
  mkdir -p "$dir"
  for case_file in "${cases[@]}"; do
    case_file=$(realpath "$case_file")
    local name
    name=$(basename "$case_file" .toml)
    rm -rf "${dir:?}/$name" "${dir:?}/$name.ensemble"
    local start=$SECONDS
    "$bodyfit" run "$case_file" -o "$dir/$name" > "$dir/$name.log" 2>&1 ||
      { echo "$name: bodyfit run failed (exit $?; $dir/$name.log)" >&2; exit 1; }
    if grep -q '^\[ensemble\]' "$case_file"; then
      "$bodyfit" ensemble "$case_file" -o "$dir/$name.ensemble" --jobs "${BODYFIT_COMPARE_JOBS:-2}" \
        >> "$dir/$name.log" 2>&1 || { echo "$name: bodyfit ensemble failed ($dir/$name.log)" >&2; exit 1; }
    fi
    { sums_of "$dir/$name" | sed 's|  \./|  run/|'
      [[ -d "$dir/$name.ensemble" ]] && sums_of "$dir/$name.ensemble" | sed 's|  \./|  ensemble/|'
    } > "$dir/$name.sums"
    echo "$name: $(wc -l < "$dir/$name.sums") files in $((SECONDS - start)) s"
  done
}

compare() {
  local a=$1 b=$2 status=0
  for sums in "$a"/*.sums; do
    local name
    name=$(basename "$sums" .sums)
    if [[ ! -f "$b/$name.sums" ]]; then
      echo "$name: not recorded in $b"
      status=1
      continue
    fi
    # Files under the same name with other bytes; files under one name only, and of those, the ones
    # whose bytes the other record holds under another name (renamed, the same content).
    local report
    report=$(awk 'NR == FNR { a[$2] = $1; ha[$1]++; next } { b[$2] = $1; hb[$1]++ }
      END {
        for (f in a) if (f in b) { if (a[f] != b[f]) changed = changed " " f }
                     else if (a[f] in hb) renamed++; else { gone = gone " " f; ngone++ }
        for (f in b) if (!(f in a)) { if (b[f] in ha) renamed_to++; else { added = added " " f; nadded++ } }
        if (changed != "") printf "differs in:%s\n", changed
        if (ngone) printf "only in the first (%d):%s\n", ngone, gone
        if (nadded) printf "only in the second (%d):%s\n", nadded, added
        if (renamed) printf "renamed with the same bytes: %d files\n", renamed
      }' "$sums" "$b/$name.sums")
    if grep -qE '^(differs|only)' <<< "$report"; then
      echo "$name:"
      sed 's/^/  /' <<< "$report" | cut -c1-400
      status=1
    else
      echo "$name: identical ($(wc -l < "$sums") files${report:+; $report})"
    fi
  done
  return $status
}

case "${1:-}" in
  record) (($# >= 3)) || usage; shift; record "$@" ;;
  compare) (($# == 3)) || usage; compare "$2" "$3" ;;
  *) usage ;;
esac
