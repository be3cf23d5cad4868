"""odemag.Simulation against `odemag run`: the same steps, the same final
state and the same outcomes, bit for bit; the state and per-step arrays."""

import json
import threading
import time

import numpy as np
import pytest

import odemag
from conftest import ROOT, cli

# (scene, duration or None for the scene's own): short runs with outcomes,
# contacts, and a time line (the plunger's coil is switched off at 0.1 s).
RUNS = [
    ("examples/drop_on_magnet.json", None),
    ("demos/scenes/ball_chain.json", None),
    ("examples/solenoid_plunger.json", 0.15),
]


def scene_file(name, duration, tmp_path):
    """The scene, with simulation.duration set when given, as a file both sides read."""
    scene = json.loads((ROOT / name).read_text())
    if duration is not None:
        scene.setdefault("simulation", {})["duration"] = duration
    path = tmp_path / pathlib_name(name)
    path.write_text(json.dumps(scene))
    return path


def pathlib_name(name):
    return name.replace("/", "_")


def run_cli(path, tmp_path):
    out = tmp_path / "out"
    cli("run", path, "--out", out, "--frames", "no", "--quiet", "yes", "--state-every-step", "yes")
    summary = json.loads((out / "summary.json").read_text())
    last = json.loads((out / "state.jsonl").read_text().splitlines()[-1])
    return summary, last


@pytest.mark.parametrize("name,duration", RUNS)
def test_run_equals_cli(name, duration, tmp_path):
    path = scene_file(name, duration, tmp_path)
    summary, last = run_cli(path, tmp_path)

    sim = odemag.Simulation(odemag.load(path))
    sim.run()
    outcomes = sim.finish()

    assert sim.steps == summary["steps"] == last["step"]
    assert sim.time == summary["duration"] == last["time"]
    assert outcomes == summary["outcomes"]
    assert sim.outcomes == outcomes
    bodies = last["bodies"]
    assert sim.body_names == [b["name"] for b in bodies]
    assert sim.present.tolist() == [b["present"] for b in bodies]
    for key, array in (("position", sim.positions), ("orientation", sim.quaternions),
                       ("velocity", sim.velocities), ("angular_velocity", sim.angular_velocities),
                       ("moment", sim.moments), ("force", sim.forces), ("torque", sim.torques)):
        np.testing.assert_array_equal(array, np.array([b[key] for b in bodies]), err_msg=key)
    r = sim.records
    assert r["iterations"].sum() == summary["iterations"]["total"]
    assert r["substeps"].sum() == summary["substeps"]["total"]
    assert int((~r["converged"]).sum()) == summary["steps_not_converged"]


def test_step_by_step_equals_run():
    scene = odemag.load(ROOT / "examples/drop_on_magnet.json")
    a, b = odemag.Simulation(scene), odemag.Simulation(scene)
    a.run(0.1)
    while b.time + 0.5 * b.time_step < 0.1:
        b.step()
    assert a.steps == b.steps == 50
    np.testing.assert_array_equal(a.positions, b.positions)
    b.advance_to(0.2)
    a.run(0.1)
    assert a.steps == b.steps == 100
    np.testing.assert_array_equal(a.forces, b.forces)


def test_state_arrays_shapes_and_units():
    scene = odemag.load(ROOT / "demos/scenes/ball_chain.json")
    sim = odemag.Simulation(scene)
    n = len(scene.body_names)
    for name in ("positions", "velocities", "angular_velocities", "moments", "forces", "torques"):
        a = getattr(sim, name)
        assert a.shape == (n, 3) and a.dtype == np.float64, name
    q = sim.quaternions
    assert q.shape == (n, 4) and q.dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, rtol=1e-12)
    assert sim.present.dtype == np.bool_ and sim.present.shape == (n,)
    assert sim.records["time"].shape == (0,)
    for _ in range(3):
        sim.step()
    r = sim.records
    assert set(r) == {"time", "magnetic_ms", "rigid_ms", "wall_ms", "substeps", "substeps_wanted", "iterations",
                      "llg_steps", "newton_steps", "relaxations", "skipped", "converged", "residual",
                      "held", "rezoned"}
    assert all(len(v) == 3 for v in r.values())
    np.testing.assert_array_equal(r["time"], [0.0, sim.time_step, 2 * sim.time_step])
    assert r["substeps"].dtype.kind == "i" and r["converged"].dtype == np.bool_
    assert (r["magnetic_ms"] > 0).all() and (r["rigid_ms"] > 0).all()
    assert (r["wall_ms"] >= r["magnetic_ms"] + r["rigid_ms"]).all()
    assert sim.steps == 3 and sim.time == pytest.approx(3 * sim.time_step)


def test_magnetization_scale_control():
    scene = odemag.load(ROOT / "examples/drop_on_magnet.json")
    sim = odemag.Simulation(scene)
    ball = scene.body_names.index("ball_1")
    pull = np.linalg.norm(sim.forces[ball])
    assert pull > 0.0
    assert sim.magnetization_scale("magnet") == 1.0
    sim.set_magnetization_scale("magnet", 0.0)
    assert sim.magnetization_scale(scene.body_names.index("magnet")) == 0.0
    sim.step()
    assert np.linalg.norm(sim.forces[ball]) < 1e-6 * pull  # the magnet is off: the ball is not pulled
    with pytest.raises(KeyError):
        sim.magnetization_scale("no such body")
    with pytest.raises(IndexError):
        sim.magnetization_scale(len(scene.body_names))
    sim.external_field = [0.0, 0.0, 40.0]
    np.testing.assert_array_equal(sim.external_field, [0.0, 0.0, 40.0])


