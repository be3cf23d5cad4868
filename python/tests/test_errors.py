"""Bad scenes and bad arguments: odemag.SceneError (a ValueError) with the
message `odemag` prints, and the file and key as attributes."""

import copy
import json
import pickle

import numpy as np
import pytest

import odemag
from conftest import ROOT, cli_error

BASE = json.loads((ROOT / "examples/bar_and_ball.json").read_text())


def broken(change):
    scene = copy.deepcopy(BASE)
    change(scene)
    return scene


# (what is wrong, the scene as a dict, the key path the error must name)
CASES = [
    ("unknown key", broken(lambda s: s["bodies"][1].update(colour=[1, 0, 0])), "bodies[1].colour"),
    ("out of range", broken(lambda s: s["materials"]["magnet"].update(magnetization=[0, 0, 1e12])),
     "materials.magnet.magnetization"),
    ("negative size", broken(lambda s: s["bodies"][1]["shape"].update(sphere=-0.006)), "bodies[1].shape.sphere"),
    ("wrong type", broken(lambda s: s["bodies"][0].update(fixed="yes")), "bodies[0].fixed"),
    ("unknown material", broken(lambda s: s["bodies"][1].update(material="steel")), "bodies[1].material"),
]


@pytest.mark.parametrize("what,scene,key", CASES, ids=[c[0] for c in CASES])
def test_bad_scene_file_names_file_and_key(what, scene, key, tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(path)
    e = caught.value
    assert isinstance(e, ValueError)
    assert e.file == str(path)
    assert e.key == key
    assert str(e) == f"{path}: {key}: {e.message}"
    assert str(e) == cli_error("solve", path)  # the program's line, word for word


@pytest.mark.parametrize("what,scene,key", CASES, ids=[c[0] for c in CASES])
def test_bad_dict_and_text_name_their_source(what, scene, key):
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(scene)
    assert (caught.value.file, caught.value.key) == ("<dict>", key)
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(json.dumps(scene), file="variant 3")
    assert (caught.value.file, caught.value.key) == ("variant 3", key)


def test_malformed_json_names_file_and_key(tmp_path):
    path = tmp_path / "cut.json"
    text = (ROOT / "examples/bar_and_ball.json").read_text()
    path.write_text(text[: text.index('"density"')])  # cut inside bodies[1]
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(path)
    assert caught.value.file == str(path)
    assert caught.value.key == "bodies[1].position"  # the value being read when the text ends
    assert caught.value.message.startswith("invalid JSON: ")
    assert str(caught.value) == cli_error("solve", path)


def test_scene_error_pickles_with_its_attributes():
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(CASES[0][1])
    copy_ = pickle.loads(pickle.dumps(caught.value))
    assert type(copy_) is odemag.SceneError
    assert (str(copy_), copy_.file, copy_.key, copy_.message) == (
        str(caught.value), "<dict>", "bodies[1].colour", caught.value.message)


def test_missing_file(tmp_path):
    path = tmp_path / "none.json"
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(str(path))
    assert caught.value.file == str(path) and caught.value.key == ""
    assert str(caught.value) == cli_error("solve", path)


def test_not_a_scene_source():
    with pytest.raises(TypeError):
        odemag.load(3.5)


@pytest.mark.parametrize("points,why", [
    (np.zeros(3), "shape (3,)"),
    (np.zeros((4, 2)), "shape (4, 2)"),
    (np.zeros((2, 3, 1)), "shape (2, 3, 1)"),
    ([[0, 0, 0.1], [0, 0, float("nan")]], "points[1]"),
    ("0,0,1", "points"),
])
def test_bad_points(points, why):
    scene = odemag.load(ROOT / "examples/bar_and_ball.json")
    with pytest.raises(ValueError, match=r"^points") as caught:
        scene.field(points)
    assert why in str(caught.value)


def test_bad_backend_argument():
    scene = odemag.load(ROOT / "examples/bar_and_ball.json")
    with pytest.raises(ValueError, match="backend"):
        scene.solve(backend="abacus")
    with pytest.raises(ValueError, match="threads"):
        scene.solve(threads=-1)


def test_bad_backend_in_scene_names_the_key():
    scene = broken(lambda s: s.update(solver={"backend": "abacus"}))
    with pytest.raises(odemag.SceneError) as caught:
        odemag.load(scene).solve()
    assert caught.value.key == "solver.backend"
