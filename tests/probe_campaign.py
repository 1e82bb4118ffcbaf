#!/usr/bin/env python3
"""A campaign of several hundred probes, generated rather than written one by one: every numeric
option of the stage commands with values that do not belong (NaN, infinities, negatives, zero,
10³⁰⁰, 2⁶⁴, words, nothing), every key of two shipped cases set to wrong values, mesh files of
every format truncated at ten places and with bytes flipped, the rasters of a fire case (DEM, fuel
map, wind) damaged in 15 ways. Each probe must end well: an exit code
of 0 (when the input is acceptable), 1 (bad input), 2 (usage), 4 (model), 5 (numerical) or 6
(output) — never a signal death, a hang (its time limit), an internal error (exit 3), or a
non-number accepted by a numeric option, or a raster that says something impossible accepted (a
silent answer). Prints the counts by class and outcome
(docs/validation/robustness.md) and exits 1 when a probe did not end well.

    tests/probe_campaign.py BODYFIT_EXE SOURCE_DIR WORK_DIR [--only CLASS]
"""
import os
import pathlib
import random
import re
import subprocess
import sys
import time

ENDED_WELL = {0, 1, 2, 4, 5, 6}
NOT_NUMBERS = ["nan", "inf", "-inf", "x", ""]
BAD_NUMBERS = ["-1", "0", "1e-300", "1e300", "18446744073709551616", "1,2"] + NOT_NUMBERS


class Campaign:
    def __init__(self, exe, work):
        self.exe, self.work = exe, work
        self.results = {}  # class -> outcome -> count
        self.failures = []

    def probe(self, cls, args, timeout=60, numeric_value=None, expect_file=None, must_refuse=False, label=None):
        start = time.time()
        try:
            r = subprocess.run([self.exe, "-q", *args], cwd=self.work, capture_output=True, text=True,
                               timeout=timeout, errors="replace")
            code, err = r.returncode, r.stderr
        except subprocess.TimeoutExpired:
            code, err = None, ""
        if code is None:
            outcome = "hang"
        elif code < 0:
            outcome = f"signal {-code}"
        elif code == 3:
            outcome = "internal error"
        elif code not in ENDED_WELL:
            outcome = f"exit {code}"
        elif code == 0 and numeric_value is not None and numeric_value in NOT_NUMBERS:
            outcome = "accepted a non-number"
        elif code == 0 and must_refuse:
            outcome = "accepted silently"
        elif code == 0 and expect_file and not (self.work / expect_file).exists():
            outcome = "exit 0 without its output"
        elif code != 0 and not err.strip():
            outcome = "failed without a message"
        else:
            outcome = "ended well"
        counts = self.results.setdefault(cls, {})
        counts[outcome] = counts.get(outcome, 0) + 1
        if outcome != "ended well":
            # The damaged inputs are rewritten by the next probe: keep this one's, to reproduce it.
            for a in args:
                if a.startswith(("cut.", "flip.")) and (self.work / a).exists():
                    kept = self.work / f"kept_{len(self.failures)}_{a}"
                    kept.write_bytes((self.work / a).read_bytes())
                    args = [str(kept.name) if x == a else x for x in args]
            what = f" [{label}]" if label else ""
            self.failures.append(f"{cls}{what}: bodyfit {' '.join(args)} -> {outcome} ({time.time() - start:.1f} s)\n"
                                 f"    {err.strip()[-300:]}")
        if expect_file:
            (self.work / expect_file).unlink(missing_ok=True)


def numeric_options(exe, command):
    """The options of `command` that take a number, from its --help."""
    text = subprocess.run([exe, *command, "--help"], capture_output=True, text=True).stdout
    return re.findall(r"^\s+(--[a-z-]+) (?:FLOAT|INT|UINT)\b", text, re.M)


def option_probes(c, exe):
    fixtures = {
        "mesh sphere": (["mesh", "sphere"], ["-o", "out.mesh"], "out.mesh", {"--faces": "500"}),
        "info": (["info", "s.mesh"], [], None, {}),
        "distance": (["distance", "s.mesh", "--phi", "phi.sol"], ["-o", "out.sol"], "out.sol", {}),
        "advect": (["advect", "s.mesh", "--phi", "phi.sol", "--velocity", "v.sol"], ["-o", "out.sol"], "out.sol",
                   {"--time": "0.1"}),
        "discretize": (["discretize", "s.mesh", "--phi", "phi.sol"], ["-o", "out.mesh"], "out.mesh", {}),
        "remesh": (["remesh", "s.mesh"], ["-o", "out.mesh"], "out.mesh", {}),
        "render": (["render", "s.mesh"], ["-o", "out.png"], "out.png", {}),
        "mesh terrain": (["mesh", "terrain"], ["-o", "out.mesh"], "out.mesh", {"--extent": "1000", "--h": "100"}),
    }
    for name, (command, output, produced, defaults) in fixtures.items():
        options = numeric_options(exe, command[:2] if command[0] == "mesh" else command[:1])
        for option in options:
            for value in BAD_NUMBERS:
                given = {**defaults, option: value}
                args = [*command, *output]
                for key, v in given.items():
                    args += [f"{key}={v}"] if v.startswith("-") or v == "" else [key, v]
                c.probe("option values", args, timeout=60, numeric_value=value, expect_file=produced)


