#!/usr/bin/env bash
# The benchmark suite: `bodyfit run` on the conormal case (meshes/cases/sphere_cap.toml) and on the
# fire case (meshes/cases/fire_one_disk.toml, at its own defaults) at several mesh sizes, with 1 and
# 2 threads and the outputs off. From each run's history.csv: the median over the iterations
# (row 0, T^0, left out) of every stage's milliseconds, of the total, of the faces and sub-steps;
# from /usr/bin/time: the wall, user and system seconds and the peak resident memory.
#
# Writes, in the output directory: bench_suite.csv (one row per case, size, threads and stage),
# performance.md (the report: tables, fitted growth exponents, 1 → 2 thread speed-ups, the goals),
# images/performance_<case>.png (ms per iteration against faces, log-log, one line per stage) and
# runs/<case>_<size>_t<threads>/ (each run's history.csv, log and time). Unless --quick or --no-docs,
# the report also replaces the part of docs/validation/performance.md between its bench_suite markers, and the
# plots go to docs/validation/images/.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

usage() {
  cat <<'EOF'
usage: scripts/bench_suite.sh [--quick] [--large] [--sizes 60k,1M,...] [--cases conormal,fire]
                              [--threads 1,2] [--iterations N] [--max-seconds S] [--out DIR]
                              [--build DIR] [--no-docs]
  --quick        the two smallest sizes of each case, 1 iteration (a smoke run); docs untouched
  --large        also the conormal case at 4M faces (if at least 6 GiB of memory are available)
  --sizes        only these sizes (labels below; default: all but 4M)
  --cases        only these cases (default conormal,fire)
  --threads      thread counts, each a `bodyfit --threads N` run (default 1,2)
  --iterations   iterations per run (default 4 for conormal, 3 for fire; --quick: 1)
  --max-seconds  stop a run after S seconds and record it as timed out (default 1800)
  --out          output directory (default <build>/bench_suite)
  --build        build directory with bin/bodyfit (default $BODYFIT_BUILD_DIR or build/)
  --no-docs      do not update docs/validation/performance.md and docs/validation/images/performance_*.png
Sizes (faces of T^0) and mesh sizes h (--set surface.h=h --set remesh.hmax=h):
  conormal  60k 0.0216, 120k 0.0153, 240k 0.0108, 1M 0.0054, 4M 0.0027 (remesh.hmin = h/10)
  fire      54k 386 m, 233k 194 m, 1M 97 m
EOF
}

# Case tables: label:h, smallest first.
CONORMAL_SIZES="60k:0.0216 120k:0.0153 240k:0.0108 1M:0.0054"
CONORMAL_LARGE="4M:0.0027"
FIRE_SIZES="54k:386 233k:194 1M:97"
STAGES="velocity distance advect discretize remesh review output total"

quick=0 large=0 docs=1 sizes="" cases="conormal,fire" threads="1,2" iterations="" max_seconds=1800
build="${BODYFIT_BUILD_DIR:-$ROOT/build}" out=""
while (($#)); do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --quick) quick=1 docs=0 ;;
    --large) large=1 ;;
    --no-docs) docs=0 ;;
    --sizes|--cases|--threads|--iterations|--max-seconds|--out|--build)
      if (($# < 2)); then echo "bench_suite.sh: $1 needs a value" >&2; usage >&2; exit 2; fi
      case "$1" in
        --sizes) sizes=$2 ;; --cases) cases=$2 ;; --threads) threads=$2 ;; --iterations) iterations=$2 ;;
        --max-seconds) max_seconds=$2 ;; --out) out=$2 ;; --build) build=$2 ;;
      esac
      shift ;;
    *) echo "bench_suite.sh: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
  esac
  shift
