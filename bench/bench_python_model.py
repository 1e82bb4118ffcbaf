#!/usr/bin/env python3
"""A velocity model in Python against the same model in C++: the conormal case
(meshes/cases/sphere_cap.toml) at 240k faces (surface.h = remesh.hmax = 0.0108, as the benchmark
suite's 240k size), outputs off (output.vtu_every = 0: the model's cost, not the disk's), run
alternately by three callers:

  cpp      bodyfit run with the C++ conormal plugin
  plugin   bodyfit run with the python model (examples/python/conormal.py through the embedded
           interpreter)
  object   bodyfit.run(case, model=Conormal()) from this interpreter

Per run, the median over the iterations (row 0, T^0, left out) of ms_total and ms_velocity from
history.csv; over the repeats, the median of those. Prints a table and writes bench_python_model.csv
(caller, repeat, iterations, ms_total, ms_velocity) in --out.

usage: bench/bench_python_model.py [--build DIR] [--out DIR] [--h H] [--iterations N] [--repeats R]
"""
import argparse
import csv
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]


def median_of_history(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))[1:]
    return (len(rows), statistics.median(float(r["ms_total"]) for r in rows),
            statistics.median(float(r["ms_velocity"]) for r in rows))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.environ.get("BODYFIT_BUILD_DIR", ROOT / "build"))
    parser.add_argument("--out", default=None)
    parser.add_argument("--h", type=float, default=0.0108)
    parser.add_argument("--iterations", type=int, default=8)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    build = pathlib.Path(args.build).resolve()
    out = pathlib.Path(args.out or build / "bench_python_model")
    out.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(build / "python"))
    sys.path.insert(0, str(ROOT / "examples" / "python"))
    import bodyfit
    from conormal import Conormal

    h = args.h
    dt = 0.5 * h  # the case's cfl = 0.5
    sets = {"surface.h": h, "remesh.hmax": h, "remesh.hmin": h / 10, "time.final_time": args.iterations * dt,
            "output.vtu_every": 0, "output.png_every": 0}
    cli_sets = [a for k, v in sets.items() for a in ("--set", f"{k}={v}")]
    exe = build / "bin" / "bodyfit"
    runs = {
        "cpp": lambda d: subprocess.run([exe, "run", ROOT / "meshes/cases/sphere_cap.toml", "-o", d, *cli_sets],
                                        check=True, capture_output=True),
        "plugin": lambda d: subprocess.run([exe, "run", ROOT / "examples/python/sphere_cap_python.toml", "-o", d,
                                            *cli_sets], check=True, capture_output=True),
        "object": lambda d: bodyfit.run(
            {**__import__("tomllib").loads((ROOT / "meshes/cases/sphere_cap.toml").read_text()),
             "model": {"speed": 1.0}}, out=d, model=Conormal(), set=sets, progress=False),
    }
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for repeat in range(args.repeats):
            for caller, run in runs.items():
                d = pathlib.Path(tmp) / f"{caller}_{repeat}"
                run(d)
                n, total, velocity = median_of_history(d / "history.csv")
                rows.append((caller, repeat, n, total, velocity))
                print(f"{caller:7s} repeat {repeat}: {n} iterations, {total:.1f} ms per iteration "
                      f"({velocity:.2f} ms velocity)", flush=True)
    with open(out / "bench_python_model.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["caller", "repeat", "iterations", "ms_total", "ms_velocity"])
        w.writerows(rows)
    base = statistics.median(r[3] for r in rows if r[0] == "cpp")
    print(f"\nconormal case, h = {h} ({args.iterations} iterations, {args.repeats} repeats; medians)")
    print(f"{'caller':8s} {'ms/iteration':>13s} {'ms velocity':>12s} {'vs cpp':>8s}")
    for caller in runs:
        total = statistics.median(r[3] for r in rows if r[0] == caller)
        velocity = statistics.median(r[4] for r in rows if r[0] == caller)
        print(f"{caller:8s} {total:13.1f} {velocity:12.2f} {100 * (total / base - 1):+7.1f}%")
    print(f"-> {out / 'bench_python_model.csv'}")


if __name__ == "__main__":
    main()
