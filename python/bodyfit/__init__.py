"""bodyfit: a region moving inside a fixed triangulated surface, meshed exactly at every step.

Meshes and fields are numpy arrays; the stages are functions with the command line's options and
defaults; runs take a case file or a dict and a velocity model written in C++ (a plugin) or in
Python (any object with a ``compute(step)`` method). docs/guide/python.md is the guide.
"""
from __future__ import annotations

import csv as _csv
import json as _json
import os as _os
from dataclasses import dataclass as _dataclass, field as _field
from typing import Any, Optional, Sequence

import numpy as _np

from . import _bodyfit
from ._bodyfit import (  # noqa: F401  (the public names)
    Error,
    InputError,
    IoError,
    Mesh,
    NumericalError,
    PluginError,
    Step,
    advect,
    discretize,
    plane,
    read,
    read_field,
    remesh,
    set_log_level,
    set_threads,
    signed_distance,
    sphere,
    write_field,
)

__version__ = _bodyfit.__version__

__all__ = [
    "Error", "InputError", "IoError", "NumericalError", "PluginError",
    "Mesh", "Step", "Parameter", "Output", "Review", "RunResult",
    "read", "read_field", "write_field", "from_meshio", "sphere", "plane",
    "signed_distance", "advect", "discretize", "remesh", "info",
    "run", "set_threads", "set_log_level", "build_info",
]


def build_info() -> dict:
    """Version, build type, compiler, plugin ABI, cores, and where plugins are searched."""
    info = dict(_bodyfit._build_info())
    info["plugin_search_path"] = [str(p) for p in _bodyfit.plugin_search_path()]
    info["numpy"] = _np.__version__
    return info


def info(mesh: Mesh) -> dict:
    """What ``bodyfit info --json`` says of a mesh: counts, bounding box, area, quality, edge
    lengths, regions, interface, components, boundary loops, Euler characteristic, feature tags."""
    result = _json.loads(_bodyfit.info_json(mesh))
    result.pop("file", None)
    return result


# ---- declarations of a Python model ---------------------------------------------------------------

@_dataclass
class Parameter:
    """A parameter of a Python model (its ``parameters`` attribute): read from the case's
    ``[model]`` table with this default (None: required), type, unit and range; refused otherwise.
    ``type`` is inferred from the default unless given: number, integer, boolean, string, path,
    numbers."""
    name: str
    default: Any = None
    unit: str = ""
    description: str = ""
    type: Optional[str] = None
    min: Optional[float] = None
    max: Optional[float] = None
    choices: Optional[Sequence[str]] = None


@_dataclass
class Output:
    """An output of a Python model (its ``outputs`` attribute): a ``metric`` (a history.csv
    column, from compute's ``metrics``), a vertex ``field`` (in each VTU, from compute's
    ``fields``), or a ``value`` (from finish)."""
    name: str
    kind: str = "metric"
    unit: str = ""
    description: str = ""


@_dataclass
class Review:
    """A model's verdict on a candidate mesh (``review`` may also return None to accept, or False
    to reject). ``stop`` ends the run; ``next_dt`` sets the next step."""
    accept: bool = True
    reason: str = ""
    stop: bool = False
    next_dt: float = 0.0
    metrics: dict = _field(default_factory=dict)


# ---- runs -------------------------------------------------------------------------------------------

@_dataclass
class RunResult:
    """What a run left: its history (a dict of numpy arrays, or a pandas DataFrame when pandas is
    importable), the final mesh, the output directory, and how it ended."""
    history: Any
    mesh: Optional[Mesh]
    output_dir: str
    iteration: int
    time: float
    reason: str
    message: str
    exit_code: int


