#!/usr/bin/env bash
# Set up (Debian packages), build, and run the whole test suite: what CI runs (.ci/run). Stages:
#   release   build/ (Release, the build users get) and every test;
#   sanitize  build-sanitize/ (clang, AddressSanitizer with leak detection + UndefinedBehaviorSanitizer,
#             no benchmark programs, with the fuzz targets) and every test again, under the sanitizers;
#   fuzz      each libFuzzer target of tests/fuzz for BODYFIT_FUZZ_SECONDS seconds (default 30) from
#             its seed corpus (scripts/run_fuzzers.sh).
# Any failure, sanitizer report or fuzzer finding fails the run. docs/reference/testing.md has the details.
#   usage: scripts/run_tests.sh [--stages release,sanitize,fuzz]   (default: all three, what CI runs)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
JOBS="${BODYFIT_JOBS:-$(nproc)}"
stages="release,sanitize,fuzz"
case "${1:-}" in
  "") ;;
  --stages) stages="${2:?--stages needs a value, e.g. release,sanitize}" ;;
  -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "run_tests.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
esac
for s in ${stages//,/ }; do
  [[ $s == release || $s == sanitize || $s == fuzz ]] || { echo "run_tests.sh: unknown stage '$s'" >&2; exit 2; }
done
want() { [[ ",$stages," == *",$1,"* ]]; }
elapsed() { printf '%dm%02ds' $(($1 / 60)) $(($1 % 60)); }

"$ROOT/scripts/setup.sh"

if want release; then
  start=$SECONDS
  "$ROOT/scripts/build.sh"
  built=$SECONDS
  (cd "${BODYFIT_BUILD_DIR:-$ROOT/build}" && ctest --output-on-failure -j "$JOBS" --timeout 600)
  echo "run_tests.sh: release stage: build $(elapsed $((built - start))), tests $(elapsed $((SECONDS - built)))"
fi

SANITIZE_BUILD="${BODYFIT_SANITIZE_BUILD_DIR:-$ROOT/build-sanitize}"
if want sanitize; then
  start=$SECONDS
  cmake -S "$ROOT" -B "$SANITIZE_BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
    -DBODYFIT_SANITIZE=address,undefined -DBODYFIT_BUILD_FUZZERS=ON -DBODYFIT_BUILD_BENCH=OFF > /dev/null
  cmake --build "$SANITIZE_BUILD" -j "$JOBS"
  built=$SECONDS
  # Leaks are errors (the suppressions file lists what is left to system libraries, and why); a
  # single allocation above 2 GB is one too, as in the fuzzers (a count read from a file trusted
  # before its length); a test under the sanitizers runs a few times slower: a longer timeout.
  (cd "$SANITIZE_BUILD" &&
     ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_string_checks=1:max_allocation_size_mb=2048" \
     LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizers/lsan.supp:print_suppressions=0" \
     UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
     ctest --output-on-failure -j "$JOBS" --timeout 1800)
  echo "run_tests.sh: sanitize stage: build $(elapsed $((built - start))), tests $(elapsed $((SECONDS - built)))"
fi

if want fuzz; then
  start=$SECONDS
  [[ -x "$SANITIZE_BUILD/bin/fuzz_mesh_text" ]] || {
    echo "run_tests.sh: the fuzz stage needs the sanitize stage's build ($SANITIZE_BUILD)" >&2; exit 1; }
  # Every target (openmesh is back since OBJ and PLY, like OFF, are read by bodyfit's parsers).
  "$ROOT/scripts/run_fuzzers.sh" --build "$SANITIZE_BUILD" --seconds "${BODYFIT_FUZZ_SECONDS:-30}"
  echo "run_tests.sh: fuzz stage: $(elapsed $((SECONDS - start)))"
fi
