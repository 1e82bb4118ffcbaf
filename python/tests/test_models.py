"""Velocity models written in Python: through `bodyfit run` (the python plugin) and through
bodyfit.run, against the C++ conormal model; failures, parameters, reviews, checkpoints, resume."""
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import bodyfit
from conftest import ROOT, run_cli

MODELS = pathlib.Path(__file__).resolve().parent / "models"
EXAMPLE = ROOT / "examples" / "python" / "conormal.py"
# The main example, coarser and shorter: a test takes a second.
QUICK_SET = {"surface.h": 0.1, "remesh.hmax": 0.1, "remesh.hmin": 0.01, "time.final_time": 0.3, "output.png_every": 0}
QUICK = [f"{k}={v}" for k, v in QUICK_SET.items()]


def sets(*extra):
    return [a for s in [*QUICK, *extra] for a in ("--set", s)]


def python_case(tmp_path, module, cls, **parameters):
    """The main example's case with [model] the python model `cls` of `module`."""
    lines = [f'[surface]\ngenerator = "sphere"\nh = 0.1\n',
             '[region]\nshape = "cap"\naxis = [0.0, 0.0, 1.0]\nangle = 45.0\n',
             f'[model]\nname = "python"\nmodule = "{module}"\nclass = "{cls}"']
    lines += [f"{k} = {v!r}" for k, v in parameters.items()]
    lines += ['\n[time]\ncfl = 0.5\nfinal_time = 0.3\n', '[remesh]\nhmax = 0.1\nhmin = 0.01\nhausd = 0.001\n',
              '[output]\npng_every = 0\n']
    path = tmp_path / "case.toml"
    path.write_text("\n".join(lines))
    return path


@pytest.fixture(scope="module")
def cpp_run(tmp_path_factory):
    """The C++ conormal model on the quick case: what the Python models must reproduce."""
    out = tmp_path_factory.mktemp("cpp") / "out"
    run_cli("run", ROOT / "meshes" / "cases" / "sphere_cap.toml", "-o", out, *sets())
    return out


def test_python_model_from_the_command_line(cpp_run, tmp_path):
    run_cli("run", ROOT / "examples" / "python" / "sphere_cap_python.toml", "-o", tmp_path / "out", *sets())
    assert (tmp_path / "out" / "final.mesh").read_bytes() == (cpp_run / "final.mesh").read_bytes()


def test_python_model_from_python(cpp_run, tmp_path):
    sys.path.insert(0, str(EXAMPLE.parent))
    from conormal import Conormal
    case = ROOT / "meshes" / "cases" / "sphere_cap.toml"
    overrides = QUICK_SET
    with pytest.raises(bodyfit.InputError, match='name = "conormal" and a model object'):
        bodyfit.run(case, out=tmp_path / "refused", model=Conormal(), set=overrides, progress=False)
    # The same case as a dict, without a model name: the object is the model.
    import tomllib
    table = tomllib.loads(case.read_text())
    del table["model"]["name"]
    result = bodyfit.run(table, out=tmp_path / "out", model=Conormal(), set=overrides, progress=False)
    assert (tmp_path / "out" / "final.mesh").read_bytes() == (cpp_run / "final.mesh").read_bytes()
    assert result.reason == "final time reached" or result.time == pytest.approx(0.3)
    assert result.mesh.n_faces > 0
    assert list(result.history["speed"])[-1] == 1.0
    plain = bodyfit.run(table, out=tmp_path / "again", model=Conormal(), set=overrides, progress=False,
                        dataframe=False)
    assert isinstance(plain.history["area"], np.ndarray)
    np.testing.assert_array_equal(plain.history["area"], np.asarray(result.history["area"]))