done
[[ "$threads" =~ ^[0-9]+(,[0-9]+)*$ ]] || { echo "bench_suite.sh: --threads '$threads': expected e.g. 1,2" >&2; exit 2; }
[[ -z "$iterations" || "$iterations" =~ ^[1-9][0-9]*$ ]] || { echo "bench_suite.sh: --iterations '$iterations'" >&2; exit 2; }
[[ "$max_seconds" =~ ^[1-9][0-9]*$ ]] || { echo "bench_suite.sh: --max-seconds '$max_seconds'" >&2; exit 2; }
for c in ${cases//,/ }; do
  [[ "$c" == conormal || "$c" == fire ]] || { echo "bench_suite.sh: unknown case '$c' (conormal, fire)" >&2; exit 2; }
done
for s in ${sizes//,/ }; do
  [[ " $CONORMAL_SIZES $CONORMAL_LARGE $FIRE_SIZES" == *" $s:"* ]] ||
    { echo "bench_suite.sh: unknown size '$s'" >&2; usage >&2; exit 2; }
done

bodyfit="$build/bin/bodyfit"
[[ -x "$bodyfit" ]] || { echo "bench_suite.sh: no $bodyfit (build first, or give --build DIR)" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "bench_suite.sh: needs GNU time (/usr/bin/time; Debian package 'time')" >&2; exit 1; }
out="${out:-$build/bench_suite}"
mkdir -p "$out/runs" "$out/images"
out="$(cd "$out" && pwd)"
csv="$out/bench_suite.csv"

# The runs: case label h, in order (smallest first).
plan=()
for c in ${cases//,/ }; do
  if [[ $c == conormal ]]; then list="$CONORMAL_SIZES"; else list="$FIRE_SIZES"; fi
  if [[ $c == conormal && ( $large == 1 || ",$sizes," == *",4M,"* ) ]]; then
    available_kb=$(awk '/^MemAvailable:/ { print $2 }' /proc/meminfo)
    if ((available_kb >= 6 * 1024 * 1024)); then list="$list $CONORMAL_LARGE"
    else echo "skipping conormal 4M: $((available_kb / 1024)) MiB of memory available, 6 GiB wanted"; fi
  fi
  n=0
  for entry in $list; do
    label=${entry%%:*}
    [[ -z "$sizes" || ",$sizes," == *",$label,"* ]] || continue
    ((quick == 0 || n < 2)) || continue
    n=$((n + 1))
    plan+=("$c $label ${entry#*:}")
  done
done
((${#plan[@]} > 0)) || { echo "bench_suite.sh: no run selected" >&2; exit 2; }

# One row per stage of one run: the medians over history.csv's rows of iteration ≥ 1.
summarize() {  # history.csv case size h threads rss_kb wall user sys status
  awk -F, -v OFS=, -v case_name="$2" -v size="$3" -v h="$4" -v threads="$5" -v rss_kb="$6" -v wall="$7" \
      -v user="$8" -v sys="$9" -v status="${10}" -v stages="$STAGES" '
    function median(a, n,   i, j, t) {
      for (i = 2; i <= n; i++) for (j = i; j > 1 && a[j - 1] > a[j]; j--) { t = a[j]; a[j] = a[j - 1]; a[j - 1] = t }
      return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
    }
    NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    $col["iteration"] >= 1 { n++; for (c in col) value[c, n] = $col[c] }
    END {
      ns = split(stages, stage, " ")
      for (k = 1; k <= n; k++) a[k] = value["faces", k]
      faces = n ? median(a, n) : ""
      for (k = 1; k <= n; k++) a[k] = value["substeps", k]
      substeps = n ? median(a, n) : ""
      fps = ""  # of the run: faces / (median total seconds per iteration)
      if (n && "ms_total" in col) {
        for (k = 1; k <= n; k++) a[k] = value["ms_total", k]
        m = median(a, n)
        if (m > 0) fps = sprintf("%.0f", faces * 1000 / m)
      }
      for (s = 1; s <= ns; s++) {
        ms = ""
        if (n && ("ms_" stage[s]) in col) {
          for (k = 1; k <= n; k++) a[k] = value["ms_" stage[s], k]
          ms = sprintf("%.1f", median(a, n))
        }
        print case_name, size, h, threads, stage[s], n + 0, faces, substeps, ms, fps,
              rss_kb == "" ? "" : sprintf("%.0f", rss_kb / 1024), wall, user, sys, status
      }
    }' "$1"
}

echo "case,size,h,threads,stage,iterations,faces,substeps,ms,faces_per_second,peak_rss_mb,wall_s,user_s,sys_s,status" > "$csv"
plot_threads=$(tr ',' '\n' <<< "$threads" | sort -n | tail -n 1)  # the thread count of the plots and exponents
# CGAL's isotropic remeshing (bench/bench_cgal_remesh, built where CGAL is installed) on the final
# mesh of each conormal run at $plot_threads threads, at the same target edge length h.
cgal="$build/bin/bench_cgal_remesh" cgal_csv="$out/cgal_remesh.csv"
rm -f "$cgal_csv"
if [[ ! -x "$cgal" ]]; then echo "skipping bench_cgal_remesh: not built (needs CGAL)"
elif ((quick)); then echo "skipping bench_cgal_remesh: --quick"; fi
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
total=$((${#plan[@]} * $(tr ',' '\n' <<< "$threads" | wc -l)))
k=0
for entry in "${plan[@]}"; do
  read -r c label h <<< "$entry"
  if [[ $c == conormal ]]; then
    case_file="$ROOT/meshes/cases/sphere_cap.toml" n_iter=4
    extra=(--set "remesh.hmin=$(awk -v h="$h" 'BEGIN { print h / 10 }')")
  else
    case_file="$ROOT/meshes/cases/fire_one_disk.toml" n_iter=3 extra=()
  fi
  ((quick == 0)) || n_iter=1
  n_iter=${iterations:-$n_iter}
  for t in ${threads//,/ }; do
    k=$((k + 1))
    run="$out/runs/${c}_${label}_t$t"
    rm -rf "$run" && mkdir -p "$run"
    printf '[%d/%d] %s %s (h = %s) threads %s, %s iteration(s) ... ' "$k" "$total" "$c" "$label" "$h" "$t" "$n_iter"
    code=0
    /usr/bin/time -f '%M %e %U %S' -o "$run/time.txt" \
      timeout -k 10 "$max_seconds" "$bodyfit" -q --threads "$t" run "$case_file" -o "$run" \
      --set "surface.h=$h" --set "remesh.hmax=$h" --set "time.iterations=$n_iter" \
      --set output.vtu_every=0 --set output.png_every=0 "${extra[@]}" > "$run/log.txt" 2>&1 || code=$?
    read -r rss wall user sys < <(tail -n 1 "$run/time.txt") || true
    if ((code == 0)); then status=ok; elif ((code == 124 || code == 137)); then status=timeout; else status="failed($code)"; fi
    history="$run/history.csv"
    [[ -s "$history" ]] || history=/dev/null
    summarize "$history" "$c" "$label" "$h" "$t" "$rss" "$wall" "$user" "$sys" "$status" >> "$csv"
    awk -F, -v c="$c" -v s="$label" -v t="$t" '$1 == c && $2 == s && $4 == t && $5 == "total" {
      if ($9 == "") printf "no iteration completed, %s MiB, %s s wall: %s\n", $11, $12, $15
      else printf "%s ms per iteration, %s faces, %s MiB, %s s wall: %s\n", $9, $7, $11, $12, $15 }' "$csv"
    if [[ -x "$cgal" && $quick == 0 && $c == conormal && $t == "$plot_threads" && -f "$run/final.mesh" ]]; then
      timeout -k 10 "$max_seconds" "$cgal" "$run/final.mesh" "$h" --csv "$cgal_csv" > "$run/cgal_remesh.txt" 2>&1 ||
        echo "bench_cgal_remesh failed on $run/final.mesh: see $run/cgal_remesh.txt"
    fi
    rm -f "$run/checkpoint.bin" "$run/final.mesh" "$run/final.sol"
  done
done

# Plots: ms per iteration against faces per stage (at the largest thread count), log-log.
for c in ${cases//,/ }; do
  table="$out/images/performance_$c.csv"
  # Columns: faces, then each stage that takes at least 1 ms at some size.
  awk -F, -v c="$c" -v t="$plot_threads" -v stages="$STAGES" '
    NR > 1 && $1 == c && $4 == t && $9 != "" {
      if (!($2 in row)) { row[$2] = ++n; size[n] = $2 }
      ms[$2, $5] = $9; faces[$2] = $7; if ($9 >= 1) used[$5] = 1
    }
    END {
      ns = split(stages, stage, " ")
      line = "faces"; for (s = 1; s <= ns; s++) if (stage[s] in used) line = line "," stage[s]
      print line
      for (i = 1; i <= n; i++) {
        line = faces[size[i]]
        for (s = 1; s <= ns; s++) if (stage[s] in used) line = line "," ms[size[i], stage[s]]
        print line
      }
    }' "$csv" > "$table"
  columns=$(head -n 1 "$table" | cut -d, -f2- | tr ',' ' ')
  if (($(wc -l < "$table") < 2)) || [[ -z "$columns" ]]; then
    echo "no data to plot for $c"; rm -f "$table"; continue
  fi
  ys=(); for col in $columns; do ys+=(-y "$col"); done
  "$bodyfit" -q plot "$table" -x faces "${ys[@]}" --log-x --log-y --legend top-left --size 760x520 \
    --y-label "ms per iteration" --title "$c: median ms per iteration, $plot_threads thread(s)" \
    -o "$out/images/performance_$c.png"
done

# The report (markdown).
commit=$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)
[[ -z "$(git -C "$ROOT" status --porcelain --untracked-files=no 2>/dev/null)" ]] || commit="$commit (with local changes)"
cpu=$(awk -F': ' '/^model name/ { print $2; exit }' /proc/cpuinfo)
{
  echo "Generated by \`scripts/bench_suite.sh$([[ $quick == 1 ]] && echo " --quick")\` on $(date -u '+%Y-%m-%d %H:%M UTC'),"
  echo "commit $commit; $(nproc) cores ($cpu); load average $load_start at the start,"
  echo "$(cut -d' ' -f1-3 /proc/loadavg) at the end."
  echo
  awk -F, -v plot_threads="$plot_threads" -v stages="$STAGES" -f /dev/stdin "$csv" <<'AWK'
function key3(c, s, t) { return c SUBSEP s SUBSEP t }
NR == 1 { next }
{
  c = $1; s = $2; t = $4
  if (!(c in seen_case)) { seen_case[c] = 1; cases[++ncase] = c }
  if (!((c, s) in seen_size)) { seen_size[c, s] = 1; sizes[c, ++nsize[c]] = s; hval[c, s] = $3 }
  if (!(t in seen_threads)) { seen_threads[t] = 1; threads[++nthreads] = t }
  k = key3(c, s, t); have[k] = 1
  ms[k, $5] = $9; iters[k] = $6; faces[k] = $7; substeps[k] = $8; rss[k] = $11; wall[k] = $12
  user[k] = $13; sys[k] = $14; status[k] = $15
  if ($5 == "total") fps[k] = $10
}
function cell(v) { return v == "" ? "–" : v }
END {
  ns = split(stages, stage, " ")
  for (i = 1; i <= ncase; i++) {
    c = cases[i]
    printf "### %s\n\n", c
    printf "Median ms per iteration of each stage over iterations ≥ 1; faces and sub-steps: medians too; "
    printf "peak RSS in MiB; wall, user and system seconds of the whole run (setup included).\n\n"
    printf "| size | h | threads | faces | sub-steps |"
    for (j = 1; j <= ns; j++) printf " %s |", stage[j]
    printf " faces/s | peak RSS | wall s | user s | sys s | status |\n|"
    for (j = 1; j <= ns + 11; j++) printf "---|"
    printf "\n"
    for (a = 1; a <= nsize[c]; a++) for (b = 1; b <= nthreads; b++) {
      s = sizes[c, a]; t = threads[b]; k = key3(c, s, t)
      if (!(k in have)) continue
      printf "| %s | %s | %s | %s | %s |", s, hval[c, s], t, cell(faces[k]), cell(substeps[k])
      for (j = 1; j <= ns; j++) printf " %s |", (j == ns ? "**" cell(ms[k, stage[j]]) "**" : cell(ms[k, stage[j]]))
      printf " %s | %s | %s | %s | %s | %s |\n", cell(fps[k]), cell(rss[k]), cell(wall[k]), cell(user[k]), cell(sys[k]), status[k]
    }
    printf "\n"
    # Growth exponents: least-squares slope of log(ms) against log(faces) over the sizes.
    printf "Growth exponent p (ms ∝ faces^p, least squares over the sizes, %s thread(s); – where a stage takes < 1 ms):\n\n", plot_threads
    printf "| stage | p | sizes |\n|---|---|---|\n"
    for (j = 1; j <= ns; j++) {
      n = 0; sx = sy = sxx = sxy = 0; ok = 1; used = ""
      for (a = 1; a <= nsize[c]; a++) {
        k = key3(c, sizes[c, a], plot_threads)
        if (!(k in have) || ms[k, stage[j]] == "" || faces[k] == "") continue
        if (ms[k, stage[j]] < 1) ok = 0
        x = log(faces[k]); y = log(ms[k, stage[j]] > 0 ? ms[k, stage[j]] : 1)
        n++; sx += x; sy += y; sxx += x * x; sxy += x * y; used = used (used == "" ? "" : ", ") sizes[c, a]
      }
      d = n * sxx - sx * sx
      p = (n >= 2 && ok && d > 0) ? sprintf("%.2f", (n * sxy - sx * sy) / d) : "–"
      printf "| %s | %s | %s |\n", stage[j], p, used
    }
    printf "\n"
    # Speed-up from the smallest to the largest thread count.
    if (nthreads >= 2) {
      t1 = threads[1]; t2 = threads[nthreads]
      printf "Speed-up from %s to %s thread(s) (ms at %s / ms at %s):\n\n| size |", t1, t2, t1, t2
      for (j = 1; j <= ns; j++) printf " %s |", stage[j]
      printf "\n|---|"
      for (j = 1; j <= ns; j++) printf "---|"
      printf "\n"
      for (a = 1; a <= nsize[c]; a++) {
        s = sizes[c, a]; k1 = key3(c, s, t1); k2 = key3(c, s, t2)
        if (!(k1 in have) || !(k2 in have)) continue
        printf "| %s |", s
        for (j = 1; j <= ns; j++) {
          m1 = ms[k1, stage[j]]; m2 = ms[k2, stage[j]]
          printf " %s |", ((m1 != "" && m2 != "" && m1 >= 1 && m2 > 0) ? sprintf("%.2f", m1 / m2) : "–")
        }
        printf "\n"
      }
      printf "\n"
    }
    printf "![%s: ms per iteration against faces](images/performance_%s.png)\n\n", c, c
  }
  # The goals of the benchmark suite (docs/validation/performance.md).
  printf "### Goals\n\n| case | size | threads | ms per iteration | goal | peak RSS MiB | goal | met |\n|---|---|---|---|---|---|---|---|\n"
  ngoal = split("conormal 1M 1500 1024|fire 233k 1000 -", goal, "|")
  for (g = 1; g <= ngoal; g++) {
    split(goal[g], f, " ")
    found = 0
    for (b = 1; b <= nthreads; b++) {
      k = key3(f[1], f[2], threads[b])
      if (!(k in have)) continue
      found = 1; total = ms[k, "total"]
      met = total != "" && status[k] == "ok" && total <= f[3] && (f[4] == "-" || (rss[k] != "" && rss[k] <= f[4]))
      printf "| %s | %s | %s | %s | ≤ %s | %s | %s | %s |\n", f[1], f[2], threads[b], cell(total), f[3], cell(rss[k]),
             (f[4] == "-" ? "–" : "≤ " f[4]), (met ? "yes" : "**no**")
    }
    if (!found) printf "| %s | %s | – | not run | ≤ %s | – | %s | – |\n", f[1], f[2], f[3], (f[4] == "-" ? "–" : "≤ " f[4])
  }
  printf "\n"
}
AWK
  if [[ -s "$cgal_csv" ]]; then
    echo "### CGAL's isotropic remeshing"
    echo
    echo "\`bench_cgal_remesh final.mesh h\` (CGAL::Polygon_mesh_processing::isotropic_remeshing, 3 iterations"
    echo "over the whole mesh) on the final mesh of each conormal run above, for comparison with its"
    echo "\`remesh\` column (bodyfit remeshes incrementally, near the moved interface):"
    echo
    awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i
                       print "| input faces | target h | ms | faces | q min | q mean |\n|---|---|---|---|---|---|"; next }
             { printf "| %s | %s | %s | %s | %s | %s |\n", $col["input_faces"], $col["target"], $col["ms"],
               $col["faces"], $col["q_min"], $col["q_mean"] }' "$cgal_csv"
    echo
  fi
} > "$out/performance.md"
echo "wrote $csv, $out/performance.md and $out/images/"

if ((docs)); then
  doc="$ROOT/docs/validation/performance.md"
  begin='<!-- bench_suite:begin -->' end='<!-- bench_suite:end -->'
  if ! grep -qF "$begin" "$doc" 2>/dev/null || ! grep -qF "$end" "$doc"; then
    echo "bench_suite.sh: $doc has no $begin ... $end markers; left alone" >&2
    exit 1
  fi
  awk -v begin="$begin" -v end="$end" -v report="$out/performance.md" '
    $0 == begin { print; while ((getline line < report) > 0) print line; skip = 1; next }
    $0 == end { skip = 0 }
    !skip' "$doc" > "$doc.tmp" && mv "$doc.tmp" "$doc"
  for c in ${cases//,/ }; do
    [[ ! -f "$out/images/performance_$c.png" ]] || cp "$out/images/performance_$c.png" "$ROOT/docs/validation/images/"
  done
  echo "updated $doc and docs/validation/images/performance_*.png"
fi
