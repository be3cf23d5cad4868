"""Shared fixtures: the repository, the built `odemag` program (ODEMAG_PROGRAM,
set by CTest; else build/bin/odemag) and helpers that run it."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def program():
    path = os.environ.get("ODEMAG_PROGRAM") or str(ROOT / "build" / "bin" / "odemag")
    if not os.access(path, os.X_OK):
        pytest.skip(f"no odemag program at {path} (set ODEMAG_PROGRAM)")
    return path


def cli(*args, check=True):
    """Runs `odemag ARGS...`; the completed process (text output)."""
    p = subprocess.run([program(), *map(str, args)], capture_output=True, text=True, timeout=120)
    if check and p.returncode != 0:
        raise AssertionError(f"odemag {' '.join(map(str, args))}: exit {p.returncode}: {p.stderr}")
    return p


def cli_solve(scene_path):
    return json.loads(cli("solve", scene_path).stdout)


def cli_field(scene_path, points_path):
    """The CSV of `odemag field` as a list of rows of floats (header dropped)."""
    lines = cli("field", scene_path, "--points", points_path).stdout.splitlines()
    assert lines[0] == "x,y,z,Bx,By,Bz,Hx,Hy,Hz"
    return [[float(v) for v in line.split(",")] for line in lines[1:]]


def cli_error(*args):
    """The one line `odemag` prints on stderr for bad input (exit status 2), without "odemag: "."""
    p = cli(*args, check=False)
    assert p.returncode == 2, p.stderr
    line = p.stderr.strip()
    assert line.startswith("odemag: ") and "\n" not in line, p.stderr
    return line[len("odemag: "):]


@pytest.fixture
def root():
    return ROOT
