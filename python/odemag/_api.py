"""The bindings' Python API (imported by odemag/__init__.py; needs the built
extension odemag._core). docs/python.md."""


import json
import os

from . import _core
from ._core import Field, Magnetics, Scene, SceneError, Simulation, Solution

__all__ = ["load", "Scene", "Solution", "Field", "Simulation", "Magnetics", "SceneError"]

SceneError.__doc__ = """A bad scene, as `odemag` reports it (a ValueError).

str(error) is the line `odemag` prints after "odemag: ": "FILE: KEY: message".
Attributes: file (the path, or "<dict>" / "<string>" / the name given to
load), key (the scene key path, e.g. "bodies[2].shape.sphere"; "" when the
error is about the whole file, such as malformed JSON before any key) and
message (what is wrong)."""
# Defaults for a SceneError raised from Python code with only a message.
SceneError.file = ""
SceneError.key = ""
SceneError.message = ""


def _scene_error(text, file, key, message):
    error = SceneError(text)
    error.file, error.key, error.message = file, key, message
    return error


# Pickled with its attributes (errors coming back from worker processes).
SceneError.__reduce__ = lambda self: (_scene_error, (str(self), self.file, self.key, self.message))


def _plain(value):
    """json.dumps' fallback: numpy scalars and arrays as Python numbers and lists."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not a scene value: {value!r} ({type(value).__name__})")


def load(source, *, file=None):
    """The scene of a file path (str or os.PathLike), a dict, or JSON text.

    A str whose first non-blank character is "{" is JSON text; any other str
    is a path. ``file`` names a dict or text in messages (default "<dict>",
    "<string>"). Raises SceneError naming the file and key for a bad scene,
    as `odemag` does (docs/scene-format.md).
    """
    if isinstance(source, os.PathLike):
        return _core.load_file(os.fspath(source))
    if isinstance(source, dict):
        return _core.parse_scene(json.dumps(source, default=_plain), file or "<dict>")
    if isinstance(source, bytes):
        source = source.decode("utf-8")
    if isinstance(source, str):
        if source.lstrip().startswith("{"):
            return _core.parse_scene(source, file or "<string>")
        return _core.load_file(source)
    raise TypeError(f"load: expected a path, a dict or JSON text, got {type(source).__name__}")