def test_band_vertices_in_a_banded_state(tmp_path):
    """The state after the first has d in a band: band_vertices lists the band and its ring, where
    the conormal is filled; the first state's d is whole (empty: every vertex)."""

    class Probe:
        name = "band_probe"

        def __init__(self):
            self.sizes = []

        def compute(self, step):
            band = np.asarray(step.band_vertices)
            if len(step.active_vertices) == 0:
                d = np.asarray(step.distance)
                self.sizes.append((len(band), len(d)))
                if len(band):
                    assert np.all(np.diff(band) > 0)
                    assert np.all(np.abs(d[band]) <= np.abs(d).max())
                    outside = np.setdiff1d(np.arange(len(d)), band)
                    assert np.all(np.asarray(step.conormal)[outside] == 0)
            return {"velocity": np.asarray(step.conormal).copy()}

    probe = Probe()
    case = {"surface": {"generator": "sphere", "h": 0.04}, "region": {"shape": "cap", "axis": [0.0, 0.0, 1.0], "angle": 45.0},
            "time": {"cfl": 0.5, "iterations": 4}, "remesh": {"hmax": 0.04, "hmin": 0.004}, "output": {"png_every": 0}}
    bodyfit.run(case, out=tmp_path / "out", model=probe, progress=False)
    # The first state and the final one (its outputs): d on the whole surface; between, a band.
    assert probe.sizes[0][0] == 0 and probe.sizes[-1][0] == 0
    assert len(probe.sizes) == 5
    assert all(0 < band < 0.6 * n for band, n in probe.sizes[1:-1]), probe.sizes


def test_a_case_python_model_from_python(cpp_run, tmp_path):
    """A case naming the python model runs from Python too (in this interpreter, not the plugin's)."""
    case = ROOT / "examples" / "python" / "sphere_cap_python.toml"
    bodyfit.run(case, out=tmp_path / "out", set=QUICK_SET,
                progress=False)
    assert (tmp_path / "out" / "final.mesh").read_bytes() == (cpp_run / "final.mesh").read_bytes()


@pytest.mark.parametrize("cls, code, message", [
    ("NoCompute", 4, "has no compute"),
    ("WrongLength", 4, r"compute\(\): the velocity: shape \(\d+, 3\), expected \(\d+, 3\)"),
    ("NaNVelocity", 4, "NaN at row 5"),
    ("NotArray", 4, "compute\\(\\) returned a list"),
    ("Raises", 4, "ValueError: boom at iteration 2"),
    ("KeptStep", 4, "no longer valid"),
    ("Missing", 1, "no class 'Missing'"),
])
def test_model_failures_from_the_command_line(tmp_path, cls, code, message):
    case = python_case(tmp_path, str(MODELS / "faulty.py"), cls)
    result = run_cli("run", case, "-o", tmp_path / "out", check=False)
    assert result.returncode == code, result.stderr
    import re
    assert re.search(message, result.stderr), result.stderr


def test_model_failures_from_python(tmp_path):
    sys.path.insert(0, str(MODELS))
    import faulty
    case = {"surface": {"generator": "sphere", "h": 0.1}, "region": {"shape": "cap", "angle": 45.0},
            "time": {"cfl": 0.5, "final_time": 0.3}, "output": {"png_every": 0}}
    with pytest.raises(bodyfit.PluginError, match="boom at iteration 2") as error:
        bodyfit.run(case, out=tmp_path / "a", model=faulty.Raises(), progress=False)
    assert "Traceback" in str(error.value) and "faulty.py" in str(error.value)
    with pytest.raises(bodyfit.PluginError, match="NaN at row 5"):
        bodyfit.run(case, out=tmp_path / "b", model=faulty.NaNVelocity(), progress=False)
    with pytest.raises(bodyfit.PluginError, match="has no compute"):
        bodyfit.run(case, out=tmp_path / "c", model=faulty.NoCompute(), progress=False)


def test_an_import_error_is_a_model_failure(tmp_path):
    case = python_case(tmp_path, str(MODELS / "broken_import.py"), "Model")
    result = run_cli("run", case, "-o", tmp_path / "out", check=False)
    assert result.returncode == 4, result.stderr
    assert "No module named 'no_such_module_anywhere'" in result.stderr
    missing = python_case(tmp_path, str(MODELS / "no_such_file.py"), "Model")
    result = run_cli("run", missing, "-o", tmp_path / "out2", check=False)
    assert result.returncode == 1 and "no_such_file.py" in result.stderr