CASE_VALUES = ["-1", "0", "1e300", "\"nan\"", "nan", "inf", "\"abc\"", "[1, 2]", "true", "-1e300"]


def case_probes(c, src):
    """Each key of two shipped cases set to values that do not belong, on a coarse mesh."""
    cases = {
        "sphere_cap.toml": ({"surface.h": "0.2", "remesh.hmax": "0.2", "time.final_time": "0.2"},
                            ["surface.h", "surface.radius", "region.angle", "region.axis", "model.speed",
                             "model.period", "time.cfl", "time.final_time", "time.dt", "remesh.hmin", "remesh.hausd",
                             "remesh.hgrad", "output.vtu_every"]),
        "plane_disk.toml": ({"surface.h": "0.1", "remesh.hmax": "0.1", "time.final_time": "0.1"},
                            ["surface.size", "region.centers", "region.radii", "time.dt", "time.final_time",
                             "model.speed"]),
    }
    for case, (quick, keys) in cases.items():
        for key in keys:
            for value in CASE_VALUES:
                sets = {**quick, "output.vtu_every": "0", "output.png_every": "0", key: value}
                args = ["run", str(src / "meshes" / "cases" / case), "-o", "run_out", "--overwrite"]
                for k, v in sets.items():
                    args += ["--set", f"{k}={v}"]
                c.probe("case values", args, timeout=120)


