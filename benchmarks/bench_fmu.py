"""Cost of the FMU path against the library, start-up of a fresh extraction, memory over many steps.

    python benchmarks/bench_fmu.py [--fmu fmus/RotorCasingContact.fmu ...] [--steps 1000000] [--t-end 1.5]

Scenario (the one tests/fmu/test_contact_model.py checks against the library): 3D contact, g0 = 0.5 mm,
Omega = 3.3 omega_ref held constant, imbalance ramped from 0 to the reference m*e over 1 s
by the master (held over each communication step), 1.5 s simulated.

Printed, all measured in this one run:

* per FMU given (--fmu, repeatable): a lean master through fmpy's FMU2Slave (set the
  imbalance, fmi2DoStep, read every Real output each step into preallocated ctypes
  arrays) at communication steps h = 1 ms and 0.1 ms, and ``fmpy.simulate_fmu`` at 1 ms;
* the library's ``run_transient(hold=h)``: the same scenario, inputs held over each h as
  the master holds them, the same internal step, every output every h;
* the pythonfmu protocol floor: a pythonfmu FMU built here whose slave does nothing (the
  same number of Real outputs; do_step returns at once), driven by the same loop: what
  fmpy -> pythonfmu -> Python costs per step before any physics;
* start-up: a fresh Python process extracts the FMU and runs instantiate ... end of the
  first 1 ms step (what ``simulate_fmu`` and most masters do on every run), best of 5;
* memory: VmRSS over --steps FMU steps of 0.1 ms (0 to skip).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

STARTUP = textwrap.dedent("""
    import json, sys, time
    t0 = time.perf_counter()
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    t1 = time.perf_counter()
    unzip = extract(sys.argv[1])
    md = read_model_description(unzip)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    f = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="startup")
    f.instantiate()
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    f.setReal([vr["Omega"], vr["g0"], vr["imbalance"]], [176.2, 0.5e-3, 0.022])
    f.exitInitializationMode()
    ok = f.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    t2 = time.perf_counter()
    f.terminate(); f.freeInstance()
    print(json.dumps({"import_fmpy_s": t1 - t0, "extract_to_first_step_s": t2 - t1}))
""")

FLOOR_SLAVE = textwrap.dedent('''
    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


    class ProtocolFloor(Fmi2Slave):
        """A slave that does nothing: what the pythonfmu protocol costs per call."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.values = [0.0] * (N_OUT + 1)
            self.register_variable(Real("imbalance", causality=Fmi2Causality.input,
                                        variability=Fmi2Variability.continuous, getter=lambda: 0.0,
                                        setter=lambda v: None))
            for i in range(1, N_OUT + 1):
                self.register_variable(Real(f"y{i}", causality=Fmi2Causality.output,
                                            variability=Fmi2Variability.continuous,
                                            getter=lambda i=i: self.values[i]))

        def do_step(self, current_time, step_size):
            return True

        def get_real(self, vrs):
            v = self.values
            return [v[i] for i in vrs]

        def set_real(self, vrs, values):
            pass
