"""Resumable studies and the executors: a study killed mid-way resumes to the same numbers; a scheduler and
two workers started as separate processes on loopback run a study as the process pool does."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rotorub_model.uncertainty import load_study, run_uq

STUDY = """
[study]
name = "resume check"
method = "montecarlo"
sampler = "qmc"
n = 16
replicates = 2
chunk = 1
quantities = ["peak_force", "margin"]
events = ["rub"]
quantiles = [0.5]
seed = 4

[operating]
speed = 3.3
t_end = 3.0   # long enough (~30 ms a task) that the poll below sees the run mid-way

[inputs.g0]
parameter = "contact.g0"
distribution = "uniform"
low = 0.2e-3
high = 0.6e-3

[inputs.mu]
parameter = "contact.mu"
distribution = "uniform"
low = 0.05
high = 0.2
"""


def _write(tmp_path: Path) -> Path:
    f = tmp_path / "study.toml"
    f.write_text(STUDY)
    return f


def test_killed_study_resumes_to_the_same_result(tmp_path):
    study = _write(tmp_path)
    out = tmp_path / "killed"
    cli = [sys.executable, "-c", "import sys; from rotorub_model.app.cli import main; sys.exit(main())"]
    proc = subprocess.Popen([*cli, "uq", str(study), "--executor", "serial", "--out", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rows = out / "evaluations" / "rows"
    t0 = time.time()
    try:
        while time.time() - t0 < 60:
            if rows.is_dir() and len(list(rows.glob("*[0-9a-f].npz"))) >= 6:
                break
            if proc.poll() is not None:
                break
            time.sleep(0.02)
        assert proc.poll() is None, "the study finished before it could be interrupted"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    done = len(list(rows.glob("*[0-9a-f].npz")))
    assert 6 <= done < 32
    assert not (out / "uq_summary.json").exists()  # nothing of the result written by the killed run
    resumed = run_uq(load_study(study), executor="serial", out=out, progress=False)
    assert resumed.cost["tasks_reused_from_store"] == done
    fresh = run_uq(load_study(study), executor="serial", out=tmp_path / "fresh", progress=False)
    for k in ("peak_force", "margin"):
        assert np.array_equal(resumed.values[k], fresh.values[k]), k
    assert resumed.estimates["values"]["peak_force"]["mean"] == fresh.estimates["values"]["peak_force"]["mean"]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_scheduler_and_two_workers_as_separate_processes(tmp_path):
    """`dask scheduler` and two `dask worker` processes on 127.0.0.1, a Client by address: the study's
    numbers are the serial run's."""
    distributed = pytest.importorskip("dask.distributed")
    dask = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command (dask[distributed]) is not installed")
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--dashboard-address", ":0", "--no-show"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", addr, "--nworkers", "1", "--nthreads", "1",
                                           "--no-dashboard", "--host", "127.0.0.1"],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with distributed.Client(addr, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
            assert len(client.scheduler_info()["workers"]) == 2
            st = load_study(_write(tmp_path))
            r = run_uq(st, executor=client.get_executor(), out=tmp_path / "dask", progress=False)
            who = client.run(os.getpid)
        ref = run_uq(st, executor="serial", progress=False)
        assert len(set(who.values())) == 2 and os.getpid() not in who.values()
        for k in ("peak_force", "margin"):
            assert np.array_equal(r.values[k], ref.values[k]), k
        assert r.cost["executor"] == "ClientExecutor" and r.cost["tasks"] == 32
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()
