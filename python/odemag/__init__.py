"""odemag: magnets for rigid-body simulation, from Python (docs/python.md).

SI units throughout: m, s, A/m (magnetization, H), T (B), A m^2 (moments),
N (forces), N m (torques, about each body's centre of mass); vectors in the
world frame. Per-body arrays have one row per scene body, in scene order
(``scene.body_names``).

    scene = odemag.load("examples/plunger.json")
    sol = scene.solve()                 # sol.forces: (B, 3) N
    B, H = scene.field(points)          # points: (N, 3) m -> (N, 3) T, (N, 3) A/m
    sim = odemag.Simulation(scene)
    sim.run()                           # to simulation.duration, as `odemag run`
    sim.finish()                        # the scene's outcomes, as summary.json's
"""

# The bindings need the built extension odemag._core (build/python/odemag);
# odemag.sweep needs only the odemag program and runs from the source tree's
# python/ too (docs/sweeps.md), where the extension is absent.
import os as _os

# OpenMP threads that sleep instead of spinning while they wait (docs/python.md
# "Threads"): libgomp reads OMP_WAIT_POLICY once, when the extension loads it.
_os.environ.setdefault("OMP_WAIT_POLICY", "passive")

try:
    from ._api import Field, Magnetics, Scene, SceneError, Simulation, Solution, load
except ImportError as _missing:
    if "_core" not in str(_missing):
        raise
    _MISSING_EXTENSION = str(_missing)
else:
    _MISSING_EXTENSION = None


def __getattr__(name):
    # odemag.sweep is imported when first used, so that `python3 -m
    # odemag.sweeps` (the Dask runner) runs a module not imported before it.
    if name == "sweep":
        from .sweeps import sweep
        return sweep
    if _MISSING_EXTENSION is not None and name in __all__:
        raise ImportError(f"odemag.{name} needs the built extension odemag._core "
                          f"(build/python, docs/python.md): {_MISSING_EXTENSION}")
    raise AttributeError(f"module 'odemag' has no attribute '{name}'")


__all__ = ["load", "Scene", "Solution", "Field", "Simulation", "Magnetics", "SceneError", "sweep"]
