"""Parameter sweeps on Dask (docs/sweeps.md).

    sweep(spec, out, client=None, dask="local:2", odemag=None) -> list of row dicts
    python3 -m odemag.sweeps SPEC --out DIR [--dask local[:N]|ADDRESS] [--odemag PATH]

The variants come from the odemag program (``odemag sweep SPEC --out DIR
--expand``); each Dask task runs one (``odemag sweep SPEC --out DIR --variant
I``: into a folder of its own, moved into DIR/variants/NNNN when finished) and
returns its index and row; ``--gather`` then writes DIR/results.csv, the table
returned. A worker that dies loses only its running tasks, which Dask runs
again elsewhere; a variant already finished is reused, so rows are neither lost
nor repeated. With a scheduler ADDRESS, every worker must see DIR, SPEC and
the odemag program at the same paths (a shared file system).
"""
import argparse
import csv
import ctypes
import json
import os
import shutil
import signal
import subprocess
import sys


def _program(odemag):
    found = odemag or os.environ.get("ODEMAG") or shutil.which("odemag")
    if not found:
        raise RuntimeError("no odemag program: pass odemag=PATH, set ODEMAG, or put odemag on PATH")
    return os.path.abspath(found)


def _die_with_parent():
    # The variant's process ends with the worker that started it (a killed
    # worker leaves no run behind; Dask runs the variant again elsewhere).
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def _odemag(program, args, check=True):
    r = subprocess.run([program, "sweep", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       text=True, preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None)
    if check and r.returncode != 0:
        raise RuntimeError("odemag sweep %s: exit status %d: %s" % (" ".join(args), r.returncode, r.stderr.strip()))
    return r


def run_variant(program, spec, out, index):
    """One Dask task: runs variant `index` (reused when finished). Returns
    (index, its CSV row, ""), or (index, None, the error) when its run failed
    (the table marks it failed, as the local runner does)."""
    r = _odemag(program, [spec, "--out", out, "--variant", str(index)], check=False)
    if r.returncode != 0:
        return index, None, "exit status %d: %s" % (r.returncode, r.stderr.strip())
    return index, r.stdout.strip(), ""


def _client(dask):
    from distributed import Client, LocalCluster
    if dask == "local" or dask.startswith("local:"):
        workers = int(dask.split(":", 1)[1]) if ":" in dask else 2
        if workers < 1:
            raise ValueError("--dask local:N needs N >= 1")
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), cluster
    return Client(dask), None


def sweep(spec, out, client=None, dask="local:2", odemag=None, on_submitted=None):
    """Runs every variant of `spec` on Dask and returns results.csv as a list
    of dicts (one per variant, in index order; values as the CSV text).

    client: a distributed.Client to use (kept open); otherwise one is made
    from `dask` ("local", "local:N" or a scheduler address) and closed.
    odemag: the odemag program (default: $ODEMAG, then odemag on PATH).
    on_submitted(client, futures): called once the tasks are submitted (tests).
    """
    program = _program(odemag)
    spec, out = os.path.abspath(spec), os.path.abspath(out)
    _odemag(program, [spec, "--out", out, "--expand"])
    with open(os.path.join(out, "variants.json")) as f:
        count = json.load(f)["count"]
    try:  # tasks travel by value: workers need the odemag program, not this package
        import cloudpickle
        cloudpickle.register_pickle_by_value(sys.modules[__name__])
    except (ImportError, AttributeError, ValueError):
        pass
    own = None
    if client is None:
        client, cluster = _client(dask)
        own = (client, cluster)
    try:
        futures = client.map(run_variant, [program] * count, [spec] * count, [out] * count, range(count),
                             pure=False)
        if on_submitted:
            on_submitted(client, futures)
        results = client.gather(futures)
    finally:
        if own:
            own[0].close()
            if own[1] is not None:
                own[1].close()
    indices = sorted(index for index, _, _ in results)
    if indices != list(range(count)):
        raise RuntimeError("the tasks returned variants %s, not 0..%d" % (indices, count - 1))
    r = _odemag(program, [spec, "--out", out, "--gather", "--quiet", "yes"], check=False)
    with open(os.path.join(out, "results.csv"), newline="") as f:
        table = list(csv.DictReader(f))
    failed = ["variant %d: %s" % (index, error) for index, row, error in results if row is None]
    if failed or r.returncode != 0:
        raise RuntimeError("; ".join(failed) or "odemag sweep --gather: " + r.stderr.strip())
    return table


def main(argv=None):
    p = argparse.ArgumentParser(prog="python3 -m odemag.sweeps", description=__doc__.split("\n\n")[0])
    p.add_argument("spec")
    p.add_argument("--out", required=True)
    p.add_argument("--dask", default="local:2", help="local, local:N (a LocalCluster of N workers) or ADDRESS")
    p.add_argument("--odemag", help="the odemag program (default: $ODEMAG, then odemag on PATH)")
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args(argv)
    try:
        table = sweep(a.spec, a.out, dask=a.dask, odemag=a.odemag)
    except (RuntimeError, ValueError, OSError) as e:
        print("odemag sweep: %s" % e, file=sys.stderr)
        return 1
    if not a.quiet:
        print("odemag sweep: %d variants on Dask (%s), table %s" % (len(table), a.dask,
              os.path.join(a.out, "results.csv")), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
