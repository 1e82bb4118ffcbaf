#!/usr/bin/env bash
# Run the libFuzzer targets of tests/fuzz (built with BODYFIT_BUILD_FUZZERS, see docs/reference/testing.md)
# for a bounded time each, from their seed corpora. A crash, a sanitizer report, a leak, an
# exception other than InputError or an input slower than --timeout fails the run; the input is
# saved in the output directory (artifact_prefix) and named in the message. New corpus entries go
# to the output directory, never into the source tree.
#   usage: scripts/run_fuzzers.sh [--build DIR] [--seconds S] [--timeout S] [--seed N] [--out DIR] [target...]
#   --build    the build directory with bin/fuzz_* (default build-sanitize/)
#   --seconds  per target (default 30)
#   --timeout  per input (default 5)
#   --seed     libFuzzer's random seed (default 1: CI explores the same inputs every run, so a
#              finding is one the change under test brought; 0 picks one at random, to explore)
#   --out      working directory (default <build>/fuzz-run)
#   targets    default: all (mesh_text mesh_binary sol openmesh esri_grid case checkpoint)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BODYFIT_SANITIZE_BUILD_DIR:-$ROOT/build-sanitize}" seconds=30 timeout=5 seed=1 out="" targets=()
while (($#)); do
  case "$1" in
    --build|--seconds|--timeout|--seed|--out)
      (($# >= 2)) || { echo "run_fuzzers.sh: $1 needs a value" >&2; exit 2; }
      case "$1" in
        --build) build=$2 ;; --seconds) seconds=$2 ;; --timeout) timeout=$2 ;; --seed) seed=$2 ;; --out) out=$2 ;;
      esac
      shift ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "run_fuzzers.sh: unknown option '$1'" >&2; exit 2 ;;
    *) targets+=("$1") ;;
  esac
  shift
done
((${#targets[@]})) || targets=(mesh_text mesh_binary sol openmesh esri_grid case checkpoint)
out="${out:-$build/fuzz-run}"
mkdir -p "$out"
# Leaks are findings; a reader's allocation above 2 GB (libFuzzer's -malloc_limit_mb) too.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:symbolize=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"

failed=()
printf '%-12s %10s %8s %6s  %s\n' target executions exec/s corpus result
for t in "${targets[@]}"; do
  exe="$build/bin/fuzz_$t"
  [[ -x "$exe" ]] || { echo "run_fuzzers.sh: no $exe (configure with -DBODYFIT_BUILD_FUZZERS=ON, build target 'fuzzers')" >&2; exit 1; }
  [[ -d "$ROOT/tests/fuzz/$t" ]] || { echo "run_fuzzers.sh: no seed corpus tests/fuzz/$t" >&2; exit 1; }
  corpus="$out/$t/corpus" log="$out/$t/log.txt"
  mkdir -p "$corpus" "$out/$t/artifacts"
  code=0
  "$exe" -seed="$seed" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$out/$t/artifacts/" "$corpus" "$ROOT/tests/fuzz/$t" > "$log" 2>&1 || code=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
  size=$(find "$corpus" -type f | wc -l)
  if ((code == 0)); then result=ok; else result="FAILED (exit $code): $log"; failed+=("$t"); fi
  printf '%-12s %10s %8s %6s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "$size" "$result"
  if ((code != 0)); then
    grep -m 3 -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|ALARM|.*uncaught exception|terminate called)' "$log" || true
    ls "$out/$t/artifacts"
  fi
done
if ((${#failed[@]})); then
  echo "run_fuzzers.sh: findings in ${failed[*]} (inputs in $out/<target>/artifacts/)" >&2
  exit 1
fi
