"""Meshes and fields as numpy arrays: round trips, views, files, meshio, and bad arrays."""
import numpy as np
import pytest

import bodyfit

# Two triangles of a unit square, and an octahedron (closed).
SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=np.float64)
SQUARE_T = np.array([[0, 1, 2], [0, 2, 3]])
OCTA_V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64)
OCTA_T = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def test_arrays_round_trip():
    regions = np.array([3, 3, 2, 2, 2, 2, 3, 2])
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T, regions)
    assert (mesh.n_vertices, mesh.n_faces) == (6, 8)
    np.testing.assert_array_equal(mesh.vertices, OCTA_V)
    np.testing.assert_array_equal(mesh.triangles, OCTA_T)
    np.testing.assert_array_equal(mesh.regions, regions)
    assert mesh.triangles.dtype == np.int64 and mesh.regions.dtype == np.int32


def test_interface_edges_separate_the_regions():
    # Upper half (faces 0-3) inside: the interface is the equator, 4 edges between its 4 vertices.
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T, np.array([3, 3, 3, 3, 2, 2, 2, 2]))
    edges = mesh.interface_edges
    assert edges.shape == (4, 2)
    assert set(np.unique(edges)) == {0, 1, 2, 3}


def test_vertices_are_a_view_of_the_mesh():
    mesh = bodyfit.Mesh(SQUARE_V, SQUARE_T)
    v = mesh.vertices
    v[2, 2] = 0.5  # moves the mesh's own vertex
    assert mesh.vertices[2, 2] == 0.5
    del mesh  # the view keeps the mesh alive
    assert v[2, 2] == 0.5


@pytest.mark.parametrize("extension", [".mesh", ".meshb", ".obj", ".off", ".ply", ".stl", ".vtu"])
def test_files_round_trip(tmp_path, extension):
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T, np.array([3, 3, 3, 3, 2, 2, 2, 2]))
    path = tmp_path / ("octa" + extension)
    mesh.write(path)
    back = bodyfit.read(path)
    assert back.n_faces == 8
    np.testing.assert_allclose(np.sort(back.vertices, axis=0), np.sort(OCTA_V, axis=0), atol=1e-6)
    if extension in (".mesh", ".meshb", ".vtu"):  # the formats that keep regions
        np.testing.assert_array_equal(np.sort(back.regions), np.sort(mesh.regions))


def test_vtu_keeps_fields(tmp_path):
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T)
    mesh.fields["height"] = OCTA_V[:, 2].copy()
    mesh.fields["position"] = OCTA_V.copy()
    mesh.write(tmp_path / "f.vtu")
    back = bodyfit.read(tmp_path / "f.vtu")
    np.testing.assert_array_equal(back.fields["height"], OCTA_V[:, 2])
    np.testing.assert_array_equal(back.fields["position"], OCTA_V)


def test_sol_files_round_trip(tmp_path):
    values = np.linspace(-1, 1, 6)
    vectors = np.arange(18, dtype=np.float64).reshape(6, 3)
    bodyfit.write_field(tmp_path / "s.sol", values)
    bodyfit.write_field(tmp_path / "v.solb", vectors)
    np.testing.assert_array_equal(bodyfit.read_field(tmp_path / "s.sol"), values)
    np.testing.assert_array_equal(bodyfit.read_field(tmp_path / "v.solb", n_vertices=6), vectors)
    with pytest.raises(bodyfit.InputError, match="7"):
        bodyfit.read_field(tmp_path / "s.sol", n_vertices=7)


def test_meshio_round_trip():
    meshio = pytest.importorskip("meshio")
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T, np.array([3, 3, 3, 3, 2, 2, 2, 2]))
    mesh.fields["z"] = OCTA_V[:, 2].copy()
    m = mesh.to_meshio()
    assert isinstance(m, meshio.Mesh)
    back = bodyfit.from_meshio(m)
    np.testing.assert_array_equal(back.triangles, OCTA_T)
    np.testing.assert_array_equal(back.regions, mesh.regions)
    np.testing.assert_array_equal(back.fields["z"], OCTA_V[:, 2])


def test_meshio_reads_what_bodyfit_writes(tmp_path):
    meshio = pytest.importorskip("meshio")
    mesh = bodyfit.Mesh(OCTA_V, OCTA_T, np.array([3, 3, 3, 3, 2, 2, 2, 2]))
    mesh.write(tmp_path / "o.mesh")
    back = bodyfit.from_meshio(meshio.read(tmp_path / "o.mesh"))
    np.testing.assert_array_equal(np.sort(back.regions), np.sort(mesh.regions))


@pytest.mark.parametrize("vertices, triangles, message", [
    (OCTA_V[:, :2].copy(), OCTA_T, r"vertices: shape \(6, 2\), expected \(n, 3\)"),
    (OCTA_V.astype(np.int64), OCTA_T, "vertices: dtype int64, expected float64"),
    (np.asfortranarray(OCTA_V), OCTA_T, "strided"),
    (OCTA_V, OCTA_T.astype(np.float64), "triangles: dtype float64, expected integers"),
    ([[0.0, 0.0, 0.0]], OCTA_T, "vertices: a numpy array of shape .* got a list"),
    (OCTA_V, OCTA_T + 1, r"triangles\[\d\] refers to vertex 6, expected an index in 0..5"),
    (OCTA_V, -OCTA_T, r"refers to vertex -\d"),
])
def test_bad_arrays_are_refused(vertices, triangles, message):
    with pytest.raises(bodyfit.InputError, match=message):
        bodyfit.Mesh(vertices, triangles)


