#!/usr/bin/env bash
# `bodyfit ensemble` under a running SLURM (docs/reference/ensembles.md): srun -n 2 writes the
# sequential run's bytes, so does the shipped batch script through sbatch, and srun --mpi=none is
# refused before any task runs a member. Skipped (exit 77) without srun or a SLURM controller that
# answers: scripts/slurm_local.sh start gives one on this host (root).
#   ensemble_srun.sh <bodyfit> <source dir> <work dir>
set -uo pipefail
bodyfit=$1 source_dir=$2 work=$3

skip() { echo "SKIP: $*"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }

if ! command -v srun > /dev/null || ! command -v sbatch > /dev/null; then
  skip "no srun/sbatch on this host (Debian: slurm-wlm)"
fi
# The throw-away cluster of scripts/slurm_local.sh, unless SLURM_CONF names another.
local_conf=${BODYFIT_SLURM_DIR:-${TMPDIR:-/tmp}/bodyfit-slurm}/slurm.conf
if [[ -z ${SLURM_CONF:-} && -s $local_conf ]]; then export SLURM_CONF=$local_conf; fi
nodes=$(timeout 5 sinfo -h -o '%T' 2> /dev/null) || skip "no SLURM controller answers (scripts/slurm_local.sh start)"
grep -Eq '^(idle|mixed)' <<< "$nodes" || skip "no SLURM node can take a job (sinfo: ${nodes:-none})"

rm -rf "$work"
mkdir -p "$work"
cd "$work" || fail "cannot enter $work"
# Open MPI leaks by design at MPI_Finalize: no leak report from the ranks of a sanitizer build.
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"

# The small case of tests/test_ensemble.cpp: about 400 faces, 4 steps, 5 members, a second each.
cat > case.toml <<'TOML'
[surface]
generator = "terrain"
extent = 1200.0
h = 100.0
seed = 3
max_height = 100.0
feature_size = 600.0
[region]
shape = "disks"
centers = [[600.0, 600.0]]
radii = [150.0]
[model]
name = "fire"
[model.wind]
type = "uniform"
speed = 3.0
direction_deg = 250.0
[model.arrival]
cell_size = 50.0
[time]
dt = 120.0
final_time = 480.0
[remesh]
hmax = 100.0
[output]
vtu_every = 0
[ensemble]
members = 5
seed = 11
[ensemble.ignition]
polygon = [[250.0, 250.0], [950.0, 250.0], [950.0, 950.0], [250.0, 950.0]]
radius = 150.0
[ensemble.sample]
"model.wind.speed" = {dist = "normal", mean = 3, sd = 1, min = 0}
"model.wind.direction_deg" = {dist = "uniform", min = 200, max = 250}
"model.R0" = {dist = "lognormal", mu = -0.92, sigma = 0.2}
TOML

"$bodyfit" --threads 1 ensemble case.toml -o sequential > sequential.log 2>&1 || { cat sequential.log; fail "sequential run"; }

# srun -n 2 (PMIx): two ranks, the sequential bytes. --immediate: a busy cluster fails the test
# with srun's message instead of holding it.
srun --immediate=60 --mpi=pmix -n 2 "$bodyfit" --threads 1 ensemble case.toml -o srun > srun.log 2>&1 ||
  { cat srun.log; fail "srun -n 2"; }
grep -q '\[rank 1/2\]' srun.log || { cat srun.log; fail "srun -n 2 did not give two ranks of one job"; }
diff -r sequential srun || fail "srun -n 2 wrote other bytes than the sequential run"

# The shipped batch script, through sbatch: the same bytes again.
# Polled here: `sbatch --wait` checks the job at growing intervals (tens of seconds).
job=$(BODYFIT=$bodyfit sbatch --parsable --time=5 --ntasks=2 --output=sbatch.log \
  "$source_dir/docs/examples/ensemble.sbatch" case.toml sbatch 2> sbatch.submit) || { cat sbatch.submit; fail "sbatch"; }
for _ in $(seq 1 1500); do
  [[ -n $(squeue -h -j "$job" 2> /dev/null) ]] || break
  sleep 0.2
done
state=$(scontrol show job "$job" | grep -o 'JobState=[A-Z_]*')
[[ $state == JobState=COMPLETED ]] || { cat sbatch.log; fail "batch job $job: ${state:-no state} (5 minutes at most)"; }
grep -q '\[rank 1/2\]' sbatch.log || { cat sbatch.log; fail "the batch job did not run two ranks"; }
diff -r sequential sbatch || fail "the batch job wrote other bytes than the sequential run"

# srun without a process-management interface: refused by every task before any member runs
# (without the check, each task would be an MPI job of one running all five members).
if srun --immediate=60 --mpi=none -n 2 "$bodyfit" --threads 1 ensemble case.toml -o none > none.log 2>&1; then
  cat none.log
  fail "srun --mpi=none was accepted"
fi
[[ $(grep -c 'srun --mpi=pmix' none.log) == 2 ]] || { cat none.log; fail "srun --mpi=none: not refused by both tasks"; }
[[ ! -e none ]] || fail "srun --mpi=none: an output directory was created"

# A lone task without an interface has no one to join: it runs alone, the same bytes.
srun --immediate=60 --mpi=none -n 1 "$bodyfit" --threads 1 ensemble case.toml -o single > single.log 2>&1 ||
  { cat single.log; fail "srun --mpi=none -n 1"; }
diff -r sequential single || fail "srun --mpi=none -n 1 wrote other bytes than the sequential run"

# srun --mpi=pmi2: an MPI with a PMI-2 client joins (the sequential bytes); Open MPI, which speaks
# PMIx only in Debian, is refused with the option to use instead of its advice to rebuild it.
if srun --immediate=60 --mpi=pmi2 -n 2 "$bodyfit" --threads 1 ensemble case.toml -o pmi2 > pmi2.log 2>&1; then
  diff -r sequential pmi2 || fail "srun --mpi=pmi2 wrote other bytes than the sequential run"
else
  [[ $(grep -c 'run srun --mpi=pmix' pmi2.log) == 2 ]] || { cat pmi2.log; fail "srun --mpi=pmi2: no clear refusal"; }
  [[ ! -e pmi2 ]] || fail "srun --mpi=pmi2: an output directory was created"
fi
echo "srun -n 2, sbatch, srun --mpi=none -n 1: the sequential bytes; srun --mpi=none -n 2 and pmi2 (Open MPI) refused"
