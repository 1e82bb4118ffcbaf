#!/usr/bin/env bash
# Out-of-tree plugin check: install the bodyfit build to a temporary prefix, build
# examples/plugin against it with find_package(bodyfit) + bodyfit_add_plugin, then ask the
# installed driver to list it through BODYFIT_PLUGIN_PATH. The example is configured as
# docs/guide/writing_models.md says, with no build type: it must default to Release.
#   usage: out_of_tree_plugin.sh <bodyfit build dir> <bodyfit source dir>
set -euo pipefail
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/bodyfit_oot.XXXXXX")
trap 'rm -rf "$work"' EXIT

step() { echo "== $*"; }
fail() { echo "FAILED: $*" >&2; exit 1; }

step "install $build to $work/prefix"
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log" 2>&1 || { cat "$work/install.log"; fail "cmake --install"; }
[[ -x "$work/prefix/bin/bodyfit" ]] || fail "no bin/bodyfit in the prefix"
config=$(find "$work/prefix" -name bodyfitConfig.cmake | head -n1)
[[ -n "$config" ]] || fail "no bodyfitConfig.cmake in the prefix"

step "configure (no build type) and build examples/plugin against the prefix"
launcher=()
if command -v ccache > /dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$source/examples/plugin" -B "$work/plugin-build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  "${launcher[@]}" > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; fail "configure"; }
grep -q '^CMAKE_BUILD_TYPE:[A-Z]*=Release$' "$work/plugin-build/CMakeCache.txt" \
  || fail "examples/plugin does not default to CMAKE_BUILD_TYPE=Release"
cmake --build "$work/plugin-build" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; fail "build"; }
plugin="$work/plugin-build/bodyfit_windy.so"
[[ -f "$plugin" ]] || fail "bodyfit_windy.so was not built at the top of the build tree"

step "list it with the installed driver"
listing=$(BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" plugins 2>&1) || { echo "$listing"; fail "bodyfit plugins"; }
echo "$listing"
header="$work/prefix/include/bodyfit/plugin_abi.hpp"
abi="$(sed -n 's/.*kPluginAbiMajor = \([0-9]*\);.*/\1/p' "$header").$(sed -n 's/.*kPluginAbiMinor = \([0-9]*\);.*/\1/p' "$header")"
grep -q "^windy 3\.0  (ABI ${abi/./\\.})" <<< "$listing" || fail "windy not listed (with ABI $abi)"
grep -qF "file: $plugin" <<< "$listing" || fail "windy not listed with its file"
described=$(BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" plugins --describe windy 2>&1) || { echo "$described"; fail "bodyfit plugins --describe windy"; }
grep -qF "default [1, 0, 0]" <<< "$described" || { echo "$described"; fail "windy's parameters not described"; }
# The installed driver finds the installed conormal plugin beside its own library.
grep -qF "$work/prefix/" <<< "$(grep -A1 '^conormal ' <<< "$listing")" || fail "installed conormal plugin not found in the prefix"
grep -q "failed to load" <<< "$listing" && fail "some plugin failed to load"

step "install the example plugin into the prefix: found without BODYFIT_PLUGIN_PATH"
cmake --install "$work/plugin-build" --prefix "$work/prefix" > "$work/install-plugin.log" 2>&1 || { cat "$work/install-plugin.log"; fail "plugin install"; }
listing=$(env -u BODYFIT_PLUGIN_PATH "$work/prefix/bin/bodyfit" plugins 2>&1) || { echo "$listing"; fail "bodyfit plugins"; }
grep -A1 "^windy " <<< "$listing" | grep -qF "$work/prefix/" || { echo "$listing"; fail "installed windy not found"; }

step "a 2-iteration run with it"
cat > "$work/case.toml" <<'TOML'
[surface]
generator = "sphere"
h = 0.15

[region]
shape = "cap"
axis = [0.0, 0.0, 1.0]
angle = 45.0

[model]
name = "windy"
base = 0.5
wind = [0.3, 0.0, 0.0]
smoothing = 0.1

[time]
dt = 0.02
iterations = 2
TOML
BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" run "$work/case.toml" -o "$work/run" \
  > "$work/run.log" 2>&1 || { cat "$work/run.log"; fail "bodyfit run with the windy model"; }
grep -qF "plugin-build/bodyfit_windy.so" "$work/run.log" || { cat "$work/run.log"; fail "the run did not use the built plugin"; }
history="$work/run/history.csv"
[[ -f "$history" ]] || fail "no history.csv"
head -n1 "$history" | grep -q "max_speed" || { cat "$history"; fail "the model's metric is not in history.csv"; }
[[ $(wc -l < "$history") -eq 4 ]] || { cat "$history"; fail "history.csv should have a header and rows for iterations 0, 1, 2"; }
grep -q "windy_speed" "$work/run/step_00001.vtu" || fail "the model's point field is not in the VTU"
grep -q 'Name="wind" NumberOfComponents="3"' "$work/run/step_00002.vtu" || fail "the model's vector field is not in the final VTU"

step "the lifecycle: rejected steps, and state kept across an interrupted run"
# max_growth 2 %: the first steps (|G| grows ~6 % at dt = 0.02) are rejected and retried with dt/2.
lifecycle=(--set model.max_growth=0.02 --set time.iterations=4)
BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" run "$work/case.toml" -o "$work/full" \
  "${lifecycle[@]}" > "$work/full.log" 2>&1 || { cat "$work/full.log"; fail "lifecycle run"; }
grep -q "rejected by model 'windy'" "$work/full.log" || { cat "$work/full.log"; fail "no rejection logged"; }
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "rejections") c = i } NR > 1 { s += $c } END { exit !(s > 0) }' \
  "$work/full/history.csv" || { cat "$work/full/history.csv"; fail "no rejection counted in history.csv"; }
BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" run "$work/case.toml" -o "$work/part" \
  "${lifecycle[@]}" --set time.iterations=2 > "$work/part.log" 2>&1 || { cat "$work/part.log"; fail "first half"; }
BODYFIT_PLUGIN_PATH="$work/plugin-build" "$work/prefix/bin/bodyfit" run "$work/case.toml" -o "$work/part" \
  "${lifecycle[@]}" --resume > "$work/rest.log" 2>&1 || { cat "$work/rest.log"; fail "resumed half"; }
# The model's counter came back from the checkpoint: the last row says 4 accepted steps.
column=$(head -n1 "$work/part/history.csv" | tr ',' '\n' | grep -n '^accepted_steps$' | cut -d: -f1)
[[ $(tail -n1 "$work/part/history.csv" | cut -d, -f"$column") == 4 ]] || { cat "$work/part/history.csv"; fail "model state not restored"; }
cmp -s "$work/part/final.mesh" "$work/full/final.mesh" || fail "the resumed run's final mesh differs"

step "the minimal example (examples/constant): built and run the same way"
cmake -S "$source/examples/constant" -B "$work/constant-build" -DCMAKE_PREFIX_PATH="$work/prefix" \
  "${launcher[@]}" > "$work/constant-configure.log" 2>&1 || { cat "$work/constant-configure.log"; fail "configure constant"; }
cmake --build "$work/constant-build" > "$work/constant-build.log" 2>&1 || { cat "$work/constant-build.log"; fail "build constant"; }
sed 's/^name = "windy"$/name = "constant"/; /^base\|^wind\|^smoothing/d' "$work/case.toml" > "$work/constant.toml"
BODYFIT_PLUGIN_PATH="$work/constant-build" "$work/prefix/bin/bodyfit" run "$work/constant.toml" -o "$work/constant" \
  --set model.speed=1.0 > "$work/constant.log" 2>&1 || { cat "$work/constant.log"; fail "bodyfit run with the constant model"; }
# A cap of polar angle 45° on the unit sphere grown at unit speed for 0.04: angle π/4 + 0.04.
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "area") c = i } END {
           exact = 2 * 3.141592653589793 * (1 - cos(3.141592653589793 / 4 + 0.04))
           if ($c < 0.99 * exact || $c > 1.01 * exact) { print "area " $c " against " exact; exit 1 } }' \
  "$work/constant/history.csv" || fail "the constant model's cap is not the exact one"

echo "out-of-tree plugin: OK"
