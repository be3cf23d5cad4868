"""`odemag sweep --slurm` on a single-node Slurm started here (docs/sweeps.md
"Slurm"): slurmctld and slurmd with their own config, state and logs under a
temporary folder (auth/none: no munge key needed), the printed sbatch line
run as it is, and the gathered results.csv compared with the local runner's.
Skips, with the reason, where Slurm cannot be started (not root, no
slurm-wlm, daemons that do not come up); the daemons are stopped in every case.

Needs ODEMAG (the odemag program); CTest sets it.
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import time

import pytest

ODEMAG = os.environ.get("ODEMAG", "")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BASE = os.path.join(ROOT, "demos", "scenes", "ball_chain.json")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


CONF = """ClusterName=odemagtest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={d_port}
AuthType=auth/none
CredType=cred/none
SlurmUser=root
SlurmdUser=root
StateSaveLocation={dir}/state
SlurmdSpoolDir={dir}/spool
SlurmctldPidFile={dir}/slurmctld.pid
SlurmdPidFile={dir}/slurmd.pid
SlurmctldLogFile={dir}/slurmctld.log
SlurmdLogFile={dir}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN
PartitionName=odemag Nodes={host} Default=YES MaxTime=INFINITE State=UP
"""


@pytest.fixture
def slurm(tmp_path):
    """A running single-node Slurm: the environment that reaches it."""
    if os.geteuid() != 0:
        pytest.skip("starting slurmd needs root")
    missing = [p for p in ("slurmctld", "slurmd", "sbatch", "sinfo") if not shutil.which(p)]
    if missing:
        pytest.skip("slurm-wlm is not installed (no %s)" % ", ".join(missing))
    folder = tmp_path / "slurm"
    (folder / "state").mkdir(parents=True)
    (folder / "spool").mkdir()
    host = socket.gethostname().split(".")[0]
    conf = folder / "slurm.conf"
    conf.write_text(CONF.format(host=host, dir=folder, ctld_port=free_port(), d_port=free_port(),
                                cpus=os.cpu_count() or 1))
    env = dict(os.environ, SLURM_CONF=str(conf))
    daemons = []
    try:
        for command in (["slurmctld", "-D", "-i", "-f", str(conf)], ["slurmd", "-D", "-f", str(conf), "-N", host]):
            daemons.append(subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT,
                                            start_new_session=True))
        deadline = time.time() + 20
        state = ""
        while time.time() < deadline:
            if any(d.poll() is not None for d in daemons):
                break
            r = subprocess.run(["sinfo", "-h", "-o", "%T"], env=env, capture_output=True, text=True, timeout=10)
            state = r.stdout.strip()
            if r.returncode == 0 and state == "idle":
                break
            time.sleep(0.5)
        if state != "idle":
            logs = "".join((folder / n).read_text()[-400:] for n in ("slurmctld.log", "slurmd.log")
                           if (folder / n).exists())
            pytest.skip("Slurm did not start here (node state %r): %s" % (state, logs.replace("\n", " | ")))
        yield env
    finally:
        for d in daemons:  # the daemons and whatever they started (their own sessions)
            if d.poll() is None:
                os.killpg(d.pid, signal.SIGTERM)
        for d in daemons:
            try:
                d.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.killpg(d.pid, signal.SIGKILL)
                d.wait(timeout=5)


@pytest.mark.skipif(not os.access(ODEMAG, os.X_OK), reason="ODEMAG is not the odemag program")
def test_the_slurm_scripts_give_the_local_runners_table(tmp_path, slurm):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({
        "scene": BASE, "set": {"simulation.duration": 0.2},
        "grid": {"materials.steel.susceptibility": [10, 100, 1000]},
        "collect": ["balls_lifted", "steps", "iterations.mean"], "run": ["--backend", "cpu"]}))
    local = tmp_path / "local"
    subprocess.run([ODEMAG, "sweep", str(spec), "--out", str(local), "--quiet", "yes"], check=True, timeout=120)

    out = tmp_path / "slurm_out"
    r = subprocess.run([ODEMAG, "sweep", str(spec), "--out", str(out), "--slurm"], capture_output=True, text=True,
                       check=True, timeout=60)
    line = r.stdout.strip()
    assert line == ("jobid=$(sbatch --parsable {o}/sweep.sbatch) && sbatch --dependency=afterok:${{jobid%%;*}} "
                    "{o}/gather.sbatch".format(o=out))
    assert "#SBATCH --array=0-2\n" in (out / "sweep.sbatch").read_text()
    assert not (out / "results.csv").exists()
    subprocess.run(["bash", "-c", line], env=slurm, check=True, timeout=60)  # the printed line, as it is

    deadline = time.time() + 90
    while time.time() < deadline and not (out / "results.csv").exists():
        time.sleep(0.5)
    logs = sorted(p.name for p in (out / "slurm").iterdir())
    assert (out / "results.csv").exists(), "no table after 90 s; logs: %s" % logs
    assert (out / "results.csv").read_text() == (local / "results.csv").read_text()
    assert logs == ["gather.log", "variant-0.log", "variant-1.log", "variant-2.log"]