def file_probes(c, work):
    formats = [".mesh", ".meshb", ".off", ".obj", ".ply", ".stl", ".vtu"]
    rng = random.Random(7)
    for ext in formats:
        source = work / f"s{ext}"
        data = source.read_bytes()
        for k in range(1, 11):
            cut = work / f"cut{ext}"
            cut.write_bytes(data[: len(data) * k // 11])
            c.probe("truncated files", ["info", cut.name], timeout=30)
        for k in range(5):
            flipped = bytearray(data)
            for _ in range(8):
                flipped[rng.randrange(len(flipped))] = rng.randrange(256)
            bad = work / f"flip{ext}"
            bad.write_bytes(bytes(flipped))
            c.probe("damaged files", ["info", bad.name], timeout=30)
            c.probe("damaged files", ["remesh", bad.name, "-o", "out.mesh"], timeout=60)


FIRE_CASE = """[surface]
generator = "terrain"
dem = "dem.asc"
h = 50.0
[region]
shape = "disks"
centers = [[500600.0, 4000600.0]]
radii = [150.0]
[model]
name = "fire"
preset = "balbi2009"
[model.fuel]
map = "fuel.asc"
[model.wind]
type = "grid"
u_file = "u.asc"
v_file = "v.asc"
[time]
dt = 60.0
iterations = 2
[remesh]
hmax = 50.0
[output]
vtu_every = 0
png_every = 0
"""


def ascii_grid(cells, cols=24, rows=24, header=None):
    """An ESRI ASCII grid of 50 m cells; `cells(r, c)` gives each value's text."""
    head = header if header is not None else ["ncols %d" % cols, "nrows %d" % rows, "xllcorner 500000", "yllcorner 4000000", "cellsize 50",
                      "NODATA_value -9999"]
    return "\n".join(head + [" ".join(cells(r, c) for c in range(cols)) for r in range(rows)]) + "\n"


def raster_probes(c, work):
    """The rasters of a fire case on a DEM (the DEM, the fuel map, a wind component), each damaged in
    one way: values that are no numbers, out of range, lone outliers, undeclared NODATA markers, all
    NODATA, too few or too many values, impossible headers. Where the damage makes the raster say
    something wrong for what it is (a fuel code no preset has, a wind of 10⁶ m/s), the run must
    refuse it: accepting it is a silent answer."""
    files = {"dem.asc": lambda r, c: repr(100 + 3.0 * c + 2.0 * r), "fuel.asc": lambda r, c: "1",
             "u.asc": lambda r, c: "3", "v.asc": lambda r, c: "1"}
    lone = lambda base, value: (lambda r, c: value if (r, c) == (12, 12) else base(r, c))
    header = ["ncols 24", "nrows 24", "xllcorner 500000", "yllcorner 4000000", "cellsize 50", "NODATA_value -9999"]
    for name in ["dem.asc", "fuel.asc", "u.asc"]:
        base = files[name]
        damages = {
            "a word": (ascii_grid(lone(base, "abc")), True),
            "nan": (ascii_grid(lone(base, "nan")), name != "dem.asc"),
            "inf": (ascii_grid(lone(base, "inf")), True),
            "1e6 alone": (ascii_grid(lone(base, "1e6")), name != "dem.asc"),
            "1e300": (ascii_grid(lone(base, "1e300")), True),
            "-32768 undeclared": (ascii_grid(lone(base, "-32768")), name != "dem.asc"),
            "all NODATA": (ascii_grid(lambda r, c: "-9999"), True),
            "too few values": (ascii_grid(base)[: len(ascii_grid(base)) // 2], True),
            "too many values": (ascii_grid(base) + "1 2 3\n", True),
            "ncols 0": (ascii_grid(base, header=["ncols 0"] + header[1:]), True),
            "ncols 10^12": (ascii_grid(base, header=["ncols 1000000000000"] + header[1:]), True),
            "cellsize 0": (ascii_grid(base, header=header[:4] + ["cellsize 0"] + header[5:]), True),
            "cellsize -50": (ascii_grid(base, header=header[:4] + ["cellsize -50"] + header[5:]), True),
            "no header": (ascii_grid(base, header=[]), True),
            "empty": ("", True),
        }
        if name == "fuel.asc":
            damages["a lone code no preset has"] = (ascii_grid(lone(base, "7")), True)
        if name == "u.asc":
            damages["a lone gust of 40 m/s"] = (ascii_grid(lone(base, "40")), False)
        for damage, (text, must_refuse) in damages.items():
            for f, cells in files.items():
                (work / "rasters" / f).write_text(ascii_grid(cells))
            (work / "rasters" / name).write_text(text)
            c.probe("rasters", ["run", "rasters/case.toml", "-o", "rasters/out", "--overwrite"], timeout=60,
                    must_refuse=must_refuse, label=f"{name}: {damage}")


def main():
    exe, src, work = os.path.abspath(sys.argv[1]), pathlib.Path(sys.argv[2]).resolve(), pathlib.Path(sys.argv[3]).resolve()
    only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
    work.mkdir(parents=True, exist_ok=True)
    subprocess.run([exe, "-q", "mesh", "sphere", "--faces", "500", "-o", "s.mesh"], cwd=work, check=True)
    for ext in [".meshb", ".off", ".obj", ".ply", ".stl", ".vtu"]:
        subprocess.run([exe, "-q", "remesh", "s.mesh", "--passes", "1", "-o", f"s{ext}"], cwd=work, check=True)
    # φ = z (a cap boundary on the equator) and V = a rotation about x, as .sol files.
    lines = (work / "s.mesh").read_text().split("\n")
    i = lines.index("Vertices")
    n = int(lines[i + 1])
    points = [list(map(float, lines[i + 2 + k].split()[:3])) for k in range(n)]
    (work / "phi.sol").write_text("MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n%d\n1 1\n%s\nEnd\n" % (
        n, "\n".join(f"{p[2]!r}" for p in points)))
    (work / "v.sol").write_text("MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n%d\n1 2\n%s\nEnd\n" % (
        n, "\n".join(f"0 {-p[2]!r} {p[1]!r}" for p in points)))
    c = Campaign(exe, work)
    start = time.time()
    if only in (None, "options"):
        option_probes(c, exe)
    if only in (None, "cases"):
        case_probes(c, src)
    if only in (None, "files"):
        file_probes(c, work)
    if only in (None, "rasters"):
        (work / "rasters").mkdir(exist_ok=True)
        (work / "rasters" / "case.toml").write_text(FIRE_CASE)
        raster_probes(c, work)
    total = sum(sum(v.values()) for v in c.results.values())
    well = sum(v.get("ended well", 0) for v in c.results.values())
    for cls, counts in c.results.items():
        print(f"{cls:16s} {sum(counts.values()):4d} probes: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    print(f"{'total':16s} {total:4d} probes, {well} ended well ({time.time() - start:.0f} s)")
    for failure in c.failures:
        print("NOT WELL:", failure)
    return 0 if well == total else 1


if __name__ == "__main__":
    sys.exit(main())
