"""Abnormal process exits of Python processes that used the contact FMU.

    python benchmarks/bench_exit.py [--fmu fmus/RotorCasingContact.fmu] [--n 200] [--jobs NCPU]
                                    [--kinds simulate,slaves] [--timeout 300]

The cause it was written to show (pythonfmu 0.7.0's linux64 binary writes into a block it freed at
process exit) and the fix (fmu_src/fmi/pythonfmu.py patches that binary) are in fmu_src/fmi/pythonfmu.py's
_patch_exit_double_release; the native FMU has no such code. Either flavour can be given with --fmu.

Runs --n fresh Python processes of each kind (at most --jobs at once) and counts the
ones that did not exit cleanly (non-zero return code, or death by a signal such as
SIGABRT from glibc's "corrupted double-linked list" at interpreter exit):

* ``simulate``: ``fmpy.simulate_fmu`` of the FMU file (fmpy extracts it afresh and
  deletes the extraction afterwards), 0.2 s at a 1 ms output interval, with the
  reference scenario's start values (g0 = 0.2 mm, Omega = 176.2 rad/s, imbalance = 0.022 kg.m;
  3D and transient are the defaults);
* ``slaves``: one fresh extraction, then 5 ``FMU2Slave`` instances one after the other
  (instantiate, setupExperiment, enter/exitInitializationMode with the same start
  values, 200 doStep of 1 ms each followed by a getReal of every Real output,
  terminate, freeInstance; fmpy dlcloses the binary after each freeInstance).
  ``--overlap`` keeps all instances alive together and frees them at the end.

Prints one line per kind, ``<kind>: <bad>/<n> abnormal exits [signals]``, then one line
per failure (return code or signal and the last stderr line), and exits 1 if any
process exited abnormally. Self-contained: the standard library and fmpy (which the
children import) only.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import signal
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

START_VALUES = {"g0": 0.2e-3, "Omega": 176.2, "imbalance": 0.022}

CHILD = r'''
import json, shutil, sys, tempfile
kind, fmu, steps, instances, overlap, start = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), \
    sys.argv[5] == "1", json.loads(sys.argv[6])
if kind == "simulate":
    from fmpy import simulate_fmu
    simulate_fmu(fmu, stop_time=steps * 1e-3, step_size=1e-3, output_interval=1e-3, start_values=start)
else:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    outs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    reals = [(vr[k], v) for k, v in start.items()]
    tmp = tempfile.mkdtemp(prefix="bench_exit_")
    unzipdir = extract(fmu, unzipdir=tmp)

    def make(i):
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=f"inst{i}")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setReal([r for r, _ in reals], [v for _, v in reals])
        s.exitInitializationMode()
        return s

    def run(s):
        t = 0.0
        for _ in range(steps):
            s.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
            t += 1e-3
            s.getReal(outs)

    def free(s):
        s.terminate()
        s.freeInstance()

    if overlap:
        slaves = [make(i) for i in range(instances)]
        for s in slaves:
            run(s)
        for s in slaves:
            free(s)
    else:
        for i in range(instances):
            s = make(i)
            run(s)
            free(s)
    shutil.rmtree(tmp, ignore_errors=True)
print("child ok", flush=True)
'''


def signal_name(rc: int) -> str:
    try:
        return signal.Signals(-rc).name
    except ValueError:
        return f"signal {-rc}"


def run_child(kind: str, fmu: str, ns: argparse.Namespace) -> tuple[int, str]:
    steps = ns.steps if kind == "slaves" else ns.sim_steps
    cmd = [sys.executable, "-c", CHILD, kind, fmu, str(steps), str(ns.instances), "1" if ns.overlap else "0",
           json.dumps(START_VALUES)]
    with tempfile.TemporaryDirectory(prefix="bench_exit_cwd_") as cwd:  # core files, fmpy leftovers
        try:
            p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=ns.timeout,
                               stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            return -999, f"timed out after {ns.timeout} s"
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    if p.returncode == 0 and "child ok" not in p.stdout:
        return -998, "exit code 0 without finishing"
    return p.returncode, (lines[-1] if lines else "")


def describe(rc: int) -> str:
    if rc == -999:
        return "timeout"
    if rc == -998:
        return "incomplete"
    return signal_name(rc) if rc < 0 else f"exit code {rc}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", default=str(REPO / "fmus" / "RotorCasingContact.fmu"))
    ap.add_argument("--n", type=int, default=200, help="processes per kind")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes at once")
    ap.add_argument("--kinds", default="simulate,slaves", help="comma-separated: simulate, slaves")
    ap.add_argument("--steps", type=int, default=200, help="doStep calls of 1 ms per instance (slaves)")
    ap.add_argument("--sim-steps", type=int, default=200, help="output intervals of 1 ms (simulate)")
    ap.add_argument("--instances", type=int, default=5, help="FMU2Slave instances per process (slaves)")
    ap.add_argument("--overlap", action="store_true", help="slaves: keep all instances alive, free at the end")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per process")
    ns = ap.parse_args(argv)
    fmu = str(Path(ns.fmu).resolve())
    if not Path(fmu).is_file():
        print(f"bench_exit: FMU not found: {fmu} (build it with `rotorub build-fmu`)", file=sys.stderr)
        return 2
    kinds = [k.strip() for k in ns.kinds.split(",") if k.strip()]
    for k in kinds:
        if k not in ("simulate", "slaves"):
            ap.error(f"unknown kind {k!r}")
    any_bad = False
    for kind in kinds:
        with ThreadPoolExecutor(max_workers=max(1, ns.jobs)) as ex:
            results = list(ex.map(lambda _i, kind=kind: run_child(kind, fmu, ns), range(ns.n)))
        bad = [(rc, last) for rc, last in results if rc != 0]
        any_bad |= bool(bad)
        counts = collections.Counter(describe(rc) for rc, _ in bad)
        detail = ", ".join(f"{name} x{c}" for name, c in counts.most_common()) or "none"
        print(f"{kind}: {len(bad)}/{ns.n} abnormal exits [{detail}]", flush=True)
        for rc, last in bad:
            print(f"  {kind}: {describe(rc)}: {last}", flush=True)
    return 1 if any_bad else 0


if __name__ == "__main__":
    sys.exit(main())
