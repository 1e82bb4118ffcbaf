"""Fixtures of the Python module's tests: the command line of the same build, a sphere mesh, a
level set and a velocity on it (written as Medit files, as the command line reads them)."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import bodyfit

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _find_bodyfit():
    explicit = os.environ.get("BODYFIT_EXE")
    if explicit:
        return explicit
    # The package imported lives in <build>/python/bodyfit: the program is <build>/bin/bodyfit.
    candidate = pathlib.Path(bodyfit.__file__).resolve().parents[2] / "bin" / "bodyfit"
    return str(candidate)


BODYFIT = _find_bodyfit()


def run_cli(*args, check=True, **kwargs):
    """Run the command line; returns the CompletedProcess (stdout and stderr as text)."""
    result = subprocess.run([BODYFIT, *map(str, args)], capture_output=True, text=True, **kwargs)
    if check and result.returncode != 0:
        raise AssertionError(f"bodyfit {' '.join(map(str, args))} exited {result.returncode}:\n{result.stderr}")
    return result


@pytest.fixture(scope="session")
def sphere_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sphere") / "sphere.mesh"
    run_cli("mesh", "sphere", "--faces", "3000", "-o", path)
    return path


@pytest.fixture(scope="session")
def cap_files(sphere_file, tmp_path_factory):
    """φ = polar angle − 45° (a cap around +z) and V = a rotation about x, as .sol files."""
    d = tmp_path_factory.mktemp("fields")
    mesh = bodyfit.read(sphere_file)
    x = np.array(mesh.vertices)
    phi = np.arccos(np.clip(x[:, 2], -1, 1)) - np.pi / 4
    velocity = np.cross(np.array([1.0, 0.0, 0.0]), x)
    bodyfit.write_field(d / "phi.sol", phi)
    bodyfit.write_field(d / "v.sol", velocity)
    return d / "phi.sol", d / "v.sol"
