"""Mesh and compound bodies from Python (docs/python.md "Meshes"): inline
meshes made in numpy inside a scene dict, mesh files, and their refusals."""

import numpy as np
import pytest

import odemag
from conftest import ROOT, cli_solve


def cube_mesh(edge):
    """The cube [0, edge]^3 as numpy arrays: 8 vertices, 12 outward triangles."""
    v = edge * np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)], dtype=np.float64)
    t = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]], dtype=np.int64)
    return v, t


def magnet_scene(shape):
    return {
        "cell_size": 0.002,
        "materials": {"m": {"type": "permanent", "magnetization": [0, 0, 1e6]}},
        "bodies": [{"name": "magnet", "shape": shape, "material": "m"}],
    }


def test_inline_numpy_mesh_is_the_box():
    v, t = cube_mesh(0.01)
    mesh = odemag.load(magnet_scene({"mesh": {"vertices": v, "triangles": t}})).solve()
    box = odemag.load(magnet_scene({"box": [0.01, 0.01, 0.01]})).solve()
    # A permanent magnet's moment is M V (the cubes' shares exact up to their
    # shift by 1e-10 of the mesh's size); the cells are the same cubes.
    np.testing.assert_allclose(mesh.moments[0], [0, 0, 1e6 * 1e-6], rtol=1e-9)
    assert mesh.cells.tolist() == box.cells.tolist()


def test_mesh_file_relative_to_the_scene_and_the_same_as_odemag_solve():
    path = ROOT / "examples" / "compass_needle_mesh.json"
    sol = odemag.load(path).solve()
    expected = cli_solve(path)
    np.testing.assert_array_equal(sol.moments, np.array([b["moment"] for b in expected["bodies"]]))


def test_bad_mesh_names_the_key():
    v, t = cube_mesh(0.01)
    with pytest.raises(odemag.SceneError) as e:
        odemag.load(magnet_scene({"mesh": {"vertices": v, "triangles": t[:-1]}}))
    assert e.value.key == "bodies[0].shape.mesh.triangles"
    assert "not closed: 3 boundary edges" in e.value.message


def test_compound_of_numpy_mesh_and_box():
    v, t = cube_mesh(0.01)
    scene = magnet_scene({"compound": [
        {"shape": {"box": [0.01, 0.01, 0.01]}, "position": [-0.005, 0, 0]},
        {"shape": {"mesh": {"vertices": v, "triangles": t}}, "position": [0.005, 0, 0]}]})
    sol = odemag.load(scene).solve()
    np.testing.assert_allclose(sol.moments[0], [0, 0, 1e6 * 2e-6], rtol=1e-9)