def test_parameters_are_declared_and_checked(tmp_path):
    case = python_case(tmp_path, str(MODELS / "stateful.py"), "Counting")
    result = run_cli("run", case, "-o", tmp_path / "a", "--set", "model.sped=2", check=False)
    assert result.returncode == 1 and "unknown key 'sped'" in result.stderr and "speed" in result.stderr
    result = run_cli("run", case, "-o", tmp_path / "b", "--set", "model.speed=-1", check=False)
    assert result.returncode == 1 and "speed" in result.stderr and "out of range" in result.stderr
    result = run_cli("run", case, "-o", tmp_path / "c", "--set", 'model.speed="fast"', check=False)
    assert result.returncode == 1 and "speed" in result.stderr


def read_history(path):
    return bodyfit._read_history(str(path), False)


def test_outputs_review_and_helpers(tmp_path):
    case = python_case(tmp_path, str(MODELS / "stateful.py"), "Counting", reject_at=3)
    run_cli("run", case, "-o", tmp_path / "out")
    history = read_history(tmp_path / "out" / "history.csv")
    assert history["rejections"][3] == 1 and history["rejections"].sum() == 1
    assert np.max(history["mass_error"][1:]) < 1e-9
    assert list(history["calls"][1:]) == sorted(history["calls"][1:])
    step = bodyfit.read(tmp_path / "out" / "step_00002.vtu")
    np.testing.assert_allclose(step.fields["speed_field"][:10], 1.0, atol=1e-12)


def test_interrupt_and_resume_from_the_command_line(tmp_path):
    case = python_case(tmp_path, str(MODELS / "stateful.py"), "Counting")
    run_cli("run", case, "-o", tmp_path / "whole")
    interrupted = run_cli("run", case, "-o", tmp_path / "parts", "--inject-signal", "3:INT", check=False)
    assert interrupted.returncode == 130, interrupted.stderr
    run_cli("run", case, "-o", tmp_path / "parts", "--resume")
    assert (tmp_path / "parts" / "final.mesh").read_bytes() == (tmp_path / "whole" / "final.mesh").read_bytes()
    # The model's state (its count of calls) came back from the checkpoint.
    whole = read_history(tmp_path / "whole" / "history.csv")
    parts = read_history(tmp_path / "parts" / "history.csv")
    np.testing.assert_array_equal(whole["calls"], parts["calls"])


SCRIPT = """
import sys
sys.path.insert(0, {models!r})
import bodyfit, stateful
case = {case!r}
model = stateful.Counting()
try:
    bodyfit.run(case, out={out!r}, model=model, set={{"model.interrupt_at": 3}}, progress=False)
except KeyboardInterrupt as e:
    print("interrupted:", e)
    result = bodyfit.run(case, out={out!r}, model=stateful.Counting(), set={{"model.interrupt_at": 3}},
                         progress=False, resume=True)
    print("resumed to", result.iteration)
"""


def test_interrupt_and_resume_from_python(tmp_path):
    case = {"surface": {"generator": "sphere", "h": 0.1}, "region": {"shape": "cap", "angle": 45.0},
            "time": {"cfl": 0.5, "final_time": 0.3}, "remesh": {"hmax": 0.1, "hmin": 0.01, "hausd": 0.001},
            "output": {"png_every": 0}}
    sys.path.insert(0, str(MODELS))
    import stateful as s
    whole = bodyfit.run(case, out=tmp_path / "whole", model=s.Counting(), progress=False)
    script = SCRIPT.format(models=str(MODELS), case=case, out=str(tmp_path / "parts"))
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                            env=dict(os.environ))
    # SIGINT during the compute of state 3: the step to state 4 completes and is saved.
    assert "interrupted: run interrupted after iteration 4" in result.stdout, result.stdout + result.stderr
    assert f"resumed to {whole.iteration}" in result.stdout, result.stdout + result.stderr
    assert (tmp_path / "parts" / "final.mesh").read_bytes() == (tmp_path / "whole" / "final.mesh").read_bytes()
    parts = read_history(tmp_path / "parts" / "history.csv")
    np.testing.assert_array_equal(np.asarray(whole.history["calls"]), parts["calls"])
