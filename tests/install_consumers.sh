#!/usr/bin/env bash
# Installed-tree check, for programs other than the bodyfit driver:
#  1. install the bodyfit build to a temporary prefix: no installed file (binaries included) holds
#     the build directory's path, config.hpp is installed and config.hpp.in is not;
#  2. a C program dlopen()s every installed bundled plugin with RTLD_NOW, with no LD_LIBRARY_PATH:
#     each finds libbodyfit_core of the prefix through its own RUNPATH; bodyfit_plugin_abi() returns
#     the ABI of the installed headers, bodyfit_create/bodyfit_destroy work;
#  3. an out-of-tree project configured with no build type (find_package(bodyfit)): its plugin is
#     compiled with the Release flags, and once installed to another prefix the C program loads it
#     too; its C++ program linked to bodyfit::bodyfit_core searches the prefix's plugin directory
#     (not the build tree's) and BODYFIT_PLUGIN_PATH first;
#  4. the GDAL module (when built) is installed beside the plugin directory and the installed bodyfit,
#     which does not link GDAL, loads it to read a GeoTIFF;
#  5. the map module (when built) likewise: the installed bodyfit, which does not link Cairo, draws
#     a map with it.
#   usage: install_consumers.sh <bodyfit build dir> <bodyfit source dir>
set -euo pipefail
build=$(cd "$1" && pwd)
source=$(cd "$2" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/bodyfit_install.XXXXXX")
trap 'rm -rf "$work"' EXIT
unset LD_LIBRARY_PATH BODYFIT_PLUGIN_PATH

step() { echo "== $*"; }
fail() { echo "FAILED: $*" >&2; exit 1; }

prefix="$work/prefix"
step "install $build to $prefix"
cmake --install "$build" --prefix "$prefix" > "$work/install.log" 2>&1 || { cat "$work/install.log"; fail "cmake --install"; }
plugins=$(find "$prefix" -path '*/bodyfit/plugins/bodyfit_*.so' | sort)
[[ -n "$plugins" ]] || fail "no plugin installed in <libdir>/bodyfit/plugins"
plugin_dir=$(dirname "$(head -n1 <<< "$plugins")")
libdir=$(cd "$plugin_dir/../.." && pwd)
[[ -n $(find "$libdir" -maxdepth 1 -name 'libbodyfit_core.so*') ]] || fail "no libbodyfit_core in $libdir"
[[ -f "$plugin_dir/bodyfit_conormal.so" ]] || fail "bodyfit_conormal.so not installed in $plugin_dir"

step "no installed file names the build directory; config.hpp.in is not installed"
if leaks=$(grep -rlF "$build" "$prefix"); then
  for file in $leaks; do echo "  $file: $(grep -aoF "$build[^[:space:]\"]*" "$file" | sort -u | head -n3 | tr '\n' ' ')"; done
  fail "installed files contain the build directory $build"
fi
[[ -f "$prefix/include/bodyfit/config.hpp" ]] || fail "include/bodyfit/config.hpp not installed"
[[ ! -e "$prefix/include/bodyfit/config.hpp.in" ]] || fail "include/bodyfit/config.hpp.in installed"

# The ABI the installed headers declare (kPluginAbi = major << 16 | minor).
header="$prefix/include/bodyfit/plugin_abi.hpp"
major=$(sed -n 's/.*kPluginAbiMajor = \([0-9]*\);.*/\1/p' "$header")
minor=$(sed -n 's/.*kPluginAbiMinor = \([0-9]*\);.*/\1/p' "$header")
[[ -n "$major" && -n "$minor" ]] || fail "no kPluginAbiMajor/Minor in $header"
abi=$(( (major << 16) | minor ))

step "a C program dlopen()s each installed plugin (expected ABI $major.$minor = $abi)"
cat > "$work/load_plugin.c" <<'C'
/* load_plugin <plugin.so> <expected ABI> <core soname>: dlopen with RTLD_NOW, check
   bodyfit_plugin_abi, create and destroy a model, print the file of the libbodyfit_core the dynamic
   loader chose. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <link.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static void* symbol(void* handle, const char* name) {
  dlerror();
  void* address = dlsym(handle, name);
  const char* error = dlerror();
  if (error || !address) {
    fprintf(stderr, "dlsym %s: %s\n", name, error ? error : "null");
    exit(1);
  }
  return address;
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: load_plugin <plugin.so> <expected ABI> <core soname>\n");
    return 2;
  }
  void* handle = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    fprintf(stderr, "dlopen: %s\n", dlerror());
    return 1;
  }
  uint32_t (*abi)(void) = (uint32_t (*)(void))symbol(handle, "bodyfit_plugin_abi");
  unsigned long expected = strtoul(argv[2], NULL, 10);
  uint32_t got = abi();
  if (got != expected) {
    fprintf(stderr, "bodyfit_plugin_abi() = %u, expected %lu\n", got, expected);
    return 1;
  }
  void* (*create)(void) = (void* (*)(void))symbol(handle, "bodyfit_create");
  void (*destroy)(void*) = (void (*)(void*))symbol(handle, "bodyfit_destroy");
  void* model = create();
  if (!model) {
    fprintf(stderr, "bodyfit_create returned null\n");
    return 1;
  }
  destroy(model);
  void* core = dlopen(argv[3], RTLD_NOW | RTLD_NOLOAD);
  struct link_map* map = NULL;
  if (!core || dlinfo(core, RTLD_DI_LINKMAP, &map) != 0 || !map) {
    fprintf(stderr, "%s is not loaded: %s\n", argv[3], dlerror());
    return 1;
  }
  printf("abi %u core %s\n", got, map->l_name);
  dlclose(core);
  if (dlclose(handle) != 0) {
    fprintf(stderr, "dlclose: %s\n", dlerror());
    return 1;
  }
  return 0;
}
C
"${CC:-cc}" -std=c11 -Wall -Wextra -Werror -o "$work/load_plugin" "$work/load_plugin.c" -ldl \
  || fail "cannot compile the C loader"
# The core's SONAME (libbodyfit_core.so.<major>), as the installed library names itself.
soname=$(find "$libdir" -maxdepth 1 -name 'libbodyfit_core.so.*' -printf '%f\n' | grep -E '^libbodyfit_core\.so\.[0-9]+$' | head -n1)
[[ -n "$soname" ]] || fail "no libbodyfit_core.so.<major> in $libdir"
real_libdir=$(cd "$libdir" && pwd -P)
for plugin in $plugins; do
  out=$("$work/load_plugin" "$plugin" "$abi" "$soname" 2>&1) || { echo "$out"; fail "loading $plugin"; }
  echo "  $(basename "$plugin"): $out"
  core=$(sed -n 's/.* core //p' <<< "$out")
  [[ $(cd "$(dirname "$core")" && pwd -P) == "$real_libdir" ]] \
    || fail "$(basename "$plugin") loaded $core, not the prefix's libbodyfit_core"
done

step "an out-of-tree project with no build type: a plugin and a program using the installed core"
mkdir -p "$work/consumer"
cat > "$work/consumer/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.20)
project(bodyfit_consumer LANGUAGES CXX)
find_package(bodyfit REQUIRED)
bodyfit_add_plugin(windy "$source/examples/plugin/windy.cpp")
add_executable(search_path search_path.cpp)
target_link_libraries(search_path PRIVATE bodyfit::bodyfit_core)
CMAKE
cat > "$work/consumer/search_path.cpp" <<'CPP'
// Prints the plugin search path of the installed core, then the file of each model named.
#include <bodyfit/plugin_loader.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  try {
    for (const auto& dir : bodyfit::plugin_search_path()) std::printf("dir %s\n", dir.c_str());
    for (int i = 1; i < argc; ++i) {
      bodyfit::LoadedModel model = bodyfit::load_model(argv[i]);
      std::printf("model %s %s\n", argv[i], model.file().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
CPP
launcher=()
if command -v ccache > /dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$work/consumer" -B "$work/consumer-build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_EXPORT_COMPILE_COMMANDS=ON "${launcher[@]}" > "$work/configure.log" 2>&1 \
  || { cat "$work/configure.log"; fail "configure the consumer"; }
grep -q '^CMAKE_BUILD_TYPE:[A-Z]*=$' "$work/consumer-build/CMakeCache.txt" || fail "the consumer should have no build type"
python3 - "$work/consumer-build/compile_commands.json" <<'PY' || fail "bodyfit_add_plugin did not default to the Release flags"
import json, sys
commands = {e["file"].rsplit("/", 1)[-1]: e["command"] for e in json.load(open(sys.argv[1]))}
assert "-O3" in commands["windy.cpp"].split() and "-DNDEBUG" in commands["windy.cpp"].split(), commands["windy.cpp"]
assert "-O3" not in commands["search_path.cpp"].split(), "only the plugin gets the Release flags"
PY
cmake --build "$work/consumer-build" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; fail "build the consumer"; }

other="$work/other-prefix"
cmake --install "$work/consumer-build" --prefix "$other" > "$work/install-consumer.log" 2>&1 \
  || { cat "$work/install-consumer.log"; fail "install the consumer's plugin"; }
windy=$(find "$other" -name bodyfit_windy.so)
[[ -n "$windy" ]] || fail "bodyfit_windy.so not installed to $other"
out=$("$work/load_plugin" "$windy" "$abi" "$soname" 2>&1) || { echo "$out"; fail "loading the out-of-tree plugin installed to another prefix"; }
echo "  $windy: $out"

listing=$("$work/consumer-build/search_path" conormal 2>&1) || { echo "$listing"; fail "search_path conormal"; }
echo "$listing"
first=$(sed -n 's/^dir //p' <<< "$listing" | head -n1)
[[ $(cd "$first" && pwd -P) == $(cd "$plugin_dir" && pwd -P) ]] || fail "the installed core does not search $plugin_dir first"
grep -qF "$build" <<< "$listing" && fail "the installed core searches the build tree"
conormal=$(sed -n 's/^model conormal //p' <<< "$listing")
[[ -n "$conormal" && $(cd "$(dirname "$conormal")" && pwd -P) == $(cd "$plugin_dir" && pwd -P) ]] \
  || fail "conormal not loaded from $plugin_dir"
listing=$(BODYFIT_PLUGIN_PATH="$(dirname "$windy")" "$work/consumer-build/search_path" windy 2>&1) \
  || { echo "$listing"; fail "search_path windy with BODYFIT_PLUGIN_PATH"; }
echo "$listing"
[[ $(sed -n 's/^dir //p' <<< "$listing" | head -n1) == "$(dirname "$windy")" ]] || fail "BODYFIT_PLUGIN_PATH is not searched first"
grep -qF "model windy $windy" <<< "$listing" || fail "windy not loaded through BODYFIT_PLUGIN_PATH"

if [[ -f "$build/lib/bodyfit/libbodyfit_gis.so" ]]; then
  step "the GDAL module: installed in $libdir/bodyfit, loaded on first use by the installed bodyfit"
  [[ -f "$libdir/bodyfit/libbodyfit_gis.so" ]] || fail "libbodyfit_gis.so not installed in $libdir/bodyfit"
  ldd "$prefix/bin/bodyfit" | grep -qi gdal && fail "the installed bodyfit links GDAL (it must load it on demand)"
  if command -v gdal_translate > /dev/null; then
    gdal_translate -q -of GTiff "$source/meshes/dem/hill.asc" "$work/hill.tif"
    "$prefix/bin/bodyfit" -q mesh terrain --dem "$work/hill.tif" -o "$work/hill.mesh" || fail "bodyfit mesh terrain --dem hill.tif"
    [[ -s "$work/hill.mesh" ]] || fail "no mesh from the GeoTIFF"
  fi
fi

if [[ -f "$build/lib/bodyfit/libbodyfit_map.so" ]]; then
  step "the map module: installed in $libdir/bodyfit, loaded on first use by the installed bodyfit"
  [[ -f "$libdir/bodyfit/libbodyfit_map.so" ]] || fail "libbodyfit_map.so not installed in $libdir/bodyfit"
  ldd "$prefix/bin/bodyfit" | grep -qi cairo && fail "the installed bodyfit links Cairo (it must load it on demand)"
  "$prefix/bin/bodyfit" -q mesh terrain --extent 2000 --h 200 -o "$work/small.mesh" || fail "bodyfit mesh terrain"
  "$prefix/bin/bodyfit" -q map "$work/small.mesh" -o "$work/small_map.png" --size 400x300 || fail "bodyfit map"
  [[ -s "$work/small_map.png" ]] || fail "no map drawn"
fi

step "what users need beside the programs: cases and their data, licences, the manual, man page, completion"
data="$prefix/share/bodyfit"
for item in cases/sphere_cap.toml cases/fire_luxembourg.toml dem/luxembourg_elev_200m.asc parts/bracket_h0.07.mesh \
            examples/plugin/windy.cpp examples/constant/constant.cpp; do
  [[ -f "$data/$item" ]] || fail "share/bodyfit/$item not installed"
done
"$prefix/bin/bodyfit" --help | grep -qF "$data/cases" || fail "bodyfit --help does not point to $data/cases"
# An installed case runs from anywhere (its DEM and fuel map named relative to it).
(cd "$work" && "$prefix/bin/bodyfit" -q run "$data/cases/fire_luxembourg.toml" -o "$work/lux" \
   --set time.final_time=600 --set output.png_every=0 --set model.perimeters.file='""') \
  || fail "the installed fire_luxembourg case does not run"
for doc in LICENSE LICENSE.thermal-plugin README.md architecture.md; do
  [[ -f "$prefix/share/doc/bodyfit/$doc" ]] || fail "share/doc/bodyfit/$doc not installed"
done
[[ -f "$data/dem/README.md" ]] || fail "the DEM's licence note is not installed with it"
head -n1 "$prefix/share/man/man1/bodyfit.1" | grep -q '^\.TH BODYFIT 1' || fail "no man page"
grep -q "bodyfit ensemble" "$prefix/share/man/man1/bodyfit.1" || fail "the man page lacks a command"
if command -v man > /dev/null; then
  man -l "$prefix/share/man/man1/bodyfit.1" 2>&1 | grep -q "exactly meshed" || fail "man cannot render the page"
fi
completion="$prefix/share/bash-completion/completions/bodyfit"
bash -n "$completion" || fail "the bash completion does not parse"
words=$(bash -c "source '$completion'; COMP_WORDS=(bodyfit run --ov); COMP_CWORD=2; _bodyfit; echo \"\${COMPREPLY[*]}\"")
[[ $words == --overwrite ]] || fail "the completion of 'bodyfit run --ov' is '$words'"

step "pkg-config: a plugin built without CMake, loaded by the C program"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig${PKG_CONFIG_PATH:+:$PKG_CONFIG_PATH}"
flags=$(pkg-config --cflags --libs bodyfit) || fail "pkg-config bodyfit"
# shellcheck disable=SC2086
c++ -O2 -shared -fPIC -fvisibility=hidden "$source/examples/constant/constant.cpp" $flags \
  -Wl,-rpath,"$(pkg-config --variable=libdir bodyfit)" -o "$work/bodyfit_constant.so" || fail "building with pkg-config"
out=$("$work/load_plugin" "$work/bodyfit_constant.so" "$abi" "$soname" 2>&1) || { echo "$out"; fail "loading it"; }
[[ $(cd "$(pkg-config --variable=plugindir bodyfit)" && pwd -P) == $(cd "$plugin_dir" && pwd -P) ]] \
  || fail "pkg-config's plugindir is not $plugin_dir"
pkg-config --exists bodyfit-app || fail "pkg-config bodyfit-app"

echo "install consumers: OK"
