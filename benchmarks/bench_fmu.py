"""Cost of the FMU path against the library, and memory over 10^6 FMU steps.

    python benchmarks/bench_fmu.py [--fmu fmus/RotorCasingContact.fmu] [--steps 1000000] [--t-end 1.5]

Scenario (the one tests/test_fmu.py checks to 1e-9): 3D contact, g0 = 0.5 mm,
Omega = 3.3 x omega_ref held constant, imbalance ramped from 0 to the reference m*e
over 1 s by the master (held over each communication step), 1.5 s simulated.

Printed, all in this one process (numba compiled and the FMU loaded before timing):

* FMU, fmpy.simulate_fmu: the complete fmpy master (input table, recorder of all
  outputs) at communication steps h = 1 ms and 0.1 ms;
* FMU, fmpy FMU2Slave loop: a lean master through fmpy's FMU2Slave (set imbalance,
  fmi2DoStep, get every output each step, preallocated ctypes arrays);
* library, run_transient(hold=h): the library's own run of the same scenario (inputs
  held over each h as the master does, same internal step, all outputs every h);
* library, step loop: CentralDifference.advance per h plus outputs_from_q, the
  arithmetic the FMU performs (what the 1e-9 test compares).

The ratios the target is about: FMU (lean fmpy loop) / library run_transient at 1 ms
(target <= 1.5), and FMU / library step loop (the same per-step traffic without FMI).
Then the resident memory (VmRSS) before and after --steps FMU steps (h = 0.1 ms,
one internal step each), sampled along the way (target: no growth beyond noise).
"""

from __future__ import annotations

import argparse
import ctypes
import math
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]


def rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", default=str(REPO / "fmus" / "RotorCasingContact.fmu"))
    ap.add_argument("--steps", type=int, default=1_000_000, help="FMU steps of the memory check")
    ap.add_argument("--t-end", type=float, default=1.5)
    ap.add_argument("--repeat", type=int, default=3, help="timings: best of N")
    ns = ap.parse_args(argv)

    from fmpy import extract, read_model_description, simulate_fmu
    from fmpy.fmi2 import FMU2Slave, fmi2Real, fmi2ValueReference

    from rotorub_model.analyses.transient import CentralDifference, outputs_from_q, run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import reference_parameters

    fmu_path = Path(ns.fmu)
    if not fmu_path.exists():
        print(f"{fmu_path} not found: build it with `rotorub build-fmu`", file=sys.stderr)
        return 2
    unzip = extract(str(fmu_path))
    md = read_model_description(unzip)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    real_out = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    int_out = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Integer"]

    p = reference_parameters()
    omega = 3.3 * p.normalisation.omega_ref
    me_max, g0, t_end = p.imbalance.me, 0.5e-3, ns.t_end
    model = build_model(p.replace(contact={"g0": g0}))
    contact = make_contact(model, "3D")

    def ramp(t):
        return me_max * np.minimum(np.asarray(t) / 1.0, 1.0)

    def fmu_simulate(h):
        t = np.arange(int(round(t_end / h)) + 1) * h
        sig = np.array(list(zip(t, np.full_like(t, omega), ramp(t))),
                       dtype=[("time", float), ("Omega", float), ("imbalance", float)])
        return simulate_fmu(unzip, model_description=md, stop_time=t_end, output_interval=h,
                            start_values={"g0": g0}, input=sig)

    def new_instance(name):
        f = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
        f.instantiate()
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
        f.setReal([vr["Omega"], vr["g0"], vr["imbalance"]], [omega, g0, 0.0])
        f.exitInitializationMode()
        return f

    def fmu_loop(h):
        n = int(round(t_end / h))
        f = new_instance("bench")
        vr_in = (fmi2ValueReference * 1)(vr["imbalance"])
        val_in = (fmi2Real * 1)()
        vr_out = (fmi2ValueReference * len(real_out))(*real_out)
        val_out = (fmi2Real * len(real_out))()
        out = np.empty((n, len(real_out)))
        t0 = time.perf_counter()
        for k in range(n):
            t = k * h
            val_in[0] = float(ramp(t))
            f.fmi2SetReal(f.component, vr_in, 1, val_in)
            if f.fmi2DoStep(f.component, t, h, 1) != 0:
                raise RuntimeError(f"fmi2DoStep failed at t = {t}")
            f.fmi2GetReal(f.component, vr_out, len(real_out), val_out)
            out[k] = np.ctypeslib.as_array(val_out)
        dt = time.perf_counter() - t0
        f.terminate()
        f.freeInstance()
        return dt, out

    def lib_run_transient(h):
        return run_transient(model, contact, omega, t_end=t_end, t_ramp=1.0, me=me_max, record_dt=h, hold=h)

    def lib_step_loop(h):
        n = int(round(t_end / h))
        nsub = max(1, math.ceil(h / 5.0e-4 * (1 - 1e-9)))
        cd = CentralDifference(model, contact, dt=h / nsub, t_ramp=0.0, omega_max_for_dt=omega)
        F = np.empty((n, contact.n_blades))
        for k in range(n):
            cd.advance(nsub, omega, float(ramp(k * h)))
            F[k] = outputs_from_q(model, cd.contact, cd.q[None], np.array([cd.phi]))["F_N"][0]
        return F

    def best(fn, *a):
        ts = []
        for _ in range(ns.repeat):
            t0 = time.perf_counter()
            fn(*a)
            ts.append(time.perf_counter() - t0)
        return min(ts)

    # warm-up: numba compiles both copies (library and the FMU's), the FMU's interpreter side is loaded
    fmu_simulate(1e-2)
    lib_step_loop(1e-2)
    lib_run_transient(1e-2)

    print(f"scenario: 3D, g0 = {g0 * 1e3:g} mm, Omega = {omega:.2f} rad/s, imbalance ramp 0 -> {me_max:g} kg.m "
          f"over 1 s, {t_end:g} s simulated; best of {ns.repeat}")
    print(f"{'h [ms]':>7} {'fmpy.simulate_fmu':>18} {'fmpy FMU2Slave loop':>20} {'lib run_transient':>18} "
          f"{'lib step loop':>14} {'loop/run_transient':>19} {'simulate/run_transient':>23}")
    ratios, steploop = {}, {}
    for h in (1e-3, 1e-4):
        t_sim = best(fmu_simulate, h)
        t_loop = min(fmu_loop(h)[0] for _ in range(ns.repeat))
        t_rt = best(lib_run_transient, h)
        t_sl = best(lib_step_loop, h)
        ratios[h] = t_loop / t_rt
        steploop[h] = t_loop / t_sl
        print(f"{h * 1e3:7.1f} {t_sim:17.3f}s {t_loop:19.3f}s {t_rt:17.3f}s {t_sl:13.3f}s {t_loop / t_rt:19.2f} "
              f"{t_sim / t_rt:23.2f}")
    n_steps = int(round(t_end / 1e-3))
    print(f"per communication step at 1 ms ({n_steps} steps): FMU lean loop "
          f"{best(lambda: fmu_loop(1e-3)) / n_steps * 1e6:.0f} us, library run_transient "
          f"{best(lib_run_transient, 1e-3) / n_steps * 1e6:.0f} us per record")
    print(f"target: FMU path <= 1.5 x direct run_transient at 1 ms: {'met' if ratios[1e-3] <= 1.5 else 'NOT met'} "
          f"({ratios[1e-3]:.2f} x); against the library step loop: {steploop[1e-3]:.2f} x")

    # memory over many steps
    if ns.steps > 0:
        h = 1e-4
        f = new_instance("rss")
        vr_in = (fmi2ValueReference * 2)(vr["imbalance"], vr["Omega"])
        val_in = (fmi2Real * 2)(me_max, omega)
        vr_out = (fmi2ValueReference * len(real_out))(*real_out)
        val_out = (fmi2Real * len(real_out))()
        vr_int = (ctypes.c_uint * len(int_out))(*int_out)
        val_int = (ctypes.c_int * len(int_out))()
        samples = []
        warm = min(20_000, ns.steps // 10)
        total = warm + ns.steps
        t0 = time.perf_counter()
        rss0 = None
        for k in range(total):
            f.fmi2SetReal(f.component, vr_in, 2, val_in)
            if f.fmi2DoStep(f.component, k * h, h, 1) != 0:
                raise RuntimeError(f"fmi2DoStep failed at step {k}")
            f.fmi2GetReal(f.component, vr_out, len(real_out), val_out)
            f.fmi2GetInteger(f.component, vr_int, len(int_out), val_int)
            if k + 1 == warm:
                rss0 = rss_mib()
                t0 = time.perf_counter()
            if k + 1 > warm and (k + 1 - warm) % max(1, ns.steps // 10) == 0:
                samples.append(rss_mib())
        elapsed = time.perf_counter() - t0
        f.terminate()
        f.freeInstance()
        rss1 = rss_mib()
        print(f"memory: {ns.steps} FMU steps of 0.1 ms (set 2 inputs, fmi2DoStep, get {len(real_out)} Real + "
              f"{len(int_out)} Integer outputs) after {warm} warm-up steps, {elapsed:.1f} s "
              f"({elapsed / ns.steps * 1e6:.0f} us/step)")
        print(f"VmRSS before: {rss0:.1f} MiB, after: {samples[-1]:.1f} MiB (growth {samples[-1] - rss0:+.1f} MiB), "
              f"after freeing the instance: {rss1:.1f} MiB")
        print("VmRSS every 10% of the run [MiB]: " + ", ".join(f"{s:.1f}" for s in samples))
    return 0


if __name__ == "__main__":
    sys.exit(main())