CONTROL_CHILD = r"""
import sys, numpy as np, odemag
sim = odemag.Simulation(odemag.load(sys.argv[1]))
for scale in (1e300, 1e6):
    try:
        sim.set_magnetization_scale("magnet", scale)
        print("taken", scale)
    except ValueError as e:
        print("refused", scale, e)
sim.step()
# The largest accepted scale: the run stays finite or stops at the NaN
# guard's message, never in ODE.
sim.set_magnetization_scale("magnet", float(sys.argv[2]))
try:
    sim.run(0.05)
    print("finite", bool(np.all(np.isfinite(sim.positions))), float(np.max(np.abs(sim.positions))))
except RuntimeError as e:
    print("guard", e)
"""


def test_magnetization_scale_beyond_the_range_is_refused_and_the_process_exits_cleanly(tmp_path):
    # 1e300 gave an ODE internal error and an abort at exit (status 134); 1e6
    # sent a ball 536 km up in 0.05 s.
    import os
    import subprocess
    import sys
    scene = ROOT / "examples/drop_on_magnet.json"
    magnet = json.loads(scene.read_text())["materials"]["magnet"]["magnetization"]
    largest = 1e9 / max(abs(x) for x in magnet)
    child = tmp_path / "child.py"
    child.write_text(CONTROL_CHILD)
    r = subprocess.run([sys.executable, str(child), str(scene), repr(largest)], capture_output=True, text=True,
                       timeout=300, env=os.environ)
    assert r.returncode == 0, r.stderr
    assert "ODE" not in r.stderr, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith('refused 1e+300 set_magnetization_scale: the scale 1e+300 of body'), r.stdout
    assert lines[1].startswith("refused 1000000.0"), r.stdout
    assert lines[2].startswith("finite True") or lines[2].startswith("guard "), r.stdout
    if lines[2].startswith("guard "):
        assert "non-finite state" in lines[2]


def test_run_arguments():
    sim = odemag.Simulation(odemag.load(ROOT / "examples/compass_needle.json"))
    with pytest.raises(ValueError):
        sim.run(-1.0)
    with pytest.raises(ValueError):
        sim.advance_to(float("nan"))


def test_simulations_in_one_process_do_not_share_odes_random_numbers(tmp_path):
    # dWorldQuickStep reorders constraints with ODE's random numbers: a run
    # after (and interleaved with) another in the same process must still
    # equal a fresh `odemag run`.
    scene = json.loads((ROOT / "demos/scenes/ball_chain.json").read_text())
    scene.setdefault("simulation", {}).update(contact_solver="quick", duration=0.2)
    path = tmp_path / "quick.json"
    path.write_text(json.dumps(scene))
    summary, last = run_cli(path, tmp_path)
    other = odemag.Simulation(odemag.load(path))
    other.run(0.05)
    sim = odemag.Simulation(odemag.load(path))
    while sim.time + 0.5 * sim.time_step < 0.2:
        sim.step()
        other.step()
    np.testing.assert_array_equal(sim.positions, np.array([b["position"] for b in last["bodies"]]))
    assert sim.finish() == summary["outcomes"]


def test_run_releases_the_gil():
    # Another Python thread keeps running while run() is in C++: the longest
    # pause of its loop is a fraction of the run's time (with the GIL held
    # it would be all of it).
    sim = odemag.Simulation(odemag.load(ROOT / "demos/scenes/ball_chain.json"), threads=1)
    done = threading.Event()
    worker = threading.Thread(target=lambda: (sim.run(), done.set()))
    ticks = [time.perf_counter()]
    worker.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
    worker.join()
    total = ticks[-1] - ticks[0]
    assert sim.steps > 0 and total > 0.05
    assert max(np.diff(ticks)) < 0.5 * total


def test_refined_zones_follow_a_sliding_contact(tmp_path):
    # A lattice ball sliding over another (solver.contact_refinement): after
    # each step both balls' zones move to their contacts, counted in the
    # records as odemag run counts them in summary.json, with no notice.
    ball = {"shape": {"sphere": 0.005}, "material": "iron", "cell_size": 0.0016667}
    scene = {
        "gravity": [0, 0, 0],
        "simulation": {"time_step": 0.001, "duration": 0.002},
        "external_field": [0, 0, 1000],
        "materials": {"iron": {"type": "soft", "saturation": 1e9, "susceptibility": 10}},
        "bodies": [dict(ball, name="lower", fixed=True),
                   dict(ball, name="upper", position=[0, 0, 0.01025], velocity=[3, 0, 0])],
        "solver": {"contact_refinement": True},
    }
    path = tmp_path / "sliding.json"
    path.write_text(json.dumps(scene))
    sim = odemag.Simulation(odemag.load(path))
    sim.run()
    assert list(sim.records["rezoned"]) == [2, 2]
    assert sim.notices == []
    summary, _ = run_cli(path, tmp_path)
    assert summary["rezoned"]["total"] == 4
    assert sim.notices == summary["notices"]
