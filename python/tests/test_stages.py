"""Every stage from Python against the command line on the same input: byte-identical outputs."""
import json

import numpy as np
import pytest

import bodyfit
from conftest import run_cli


def same_bytes(a, b):
    assert open(a, "rb").read() == open(b, "rb").read(), f"{a} and {b} differ"


def test_distance_matches_the_command_line(sphere_file, cap_files, tmp_path):
    phi_file, _ = cap_files
    run_cli("distance", sphere_file, "--phi", phi_file, "-o", tmp_path / "cli.sol")
    mesh = bodyfit.read(sphere_file)
    d = bodyfit.signed_distance(mesh, bodyfit.read_field(phi_file))
    bodyfit.write_field(tmp_path / "py.sol", d)
    same_bytes(tmp_path / "cli.sol", tmp_path / "py.sol")
    # The geodesic distance to the 45° circle on the unit sphere is the difference of polar angles.
    exact = np.arccos(np.clip(np.array(mesh.vertices)[:, 2], -1, 1)) - np.pi / 4
    near = np.abs(exact) < 0.2  # where the cut reads it; beyond, the march's error grows with |d|
    assert np.max(np.abs(d - exact)[near]) < 0.005


def test_distance_to_a_region_leaves_the_mesh_as_it_was(sphere_file, tmp_path):
    mesh = bodyfit.read(sphere_file)
    z = np.array(mesh.vertices)[:, 2]
    regions = np.where(z[mesh.triangles].mean(axis=1) > 0, 5, 7)
    labelled = bodyfit.Mesh(np.array(mesh.vertices), mesh.triangles, regions)
    labelled.write(tmp_path / "labelled.mesh")
    run_cli("distance", tmp_path / "labelled.mesh", "--region", 5, "-o", tmp_path / "cli.sol")
    d = bodyfit.signed_distance(labelled, region=5)
    bodyfit.write_field(tmp_path / "py.sol", d)
    same_bytes(tmp_path / "cli.sol", tmp_path / "py.sol")
    np.testing.assert_array_equal(labelled.regions, regions)


def test_advect_matches_the_command_line(sphere_file, cap_files, tmp_path):
    phi_file, v_file = cap_files
    run_cli("advect", sphere_file, "--phi", phi_file, "--velocity", v_file, "--time", 0.3, "--rk", 4,
            "-o", tmp_path / "cli.sol")
    mesh = bodyfit.read(sphere_file)
    out = bodyfit.advect(mesh, bodyfit.read_field(phi_file), bodyfit.read_field(v_file), 0.3, rk=4)
    bodyfit.write_field(tmp_path / "py.sol", out)
    same_bytes(tmp_path / "cli.sol", tmp_path / "py.sol")


def test_discretize_matches_the_command_line(sphere_file, cap_files, tmp_path):
    phi_file, _ = cap_files
    run_cli("discretize", sphere_file, "--phi", phi_file, "--hausd", 0.002, "-o", tmp_path / "cli.mesh")
    mesh = bodyfit.read(sphere_file)
    faces = mesh.n_faces
    cut = bodyfit.discretize(mesh, bodyfit.read_field(phi_file), hausd=0.002)
    cut.write(tmp_path / "py.mesh")
    same_bytes(tmp_path / "cli.mesh", tmp_path / "py.mesh")
    assert set(np.unique(cut.regions)) == {2, 3}
    assert len(cut.interface_edges) > 0
    assert mesh.n_faces == faces  # the input is left as it was


def test_remesh_matches_the_command_line(sphere_file, tmp_path):
    run_cli("remesh", sphere_file, "--hmax", 0.1, "-o", tmp_path / "cli.mesh")
    out = bodyfit.remesh(bodyfit.read(sphere_file), hmax=0.1)
    out.write(tmp_path / "py.mesh")
    same_bytes(tmp_path / "cli.mesh", tmp_path / "py.mesh")


def test_info_matches_the_command_line(sphere_file):
    cli = json.loads(run_cli("info", sphere_file, "--json").stdout)
    cli.pop("file")
    assert bodyfit.info(bodyfit.read(sphere_file)) == cli


@pytest.mark.parametrize("call, message", [
    (lambda m, phi: bodyfit.remesh(m, hmin=0.2, hmax=0.1), "hmin: 0.2 exceeds hmax 0.1"),
    (lambda m, phi: bodyfit.remesh(m, hmax=-1), "hmax: -1"),
    (lambda m, phi: bodyfit.remesh(m, hgrad=0.5), "hgrad"),
    (lambda m, phi: bodyfit.discretize(m, phi, snap=0.9), "snap: 0.9 is not in"),
    (lambda m, phi: bodyfit.discretize(m, phi[:-1]), r"phi: shape \(\d+,\), expected \(\d+,\)"),
    (lambda m, phi: bodyfit.advect(m, phi, np.zeros((m.n_vertices, 3)), 1.0, rk=3), "rk: 3"),
    (lambda m, phi: bodyfit.advect(m, phi, np.zeros((m.n_vertices, 2)), 1.0), "velocity: shape"),
    (lambda m, phi: bodyfit.signed_distance(m), "either phi or region"),
    (lambda m, phi: bodyfit.signed_distance(m, np.full(m.n_vertices, np.nan)), "phi: NaN at row 0"),
])
def test_bad_options_are_refused(sphere_file, cap_files, call, message):
    mesh = bodyfit.read(sphere_file)
    phi = bodyfit.read_field(cap_files[0])
    with pytest.raises(bodyfit.InputError, match=message):
        call(mesh, phi)


def test_a_lost_characteristic_is_a_numerical_error(sphere_file, cap_files):
    mesh = bodyfit.read(sphere_file)
    phi = bodyfit.read_field(cap_files[0])
    huge = np.cross(np.array([0.0, 0.0, 1.0]), np.array(mesh.vertices)) * 1e200
    with pytest.raises(bodyfit.InputError, match="sub-steps"):  # the work estimated is refused first
        bodyfit.advect(mesh, phi, huge, 1.0)
    with pytest.raises(bodyfit.NumericalError, match="characteristics were lost"):
        bodyfit.advect(mesh, phi, huge, 1.0, max_substeps=0)


def test_the_face_budget_applies(sphere_file):
    with pytest.raises(bodyfit.InputError, match="faces"):
        bodyfit.remesh(bodyfit.read(sphere_file), hmax=1e-6, hmin=1e-7, hausd=1e-7)


def test_stages_release_the_gil(sphere_file):
    """Two remeshes in two Python threads overlap (each holds no GIL while it works)."""
    import threading
    import time
    mesh = bodyfit.read(sphere_file)
    start = time.perf_counter()
    bodyfit.remesh(mesh, hmax=0.02)
    alone = time.perf_counter() - start
    ticks = []

    def tick():
        t_end = time.perf_counter() + alone
        while time.perf_counter() < t_end:
            ticks.append(1)
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    bodyfit.remesh(mesh, hmax=0.02)
    thread.join()
    # With the GIL held for the whole remesh the ticking thread would get ~one turn.
    assert len(ticks) > 10
