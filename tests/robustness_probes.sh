#!/usr/bin/env bash
# Representative inputs of every class of real-world fault, run as users and their schedulers run
# them: each must end well — the expected exit code and words, within its time — never a signal
# death, a hang, an internal error or a silent wrong answer. Prints one line per probe and the
# counts by class and outcome (the table in docs/validation/robustness.md); exits 1 if any probe
# did not end well.
#
#   tests/robustness_probes.sh BODYFIT_EXE SOURCE_DIR TEST_PLUGIN_DIR WORK_DIR
set -u
exe=$1 src=$2 test_plugins=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
sphere=$src/meshes/cases/sphere_cap.toml

# ---- fixtures -----------------------------------------------------------------------------------
"$exe" -q mesh sphere --faces 320 -o s.mesh
printf 'v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\nf 1 2 3 4 5\n' > concave.obj
printf 'v 0 0 0\nv 2 0 0\nv 0 2 0\nv 2 2 0\nf 1 2 3 4\n' > bowtie.obj
printf 'OFF\n5 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 0\n3 0 2 1\n3 4 1 3\n3 1 2 3\n3 0 3 2\n' > dup.off
printf 'MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTriangles\n4\n1 3 2 4294967299\n1 2 4 2\n2 3 4 2\n1 4 3 2\nEnd\n' > wide_ref.mesh
ln -sf /dev/zero zero.mesh
mkdir -p plugins && head -c 4096 "$test_plugins/bodyfit_testgood.so" > plugins/bodyfit_cut.so
printf 'not a plugin\n' > plugins/bodyfit_text.so
python3 - "$src" <<'EOF'
import sys
src = sys.argv[1]
lines = open(src + "/meshes/dem/hill.asc").read().splitlines()
header, rows = lines[:6], [l.split() for l in lines[6:]]
for name, value in (("spike", "1000000"), ("marker", "-32768")):
    cells = [r[:] for r in rows]
    cells[10][15] = value
    open(name + ".asc", "w").write("\n".join(header + [" ".join(r) for r in cells]) + "\n")
EOF
for dem in spike marker; do
  cat > $dem.toml <<EOF
[surface]
generator = "terrain"
dem = "$dem.asc"
h = 100.0
[region]
shape = "disks"
centers = [[501000.0, 4001000.0]]
radii = [200.0]
[model]
name = "fire"
[time]
dt = 60.0
final_time = 120.0
[output]
vtu_every = 0
EOF
done
cat > hang.toml <<EOF
[surface]
generator = "plane"
size = 2.0
h = 0.1
[region]
shape = "disks"
centers = [[0.0, 0.0]]
radii = [0.3]
[model]
name = "testlifecycle"
speed = 0.5
hang_file = "$work/hang"
[time]
dt = 0.05
iterations = 4
[output]
vtu_every = 0
EOF