''')


def rss_mib() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


class Lean:
    """A lean fmpy FMU2Slave master: set one input, step, read every Real output."""

    def __init__(self, path: str, start: dict[str, float], input_name: str):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave, fmi2Real, fmi2ValueReference

        self.unzip = extract(path)
        md = read_model_description(self.unzip)
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        real_out = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        self.n_out = len(real_out)
        self.f = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                           instanceName="bench")
        self.f.instantiate()
        self.f.setupExperiment(startTime=0.0)
        self.f.enterInitializationMode()
        if start:
            self.f.setReal([self.vr[k] for k in start], list(start.values()))
        self.f.exitInitializationMode()
        self.vr_in = (fmi2ValueReference * 1)(self.vr[input_name])
        self.val_in = (fmi2Real * 1)()
        self.vr_out = (fmi2ValueReference * self.n_out)(*real_out)
        self.val_out = (fmi2Real * self.n_out)()
        self.t = 0.0

    def run(self, h: float, n: int, inputs: np.ndarray, out: np.ndarray | None = None) -> float:
        f, comp = self.f, self.f.component
        set_real, do_step, get_real = f.fmi2SetReal, f.fmi2DoStep, f.fmi2GetReal
        vr_in, val_in, vr_out, val_out, n_out = self.vr_in, self.val_in, self.vr_out, self.val_out, self.n_out
        t = self.t
        t0 = time.perf_counter()
        for k in range(n):
            val_in[0] = inputs[k]
            set_real(comp, vr_in, 1, val_in)
            if do_step(comp, t, h, 1) != 0:
                raise RuntimeError(f"fmi2DoStep failed at t = {t}")
            t += h
            get_real(comp, vr_out, n_out, val_out)
            if out is not None:
                out[k] = np.ctypeslib.as_array(val_out)
        self.t = t
        return time.perf_counter() - t0

    def free(self) -> None:
        self.f.terminate()
        self.f.freeInstance()


def floor_fmu(tmp: Path, n_out: int) -> Path:
    from pythonfmu import FmuBuilder

    script = tmp / "protocol_floor.py"
    script.write_text(f"N_OUT = {n_out}\n" + FLOOR_SLAVE)
    return Path(FmuBuilder.build_FMU(script, dest=tmp))


def startup(path: str, repeat: int = 5) -> dict:
    runs = []
    for _ in range(repeat):
        r = subprocess.run([sys.executable, "-c", STARTUP, path], capture_output=True, text=True, timeout=120)
        if r.returncode != 0:
            raise RuntimeError(f"start-up run failed: {r.stderr.strip()[-2000:]}")
        runs.append(json.loads(r.stdout.strip().splitlines()[-1]))
    return {k: min(x[k] for x in runs) for k in runs[0]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", action="append", help="FMU(s) to measure (default: fmus/RotorCasingContact.fmu)")
    ap.add_argument("--steps", type=int, default=1_000_000, help="FMU steps of the memory check (0: skip)")
    ap.add_argument("--t-end", type=float, default=1.5)
    ap.add_argument("--repeat", type=int, default=5, help="timings: best of N")
    ns = ap.parse_args(argv)
    fmus = ns.fmu or [str(REPO / "fmus" / "RotorCasingContact.fmu")]
    for f in fmus:
        if not Path(f).exists():
            print(f"{f} not found: build it with `rotorub build-fmu`", file=sys.stderr)
            return 2

    from fmpy import simulate_fmu
    from timing import best_of

    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import reference_parameters

    p = reference_parameters()
    omega = 3.3 * p.normalisation.omega_ref
    me_max, g0, t_end = p.imbalance.me, 0.5e-3, ns.t_end
    model = build_model(p.replace(contact={"g0": g0}))
    contact = make_contact(model, "3D")
    start = {"Omega": omega, "g0": g0, "imbalance": 0.0}

    def ramp(t):
        return me_max * np.minimum(np.asarray(t, dtype=float) / 1.0, 1.0)

    def lib_run(h):
        return run_transient(model, contact, omega, t_end=t_end, t_ramp=1.0, me=me_max, record_dt=h, hold=h)

    def best(fn, *a):
        return best_of(lambda: fn(*a), ns.repeat)

    def lean_time(path, h, input_name="imbalance", start_values=start):
        n = int(round(t_end / h))
        times = []
        for _ in range(ns.repeat):
            lean = Lean(path, start_values, input_name)
            times.append(lean.run(h, n, ramp(np.arange(n) * h)))
            lean.free()
        return min(times), lean.n_out

    # built before any pythonfmu FMU is loaded here: a loaded one puts its own copy of the pythonfmu
    # package (without binaries) in sys.modules, and the builder would then make an FMU without binaries
    tmpdir = tempfile.TemporaryDirectory()
    try:
        floor = floor_fmu(Path(tmpdir.name), 69)
    except ImportError:
        floor = None
    lib_run(1e-2)
    print(f"scenario: 3D, g0 = {g0 * 1e3:g} mm, Omega = {omega:.2f} rad/s, imbalance ramp 0 -> {me_max:g} kg.m "
          f"over 1 s, {t_end:g} s simulated; best of {ns.repeat}")
    lib = {h: best(lib_run, h) for h in (1e-3, 1e-4)}
    for h in (1e-3, 1e-4):
        n = int(round(t_end / h))
        print(f"library run_transient(hold={h * 1e3:g} ms): {lib[h] * 1e3:8.1f} ms  ({lib[h] / n * 1e6:6.2f} us/step)")
    n1 = int(round(t_end / 1e-3))
    results = {}
    for path in fmus:
        name = f"{Path(path).parent.name}/{Path(path).name}"
        t1, n_out = lean_time(path, 1e-3)
        t01, _ = lean_time(path, 1e-4)
        sim = best(lambda p=path: simulate_fmu(p, stop_time=t_end, output_interval=1e-3,
                                               start_values={"g0": g0, "Omega": omega, "imbalance": me_max}))
        su = startup(path)
        results[name] = {"n_out": n_out, "lean_1ms_s": t1, "lean_0.1ms_s": t01, "simulate_fmu_1ms_s": sim, **su,
                         "ratio_to_library_1ms": t1 / lib[1e-3], "ratio_to_library_0.1ms": t01 / lib[1e-4]}
        print(f"{name}: {n_out} Real outputs read per step")
        print(f"  FMU2Slave loop h = 1 ms  : {t1 * 1e3:8.1f} ms  ({t1 / n1 * 1e6:6.2f} us/step)  "
              f"= {t1 / lib[1e-3]:.2f} x run_transient(hold)  (target <= 1.5)")
        print(f"  FMU2Slave loop h = 0.1 ms: {t01 * 1e3:8.1f} ms  = {t01 / lib[1e-4]:.2f} x run_transient(hold)")
        print(f"  fmpy.simulate_fmu h = 1 ms (extracts, records): {sim * 1e3:8.1f} ms")
        print(f"  fresh process: extraction -> end of first step {su['extract_to_first_step_s'] * 1e3:7.1f} ms "
              f"(target <= 500 ms; importing fmpy before it: {su['import_fmpy_s'] * 1e3:.0f} ms)")
    if floor is not None:
        n_out = next(iter(results.values()))["n_out"]
        tf, _ = lean_time(str(floor), 1e-3, input_name="imbalance", start_values={})
        print(f"pythonfmu protocol floor (a slave that does nothing, {n_out} outputs), h = 1 ms: "
              f"{tf / n1 * 1e6:6.2f} us/step = {tf / lib[1e-3]:.2f} x run_transient(hold) before any physics")
    else:
        print("pythonfmu not installed: protocol floor not measured")

    if ns.steps > 0:
        lean = Lean(fmus[0], {**start, "imbalance": me_max}, "imbalance")
        h = 1e-4
        warm = min(20_000, ns.steps // 10)
        const = np.full(max(ns.steps // 10, 1), me_max)
        lean.run(h, warm, const)
        rss0 = rss_mib()
        samples = []
        t0 = time.perf_counter()
        for _ in range(10):
            lean.run(h, len(const), const)
            samples.append(rss_mib())
        elapsed = time.perf_counter() - t0
        lean.free()
        print(f"memory: {10 * len(const)} steps of 0.1 ms of {Path(fmus[0]).name} after {warm} warm-up steps, "
              f"{elapsed:.1f} s ({elapsed / (10 * len(const)) * 1e6:.1f} us/step): VmRSS {rss0:.1f} -> "
              f"{samples[-1]:.1f} MiB (growth {samples[-1] - rss0:+.1f} MiB); every 10 %: "
              + ", ".join(f"{s:.1f}" for s in samples))
    tmpdir.cleanup()
    return 0


if __name__ == "__main__":
    sys.exit(main())
