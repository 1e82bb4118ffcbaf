"""A small fire ensemble from Python: the fire case meshes/cases/fire_one_disk.toml (Balbi's model on
a procedural terrain) under four wind speeds from the south-west, run one after the other, and
the burnt area |G|(t) of each plotted with matplotlib when it is installed (else printed).

    python3 examples/python/fire_ensemble.py [--out DIR]

For ensembles of hundreds of members (sampled parameters, burn probabilities, MPI ranks), see
`bodyfit ensemble` (docs/reference/ensembles.md); this script shows the loop a study starts from.
"""
import argparse
import pathlib

import numpy as np

import bodyfit

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASE = ROOT / "meshes" / "cases" / "fire_one_disk.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/fire_ensemble")
    parser.add_argument("--hours", type=float, default=3.0, help="simulated hours")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    curves = {}
    for speed in (0.0, 5.0, 10.0, 15.0):
        # A coarser mesh than the case's (h 800 m): the ensemble runs in seconds.
        overrides = {"surface.h": 800.0, "remesh.hmax": 800.0, "time.final_time": args.hours * 3600,
                     "model.wind.type": "uniform", "model.wind.speed": speed, "model.wind.direction_deg": 225.0,
                     "output.vtu_every": 0, "output.png_every": 0}
        result = bodyfit.run(CASE, out=out / f"wind_{speed:g}", set=overrides, overwrite=True, progress=False,
                             dataframe=False)
        t, area = result.history["time"] / 3600, result.history["area"] / 1e6
        curves[speed] = (t, area)
        print(f"wind {speed:3g} m/s: {result.iteration} iterations, burnt {area[-1]:8.2f} km² after {t[-1]:.1f} h")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for speed, (t, area) in curves.items():
        ax.plot(t, area, label=f"{speed:g} m/s")
    ax.set_xlabel("time (h)")
    ax.set_ylabel("burnt area |G| (km²)")
    ax.set_title("fire_one_disk: wind from the south-west")
    ax.legend(title="wind speed")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "burnt_area.png", dpi=120)
    print(f"plot: {out / 'burnt_area.png'}")


if __name__ == "__main__":
    main()