# ---- the probes: class | expected exit code | words expected in the output | command ------------
pass=0 fail=0
declare -A ok bad
probe() {
  local class=$1 code=$2 words=$3 command=$4 outcome
  (cd "$work" && timeout 120 bash -c "$command") > out.txt 2>&1
  local got=$?
  if [ $got -eq 124 ]; then outcome=hang
  elif [ $got -gt 128 ] && [ "$code" -le 128 ]; then outcome="signal death ($got)"
  elif [ $got -eq 3 ] && [ "$code" -ne 3 ]; then outcome="internal error"
  elif [ $got -ne "$code" ]; then outcome="exit $got, expected $code"
  elif ! grep -qF -- "$words" out.txt; then outcome="wrong words"
  else outcome=ok
  fi
  if [ "$outcome" = ok ]; then pass=$((pass + 1)) ok[$class]=$((${ok[$class]:-0} + 1))
  else fail=$((fail + 1)) bad[$class]=$((${bad[$class]:-0} + 1)); fi
  printf '%-10s %-28s %s\n' "$class" "$outcome" "$command"
  [ "$outcome" = ok ] || sed 's/^/    | /' out.txt | tail -5
}
b=\"$exe\"
probe signals 130 "is complete and saved" "$b run $sphere -o sig_term --inject-signal 2:TERM"
probe signals 130 "is complete and saved" "$b run $sphere -o sig_hup --inject-signal 2:HUP"
probe signals 6 "write failed (File too large)" "ulimit -f 64; $b run $sphere -o fsize"
probe signals 0 "no temporary" "test \$(ls -a fsize | grep -c tmp) -eq 0 && echo no temporary"
probe concurrent 1 "is in use by another run (pid" "touch hang; BODYFIT_PLUGIN_PATH=$test_plugins $b run hang.toml -o shared > first.log 2>&1 & p=\$!; for i in \$(seq 300); do [ -s shared/history.csv ] && break; sleep 0.1; done; BODYFIT_PLUGIN_PATH=$test_plugins $b run hang.toml -o shared; c=\$?; kill -9 \$p; wait \$p; exit \$c"
probe concurrent 0 "taken over" "rm -f hang; BODYFIT_PLUGIN_PATH=$test_plugins $b run hang.toml -o shared --resume --force"
probe options 2 "is not a whole number" "$b --max-faces -5 info s.mesh"
probe options 2 "is not a whole number" "$b ensemble $src/meshes/cases/fire_luxembourg_ensemble.toml --seed -1 -o ens"
probe options 0 "remesh:" "$b remesh s.mesh -hmax=0.5 -out mmg.mesh"
probe options 2 "unknown option" "$b remesh s.mesh -hmaxx 0.5 -out x.mesh"
probe options 2 "not a finite number" "$b render s.mesh -o x.png --azimuth nan"
probe options 0 "above the surface's extent" "$b remesh s.mesh --hmax 1e300 -o big.mesh"
probe options 0 "area              12.3" "$b info big.mesh"  # a 6-face collapse had 4.8
probe numbers 1 "does not fit in 32 bits" "$b info wide_ref.mesh"
probe numbers 1 "not a regular file" "$b info zero.mesh"
probe numbers 1 "above [time] max_steps" "$b run $sphere -o steps --set time.cfl=1e-12"
probe numbers 0 "cell(s) stand alone" "$b run spike.toml -o spike"
probe numbers 0 "NODATA marker the header does not declare" "$b run marker.toml -o marker"
probe polygons 0 "area              2.5" "$b info concave.obj"
probe polygons 1 "crosses itself" "$b info bowtie.obj"
probe plugins 0 "a truncated ELF file" "BODYFIT_PLUGIN_PATH=$work/plugins:$test_plugins $b plugins"
probe plugins 1 "a truncated ELF file" "$b run $sphere -o cut --set model.name=\\\"$work/plugins/bodyfit_cut.so\\\""
probe plugins 0 "crashed while being loaded" "BODYFIT_TESTFAULT_CREATE=segv BODYFIT_PLUGIN_PATH=$test_plugins $b plugins"
probe plugins 4 "called exit() in compute" "BODYFIT_PLUGIN_PATH=$test_plugins $b run $sphere -o exit --set model.name=\\\"testfault\\\" --set model.stage=\\\"compute\\\" --set model.at=1 --set model.how=\\\"exit\\\""
probe resume 0 "not a history row" "$b run $sphere -o garbage --inject-signal 2:INT; echo 'not,a,row' >> garbage/history.csv; $b run $sphere -o garbage --resume"
probe resume 4 "cannot be a column of history.csv" "BODYFIT_PLUGIN_PATH=$test_plugins $b run $sphere -o metric --set model.name=\\\"testfault\\\" --set model.stage=\\\"compute\\\" --set model.at=1 --set model.how=\\\"metric_name\\\""
probe silent 1 "is beyond 150 m/s" "$b run $src/meshes/cases/fire_luxembourg.toml -o wind --set model.wind.type=\\\"uniform\\\" --set model.wind.speed=1e300 --set model.wind.direction_deg=0"
probe real 0 "merged, as MMG and CGAL do" "$b info dup.off"

echo
echo "class      ok  not ok"
for class in signals concurrent options numbers polygons plugins resume silent real; do
  printf '%-10s %3d %6d\n' "$class" "${ok[$class]:-0}" "${bad[$class]:-0}"
done
echo "total      $pass $fail"
[ "$fail" -eq 0 ]
