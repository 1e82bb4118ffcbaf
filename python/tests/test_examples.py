"""The Python examples run as a user runs them, and meet their exact solutions."""
import re
import subprocess
import sys

from conftest import ROOT

EXAMPLES = ROOT / "examples" / "python"


def run_example(name, tmp_path, *args):
    result = subprocess.run([sys.executable, str(EXAMPLES / name), *args], cwd=tmp_path, capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_conormal_example_reaches_the_half_sphere(tmp_path):
    out = run_example("conormal.py", tmp_path)
    area, exact = map(float, re.search(r"\|G\| = ([\d.]+) \(exact: ([\d.]+)\)", out).groups())
    assert abs(area / exact - 1) < 0.002  # 2π at T; the method is within 0.1 % at h = 0.05


def test_curvature_flow_example_follows_the_exact_shrinking_cap(tmp_path):
    out = run_example("curvature_flow.py", tmp_path)
    error = float(re.search(r"error ([\d.]+) %", out).group(1))
    assert error < 1.5


def test_fire_ensemble_example_writes_its_plot(tmp_path):
    out = run_example("fire_ensemble.py", tmp_path, "--hours", "0.5", "--out", "ens")
    assert out.count("km²") == 4
    assert (tmp_path / "ens" / "burnt_area.png").stat().st_size > 10000
