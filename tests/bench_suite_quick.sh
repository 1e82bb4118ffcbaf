#!/usr/bin/env bash
# scripts/bench_suite.sh --quick end to end: every run finished, bench_suite.csv has its columns and
# one row per case, size (the two smallest), threads (1, 2) and stage, the report has the exponent
# tables, the plots exist, and docs/ is left alone.
#   usage: bench_suite_quick.sh <source dir> <build dir> <work dir>
set -euo pipefail
source=$1 build=$2 work=$3
rm -rf "$work"
fail() { echo "FAILED: $*" >&2; exit 1; }
docs_before=$(cksum < "$source/docs/validation/performance.md")

"$source/scripts/bench_suite.sh" --quick --build "$build" --out "$work"

csv="$work/bench_suite.csv"
expected="case,size,h,threads,stage,iterations,faces,substeps,ms,faces_per_second,peak_rss_mb,wall_s,user_s,sys_s,status"
[[ "$(head -n 1 "$csv")" == "$expected" ]] || fail "header: $(head -n 1 "$csv")"
rows=$(($(wc -l < "$csv") - 1))
((rows == 2 * 2 * 2 * 8)) || fail "$rows rows, expected 64 (2 cases x 2 sizes x 2 thread counts x 8 stages)"
awk -F, 'NR > 1 && ($15 != "ok" || $6 != 1 || $7 < 1000 || $9 == "") { print "bad row: " $0; bad = 1 }
         END { exit bad }' "$csv" || fail "rows of failed runs"
for c in conormal fire; do
  grep -q "^$c,.*,total," "$csv" || fail "no total of $c"
  [[ -s "$work/images/performance_$c.png" ]] || fail "no plot of $c"
done
[[ $(grep -c '^Growth exponent' "$work/performance.md") -eq 2 ]] || fail "no exponent line per case in the report"
grep -q '^| total | [0-9.-]* |' "$work/performance.md" || fail "no exponent of the total"
[[ "$(cksum < "$source/docs/validation/performance.md")" == "$docs_before" ]] || fail "--quick changed docs/validation/performance.md"
echo "ok: $rows rows"
