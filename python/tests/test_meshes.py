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


def icosphere(radius, levels):
    """A ball as the icosahedron subdivided `levels` times (numpy arrays)."""
    g = (1 + 5 ** 0.5) / 2
    v = [[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
         [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]]
    v = [list(np.array(p) / np.linalg.norm(p)) for p in v]
    t = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
         [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    for _ in range(levels):
        mid = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = np.array(v[a]) + np.array(v[b])
                v.append(list(p / np.linalg.norm(p)))
                mid[key] = len(v) - 1
            return mid[key]
        nxt = []
        for a, b, c in t:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            nxt += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        t = nxt
    return radius * np.array(v), np.array(t)


def test_magnetics_of_a_mesh_ball_at_poses_you_set():
    """A PyODE program with a trimesh ball (its geom from the same arrays)
    takes the mesh's forces from Magnetics: those of the sphere within 1%."""
    v, t = icosphere(0.005, 4)
    forces = []
    for shape in ({"mesh": {"vertices": v, "triangles": t}}, {"sphere": 0.005}):
        scene = {
            "materials": {"m": {"type": "permanent", "magnetization": [0, 0, 9e5]},
                          "iron": {"type": "soft", "saturation": 1.6e6, "susceptibility": 1000}},
            "bodies": [{"name": "magnet", "shape": {"cylinder": {"radius": 0.006, "length": 0.01}},
                        "material": "m", "cell_size": 0.002},
                       {"name": "ball", "shape": shape, "material": "iron", "cell_size": 0.005 / 3}]}
        m = odemag.Magnetics(odemag.load(scene))
        m.set_poses(np.array([[0, 0, 0], [0.001, 0, 0.0125]]), np.array([[1, 0, 0, 0], [1, 0, 0, 0]]))
        m.compute()
        forces.append(m.forces[1].copy())
    assert forces[0][2] < 0
    np.testing.assert_allclose(forces[0], forces[1], rtol=0.01, atol=1e-3 * abs(forces[1][2]))
