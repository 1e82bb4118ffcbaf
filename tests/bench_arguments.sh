#!/usr/bin/env bash
# A bench program's command line (bench/bench_args.hpp): `--help` prints the usage and exits 0,
# an unknown option prints the error and the usage to stderr and exits non-zero, and neither
# writes a file (both run in an empty directory).
#   usage: bench_arguments.sh <bench program>
set -euo pipefail
program=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
work=$(mktemp -d "${TMPDIR:-/tmp}/bodyfit_bench_args.XXXXXX")
trap 'rm -rf "$work"' EXIT
mkdir "$work/cwd"
cd "$work/cwd"

fail() { echo "FAILED: $(basename "$program") $*" >&2; exit 1; }
no_files() { [[ -z "$(ls -A .)" ]] || fail "$1: wrote $(ls -A . | tr '\n' ' ')"; }

status=0
"$program" --help > "$work/out" 2> "$work/err" || status=$?
[[ $status -eq 0 ]] || fail "--help: exit code $status"
grep -qi '^usage' "$work/out" || fail "--help: no usage on stdout"
no_files --help

status=0
"$program" --no-such-option > "$work/out" 2> "$work/err" || status=$?
[[ $status -ne 0 ]] || fail "--no-such-option: exit code 0"
grep -q 'no-such-option' "$work/err" || fail "--no-such-option: the error does not name the option"
grep -qi 'usage' "$work/err" || fail "--no-such-option: no usage on stderr"
no_files --no-such-option
echo "ok: $(basename "$program") --help, --no-such-option"
