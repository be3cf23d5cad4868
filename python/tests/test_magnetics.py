"""odemag.Magnetics (the scene's magnetics at poses the caller sets) against
`odemag solve` of the same poses; copies and views of the result arrays; a
PyODE world driven through it when python3-pyode is installed."""

import json

import numpy as np
import pytest

import odemag
from conftest import ROOT, cli_solve

SCENE = ROOT / "examples/bar_and_ball.json"


def poses(scene_dict):
    positions = np.array([b["position"] for b in scene_dict["bodies"]], dtype=float)
    quaternions = np.array([b.get("orientation", [1, 0, 0, 0]) for b in scene_dict["bodies"]], dtype=float)
    return positions, quaternions


@pytest.mark.parametrize("ball_z", [0.05, 0.07])
def test_magnetics_at_poses_equals_cli_solve(ball_z, tmp_path):
    scene = json.loads(SCENE.read_text())
    m = odemag.Magnetics(odemag.load(scene))  # the scene as written: ball at z = 0.05
    scene["bodies"][1]["position"] = [0.001, 0.0, ball_z]
    path = tmp_path / "moved.json"
    path.write_text(json.dumps(scene))
    expected = cli_solve(path)

    positions, quaternions = poses(scene)
    m.set_poses(positions, quaternions)
    report = m.compute()
    assert report["converged"]
    for key, array in (("moment", m.moments), ("force", m.forces), ("torque", m.torques)):
        np.testing.assert_array_equal(array, [b[key] for b in expected["bodies"]], err_msg=key)
    # The same poses as rotation matrices (ODE's dBodyGetRotation layout).
    m.set_poses(positions, np.array([np.eye(3)] * len(positions)))
    m.compute()
    np.testing.assert_array_equal(m.forces, [b["force"] for b in expected["bodies"]])


def test_magnetics_pose_errors():
    m = odemag.Magnetics(odemag.load(SCENE))
    with pytest.raises(ValueError, match=r"positions: expected an array of shape \(2, 3\)"):
        m.set_poses(np.zeros((3, 3)), np.zeros((3, 4)))
    with pytest.raises(ValueError, match="rotations"):
        m.set_poses(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="not finite"):
        m.set_poses([[0, 0, 0.1], [0, 0, np.inf]], [[1, 0, 0, 0]] * 2)


def test_magnetics_controls_take_the_scenes_ranges():
    # Each refused with ValueError naming the argument and the body, changing nothing.
    m = odemag.Magnetics(odemag.load(SCENE))
    with pytest.raises(ValueError, match=r'set_poses: .*body 0 "bar".*rotation .* not orthonormal'):
        m.set_poses([[0, 0, 0], [0, 0, 0.1]], [2 * np.eye(3), np.eye(3)])
    with pytest.raises(ValueError, match=r'set_poses: .*body 1 "ball".*farther than'):
        m.set_poses([[0, 0, 0], [0, 0, 2e6]], [[1, 0, 0, 0]] * 2)
    with pytest.raises(ValueError, match=r'set_magnetization_scale: the scale 1e\+300 of body 0 "bar"'):
        m.set_magnetization_scale("bar", 1e300)
    assert m.magnetization_scale("bar") == 1.0
    with pytest.raises(ValueError, match=r"external_field: .*stronger than the largest accepted"):
        m.external_field = [1e160, 0, 0]
    np.testing.assert_array_equal(m.external_field, [0, 0, 0])
    m.set_poses([[0, 0, 0], [0, 0, 0.1]], [np.eye(3)] * 2)
    m.compute()
    assert np.all(np.isfinite(m.forces))


def test_field_point_beyond_the_length_bound_names_its_index():
    with pytest.raises(ValueError, match=r"points\[1\]: farther than the largest accepted length"):
        odemag.load(SCENE).field([[0, 0, 0.1], [1e300, 0, 0]])


def test_result_arrays_are_views_of_their_own_buffers():
    scene = odemag.load(SCENE)
    sol = scene.solve()
    field = scene.field(np.array([[0.0, 0.0, 0.2], [0.0, 0.0, 0.3]]))
    for a in (sol.moments, sol.forces, sol.torques, field.B, field.H):
        assert a.dtype == np.float64 and a.flags.c_contiguous
        assert not a.flags.owndata and type(a.base).__name__ == "PyCapsule"  # no copy of the C++ vector
    assert sol.forces.shape == (2, 3) and field.B.shape == (2, 3)
    assert sol.present.dtype == np.bool_ and sol.cells.dtype.kind == "i"
    # Units: the ball's moment (A m^2) is the field's source; B = mu0 H far away (T, A/m).
    np.testing.assert_allclose(field.B, 4e-7 * np.pi * field.H, rtol=1e-12)


def test_pyode_world_driven_by_magnetics():
    ode = pytest.importorskip("ode", reason="python3-pyode is not installed")
    scene_dict = json.loads(SCENE.read_text())
    m = odemag.Magnetics(odemag.load(scene_dict))
    world = ode.World()
    world.setGravity((0, 0, -9.81))
    bodies = []
    for b in scene_dict["bodies"]:
        body = ode.Body(world)
        mass = ode.Mass()
        mass.setSphere(7870, 0.006)  # density, radius (PyODE 1.2 swaps setSphereTotal's arguments)
        body.setMass(mass)
        body.setPosition(b["position"])
        bodies.append(body)
    bar, ball = bodies
    z0 = ball.getPosition()[2]
    pulls = []
    for _ in range(20):  # 40 ms: a few mm up, no collision (this world has no geometry)
        m.set_poses([b.getPosition() for b in bodies], [b.getQuaternion() for b in bodies])
        m.compute()
        pulls.append(m.forces[1][2])
        ball.addForce(tuple(m.forces[1]))  # the bar is held: no force added to it
        world.step(0.002)
        bar.setPosition(scene_dict["bodies"][0]["position"])
        bar.setLinearVel((0, 0, 0))
    weight = 9.81 * 7870 * 4 / 3 * np.pi * 0.006 ** 3
    assert pulls[0] > weight  # pulled up harder than its weight ...
    assert all(np.diff(pulls) > 0)  # ... harder as it comes closer ...
    assert z0 + 1e-3 < ball.getPosition()[2] < 0.08  # ... so it rises towards the bar
