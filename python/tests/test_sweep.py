"""odemag.sweep on a Dask LocalCluster (docs/sweeps.md): the table equals the
variant scenes run one by one with `odemag run`, and a killed worker's
variants are run again (nothing lost, no duplicate rows).

Needs ODEMAG (the odemag program) and PYTHONPATH=python (CTest sets both).
"""
import copy
import csv
import json
import os
import signal
import subprocess
import time

import pytest

distributed = pytest.importorskip("distributed")
from odemag import sweep  # noqa: E402

ODEMAG = os.environ.get("ODEMAG", "")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BASE = os.path.join(ROOT, "demos", "scenes", "ball_chain.json")
CHI = [10, 100, 300, 1000]
INDUCTION = [True, False]
DURATION = 0.6  # s: the magnet comes down to the balls by 0.8 s; long enough for ~1 s variants
COLLECT = ["balls_lifted", "steps", "iterations.mean", "magnetic_ms.median"]

pytestmark = pytest.mark.skipif(not os.access(ODEMAG, os.X_OK), reason="ODEMAG is not the odemag program")


def write_spec(folder):
    spec = {"scene": BASE, "set": {"simulation.duration": DURATION},
            "grid": {"materials.steel.susceptibility": CHI, "solver.mutual_induction": INDUCTION},
            "collect": COLLECT[:3], "run": ["--backend", "cpu"]}
    path = os.path.join(folder, "spec.json")
    with open(path, "w") as f:
        json.dump(spec, f)
    return path


@pytest.fixture(scope="module")
def expected(tmp_path_factory):
    """The 8 variants built here by hand (not by key path) and run one by one."""
    folder = tmp_path_factory.mktemp("by_hand")
    with open(BASE) as f:
        base = json.load(f)
    rows = []
    for chi in CHI:  # the grid's order: the first key varies slowest
        for induction in INDUCTION:
            scene = copy.deepcopy(base)
            scene["simulation"]["duration"] = DURATION
            scene["materials"]["steel"]["susceptibility"] = chi
            scene["solver"]["mutual_induction"] = induction
            i = len(rows)
            path = folder / ("scene_%d.json" % i)
            path.write_text(json.dumps(scene))
            out = folder / ("run_%d" % i)
            subprocess.run([ODEMAG, "run", str(path), "--out", str(out), "--frames", "no", "--quiet", "yes",
                            "--threads", "1", "--backend", "cpu"], check=True)
            summary = json.loads((out / "summary.json").read_text())
            rows.append({"chi": chi, "induction": induction, "balls_lifted": summary["outcomes"]["balls_lifted"],
                         "steps": summary["steps"], "iterations.mean": summary["iterations"]["mean"]})
    return rows


def check_table(table, expected):
    assert [int(r["variant"]) for r in table] == list(range(8))  # every variant once, in order
    for r, e in zip(table, expected):
        assert r["status"] == "ok"
        assert float(r["materials.steel.susceptibility"]) == e["chi"]
        assert r["solver.mutual_induction"] == ("true" if e["induction"] else "false")
        for key in ("balls_lifted", "steps", "iterations.mean"):
            assert float(r[key]) == e[key], (r, e)  # bit for bit: the same program on the same scene


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def odemag_processes(out):
    """pids of odemag processes still working in `out`."""
    found = []
    for pid in os.listdir("/proc"):
        try:
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                words = f.read().split(b"\0")
        except OSError:
            continue
        if words and words[0] == ODEMAG.encode() and str(out).encode() in words:
            found.append(int(pid))
    return found


def test_local_cluster_gives_the_table_of_the_variants_run_one_by_one(tmp_path, expected):
    table = sweep(write_spec(tmp_path), tmp_path / "out", dask="local:2", odemag=ODEMAG)
    check_table(table, expected)
    assert table == read_csv(tmp_path / "out" / "results.csv")
    assert expected[6]["iterations.mean"] > expected[7]["iterations.mean"]  # with mutual induction: more iterations


def test_a_killed_workers_variants_are_run_again(tmp_path, expected):
    killed = {}

    def kill_a_busy_worker(client, futures):
        # Once a worker is running a variant (its odemag process started),
        # kill the worker process; its nanny starts a new one and Dask
        # reschedules the variants it held.
        deadline = time.time() + 30
        while time.time() < deadline and not killed:
            processing = {w: tasks for w, tasks in client.processing().items() if tasks}
            if processing and odemag_processes(tmp_path / "out"):
                pids = client.run(os.getpid)
                worker = sorted(processing)[0]
                killed["worker"], killed["tasks"] = worker, len(processing[worker])
                os.kill(pids[worker], signal.SIGKILL)
            time.sleep(0.05)
        # The scheduler counts, per task, the workers that died running it.
        while time.time() < deadline and killed.get("suspicious", 0) < 1:
            killed["suspicious"] = client.run_on_scheduler(
                lambda dask_scheduler: max(ts.suspicious for ts in dask_scheduler.tasks.values()))
            time.sleep(0.05)

    table = sweep(write_spec(tmp_path), tmp_path / "out", dask="local:2", odemag=ODEMAG,
                  on_submitted=kill_a_busy_worker)
    assert killed and killed["tasks"] >= 1
    assert killed["suspicious"] >= 1  # a variant lost with the worker, run again elsewhere
    check_table(table, expected)
    assert len({r["variant"] for r in table}) == 8
    deadline = time.time() + 10  # the killed worker's odemag went with it (PR_SET_PDEATHSIG)
    while odemag_processes(tmp_path / "out") and time.time() < deadline:
        time.sleep(0.1)
    assert odemag_processes(tmp_path / "out") == []


def test_odemag_sweep_dask_gives_the_local_runners_table(tmp_path):
    spec = write_spec(tmp_path)
    env = dict(os.environ, PYTHONPATH="")  # odemag finds python/ itself
    for out, runner in (("local", []), ("dask", ["--dask", "local:2"])):
        r = subprocess.run([ODEMAG, "sweep", spec, "--out", str(tmp_path / out), "--quiet", "yes", *runner],
                           env=env, check=True, timeout=120, stderr=subprocess.PIPE, text=True)
        assert "Warning" not in r.stderr, r.stderr  # runpy's RuntimeWarning on odemag.sweeps, say
    assert (tmp_path / "dask" / "results.csv").read_text() == (tmp_path / "local" / "results.csv").read_text()
    # A bad spec is named by odemag itself (exit 2) before Python starts.
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"scene": BASE, "grid": {"materials.stel.susceptibility": [1]}}))
    r = subprocess.run([ODEMAG, "sweep", str(bad), "--out", str(tmp_path / "bad"), "--dask", "local"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert r.stderr.startswith("odemag: %s: grid[\"materials.stel.susceptibility\"]: " % bad), r.stderr
    assert not (tmp_path / "bad").exists()