def _read_history(path: str, as_dataframe: bool):
    if not _os.path.exists(path):
        return {}
    try:
        import pandas  # noqa: F401
    except ImportError:
        as_dataframe = False
    if as_dataframe:
        import pandas
        # pandas' default float parser may be off by an ulp: the values the file holds, exactly.
        return pandas.read_csv(path, float_precision="round_trip")
    with open(path, newline="") as f:
        rows = list(_csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns = {}
    for i, name in enumerate(header):
        values = [row[i] for row in body]
        try:
            columns[name] = _np.array([float(v) for v in values])
        except ValueError:
            columns[name] = _np.array(values)
    return columns


def run(case, out=None, set: Optional[dict] = None, model=None, progress: bool = True,
        resume: bool = False, overwrite: bool = False, force: bool = False,
        verbose: bool = False, dataframe: bool = True) -> RunResult:
    """Run a case as ``bodyfit run`` does, into the directory ``out``.

    case       a case file (path) or a dict with the case file's tables
    out        the output directory (default for a file: <case name>.out; required for a dict)
    set        {"time.dt": 0.05, ...}: overrides, as --set key=value
    model      a Python model object (compute(step) and the optional methods); the case's
               [model] then holds its parameters (name left out, or "python")
    progress   a line per iteration on the console
    resume / overwrite / force / verbose   as the command line's --resume, --overwrite, --force,
               --verbose

    Ctrl-C (SIGINT), SIGTERM and SIGHUP end the run after the iteration in progress, checkpointed;
    run(..., resume=True) continues it. Raises InputError, PluginError (a model's failure, with its
    Python traceback), NumericalError, IoError; KeyboardInterrupt after an interruption.
    """
    if isinstance(case, dict) and out is None:
        raise InputError("run(): a case given as a dict needs out=...")
    result = _bodyfit._run(case, None if out is None else _os.fspath(out), set, model, progress,
                           resume, overwrite, force, verbose)
    outdir = result["output_dir"]
    final = _os.path.join(outdir, "final.mesh")
    run_result = RunResult(
        history=_read_history(_os.path.join(outdir, "history.csv"), dataframe),
        mesh=read(final) if _os.path.exists(final) else None,
        output_dir=outdir, iteration=result["iteration"], time=result["time"],
        reason=result["reason"], message=result["message"], exit_code=result["exit_code"])
    if result["exit_code"] == 130:
        raise KeyboardInterrupt(
            f"run interrupted after iteration {result['iteration']} (t = {result['time']}), which is saved in "
            f"{outdir}: continue with run(..., resume=True)")
    return run_result


# ---- other libraries ------------------------------------------------------------------------------

def _to_meshio(self: Mesh):
    """A meshio.Mesh: the triangles, cell data ``region``, point data from ``fields``."""
    import meshio
    return meshio.Mesh(_np.array(self.vertices), [("triangle", self.triangles)],
                       point_data={k: _np.asarray(v) for k, v in self.fields.items()},
                       cell_data={"region": [self.regions]})


def from_meshio(m) -> Mesh:
    """A Mesh from a meshio.Mesh's triangles (cell data ``region``, ``medit:ref`` or
    ``gmsh:physical`` as the regions; point data of (n,) or (n, 3) floats as fields)."""
    triangles = [c for c in m.cells if c.type == "triangle"]
    if not triangles:
        raise InputError("from_meshio: the mesh has no triangles")
    index = m.cells.index(triangles[0])
    regions = None
    for name in ("region", "medit:ref", "gmsh:physical"):
        if name in m.cell_data:
            regions = _np.ascontiguousarray(m.cell_data[name][index])
            break
    mesh = Mesh(_np.ascontiguousarray(m.points, dtype=_np.float64),
                _np.ascontiguousarray(triangles[0].data), regions)
    for name, values in m.point_data.items():
        values = _np.asarray(values)
        if values.dtype.kind == "f" and (values.ndim == 1 or (values.ndim == 2 and values.shape[1] == 3)):
            mesh.fields[name] = _np.ascontiguousarray(values, dtype=_np.float64)
    return mesh


def _to_pyvista(self: Mesh):
    """A pyvista.PolyData with cell data ``region`` and the fields as point data."""
    import pyvista
    faces = _np.hstack([_np.full((self.n_faces, 1), 3), self.triangles]).ravel()
    poly = pyvista.PolyData(_np.array(self.vertices), faces)
    poly.cell_data["region"] = self.regions
    for name, values in self.fields.items():
        poly.point_data[name] = _np.asarray(values)
    return poly


Mesh.to_meshio = _to_meshio
Mesh.to_pyvista = _to_pyvista
Mesh.from_meshio = staticmethod(from_meshio)