def test_nan_vertex_is_named():
    v = OCTA_V.copy()
    v[4, 1] = np.nan
    with pytest.raises(bodyfit.InputError, match="row 4"):
        bodyfit.Mesh(v, OCTA_T)


def test_degenerate_and_region_overflow():
    collinear = np.array([[0, 0, 0], [2, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
    with pytest.raises(bodyfit.InputError, match="zero area"):
        bodyfit.Mesh(collinear, np.array([[0, 1, 3], [0, 2, 1]]))
    with pytest.raises(bodyfit.InputError, match="32 bits"):
        bodyfit.Mesh(OCTA_V, OCTA_T, np.array([2**32 + 3] + [2] * 7))
    with pytest.raises(bodyfit.InputError, match="regions"):
        bodyfit.Mesh(OCTA_V, OCTA_T, np.array([3, 2]))


def test_errors_are_one_family():
    assert issubclass(bodyfit.InputError, bodyfit.Error) and issubclass(bodyfit.InputError, ValueError)
    assert issubclass(bodyfit.NumericalError, ArithmeticError)
    assert issubclass(bodyfit.IoError, OSError)
    with pytest.raises(bodyfit.InputError, match="no_such.mesh"):
        bodyfit.read("no_such.mesh")


def test_version_and_build_info():
    assert bodyfit.__version__.count(".") == 2
    info = bodyfit.build_info()
    assert info["version"] == bodyfit.__version__
    assert info["plugin_abi"].startswith("3.")
    bodyfit.set_threads(1)
    bodyfit.set_threads(0)
    with pytest.raises(bodyfit.InputError):
        bodyfit.set_threads(-1)


def test_every_option_is_documented_and_stubbed():
    """help(bodyfit.<stage>) explains each keyword, and the stubs declare the same defaults."""
    import ast
    import pathlib
    import re
    stubs = (pathlib.Path(bodyfit.__file__).parent / "_bodyfit.pyi").read_text()
    for stage in (bodyfit.signed_distance, bodyfit.advect, bodyfit.discretize, bodyfit.remesh):
        doc = stage.__doc__
        signature = doc.splitlines()[0]
        names = re.findall(r"(\w+): [^,)]+", signature[signature.index("(") + 1:])
        for name in names:
            assert re.search(rf"^{name}\s+\S", doc, re.M), f"{stage.__name__}: option {name} is not explained"
        defaults = dict(re.findall(r"(\w+): [\w\[\]\.]+ = ([^,)]+)", signature))
        stub = stubs[stubs.index(f"def {stage.__name__}("):]
        stub = stub[:stub.index("...")]
        stub_defaults = dict(re.findall(r"(\w+): [\w\[\]\.]+ = ([^,)]+)", stub))
        assert stub_defaults.keys() == defaults.keys(), stage.__name__
        for name, value in defaults.items():
            assert ast.literal_eval(stub_defaults[name]) == ast.literal_eval(value), f"{stage.__name__}: {name}"


def test_generators_and_log_level():
    sphere = bodyfit.sphere(faces=2000, radius=2.0)
    assert abs(sphere.n_faces - 2000) <= 200
    np.testing.assert_allclose(np.linalg.norm(sphere.vertices, axis=1), 2.0, rtol=1e-12)
    assert bodyfit.info(sphere)["area"] == pytest.approx(16 * np.pi, rel=0.01)
    square = bodyfit.plane(size=1.0, h=0.1)
    assert bodyfit.info(square)["area"] == pytest.approx(1.0, rel=1e-9)
    assert bodyfit.info(square)["boundary_loops"]["count"] == 1
    with pytest.raises(bodyfit.InputError, match="faces: 3 is below 20"):
        bodyfit.sphere(faces=3)
    with pytest.raises(bodyfit.InputError, match="h: -1"):
        bodyfit.plane(h=-1)
    bodyfit.set_log_level("warning")
    bodyfit.set_log_level("info")
    with pytest.raises(bodyfit.InputError, match="expected trace"):
        bodyfit.set_log_level("loud")


def test_values_of_the_wrong_kind_are_refused(tmp_path):
    mesh = bodyfit.sphere(faces=500)
    mesh.fields["x"] = [1.0, 2.0]
    with pytest.raises(bodyfit.InputError, match="field x: a numpy array"):
        mesh.write(tmp_path / "m.vtu")
    case = {"surface": {"generator": "sphere", "h": 0.2}, "region": {"shape": "cap", "angle": 45.0},
            "model": {"name": "conormal"}, "time": {"dt": 0.1, "final_time": 0.1}}
    with pytest.raises(bodyfit.InputError, match="set: a dict"):
        bodyfit.run(case, out=tmp_path / "out", set=["time.dt=0.05"], progress=False)
    with pytest.raises(bodyfit.InputError, match="a set cannot go into a case"):
        bodyfit.run(case, out=tmp_path / "out2", set={"time.dt": {0.1}}, progress=False)
