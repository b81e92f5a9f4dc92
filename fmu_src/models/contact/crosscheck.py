"""The FMI cross-check kit written next to each FMU, and the check of an FMU against it.

Layout (the FMI cross-check rules' results folder, https://github.com/modelica/fmi-cross-check):

* ``RotorCasingContact_in.csv``: the inputs, one row per communication point: ``time, Omega,
  imbalance`` (a run-up through the first critical speed with the reference imbalance);
* ``RotorCasingContact_ref.csv``: the reference outputs at the same points;
* ``RotorCasingContact_ref.opt``: StartTime, StopTime, StepSize, RelTol;
* ``ReadMe.txt``: what the run is and how to compare.

Every parameter keeps its default (the FMU's start values: g0 = 1 mm, 3D, transient), so any
importing tool can run it without setting anything but the inputs. The inputs are held over each
communication step; the table has a row at every communication point, so a tool that
interpolates inputs linearly gives the same run. The reference comes from the library
(``run_transient(hold=h)``), which both FMUs reproduce to round-off.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

NAME = "RotorCasingContact"
OUTPUTS = ("friction_torque", "gap_min", "n_contact", "disk_displacement.x", "disk_displacement.y",
           "casing_force.x", "casing_force.y", "casing_force.z") + tuple(f"blade[{j}].F_N" for j in range(1, 11))
RUN = {"speed_from": 3.2, "speed_to": 3.8, "duration": 2.0, "h": 1e-3}  # normalised speeds; s


def _omega(w_ref: float):
    a, b, d = RUN["speed_from"], RUN["speed_to"], RUN["duration"]
    return lambda t: w_ref * (a + (b - a) * min(max(t / d, 0.0), 1.0))


def reference(params=None) -> dict[str, np.ndarray]:
    """Inputs and reference outputs at the communication points 0, h, ..., duration."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import reference_parameters

    p = params or reference_parameters()
    m = build_model(p)
    w = _omega(p.normalisation.omega_ref)
    h, T = RUN["h"], RUN["duration"]
    r = run_transient(m, make_contact(m, "3D"), w, t_end=T, t_ramp=0.0, me=p.imbalance.me, record_dt=h, hold=h)
    n = len(r.t)
    t = np.concatenate([[0.0], r.t])
    o = r.outputs
    out = {"time": t, "Omega": np.array([w(x) for x in t]), "imbalance": np.full(n + 1, p.imbalance.me)}
    zero = np.zeros(1)
    out["friction_torque"] = np.concatenate([zero, o["friction_torque"]])
    out["gap_min"] = np.concatenate([[p.contact.g0], o["gap"].min(axis=(1, 2))])
    out["n_contact"] = np.concatenate([zero, (o["F_N"] > 0).sum(axis=1)])
    for k, ax in enumerate("xy"):
        out[f"disk_displacement.{ax}"] = np.concatenate([zero, o["disk_fixed"][:, k]])
    for k, ax in enumerate("xyz"):
        out[f"casing_force.{ax}"] = np.concatenate([zero, o["casing_force_fixed"][:, k]])
    for j in range(10):
        out[f"blade[{j + 1}].F_N"] = np.concatenate([zero, o["F_N"][:, j]])
    return out


def column3(name: str) -> str:
    """A kit column in the FMI 3.0 FMU's names: an element of a per-blade array, blade[j].F_N, is blade.F_N[j]."""
    m = re.match(r"^blade\[(\d+)\]\.(\w+)$", name)
    return f"blade.{m.group(2)}[{m.group(1)}]" if m else name


def write_kit(dest: str | Path, params=None, fmi: str = "2.0") -> dict[str, Path]:
    """Write the four files of the kit into ``dest`` (next to the FMU). ``fmi = "3.0"``: the FMI 3.0 FMU's
    kit, the same run and numbers with the array elements as its columns (blade.F_N[1], ...)."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    ref = reference(params)
    files = {"in": dest / f"{NAME}_in.csv", "ref": dest / f"{NAME}_ref.csv", "opt": dest / f"{NAME}_ref.opt",
             "readme": dest / "ReadMe.txt"}
    _write_csv(files["in"], ref, ("time", "Omega", "imbalance"))
    if fmi == "3.0":
        ref = {**ref, **{column3(c): ref[c] for c in OUTPUTS}}
        _write_csv(files["ref"], ref, ("time", *(column3(c) for c in OUTPUTS)))
    else:
        _write_csv(files["ref"], ref, ("time", *OUTPUTS))
    files["opt"].write_text(f"StartTime, 0.0\nStopTime, {RUN['duration']!r}\nStepSize, {RUN['h']!r}\n"
                            "RelTol, 1e-6\n")
    files["readme"].write_text(f"""{NAME}: FMI cross-check kit (co-simulation)

A run-up with blade-tip / casing rub: the spin speed Omega rises linearly from {RUN['speed_from']} to
{RUN['speed_to']} x omega_ref (through the first critical speed) in {RUN['duration']} s, the imbalance is held at
the reference value, every parameter keeps its default (3D contact, transient mode, g0 = 1 mm).

Run {NAME}.fmu from 0 to {RUN['duration']} s with a fixed communication step of {RUN['h']} s, the inputs of
{NAME}_in.csv (one row per communication point: hold each value over the step that starts there, or
interpolate linearly: the same), and compare the outputs with {NAME}_ref.csv: they agree to round-off
(the FMU computes them in double precision with the same operations as the reference; 1e-9 relative to
each column's largest value is a generous bound: measured, about 1e-11). The native FMU's binaries give
identical numbers on every platform they were run on (linux64, aarch64-linux under qemu, win64 under
wine): the kernel has its own elementary functions. The outputs at t = 0 are those after initialisation.

Reference written by rotorub (fmu_src/build/crosscheck.py) from the library's run_transient(hold=h).
""" + ("""
FMI 3.0: the per-blade outputs are arrays of n_blades elements; column blade.F_N[j] is element j of the
array blade.F_N (fmi3GetFloat64 of its value reference with nValues = n_blades). Instantiate without early
return (earlyReturnAllowed = false) to take the communication steps of this table; with early return the
same run, continued from each early return to the next communication point, gives the same numbers here
(the step's remainder is a whole number of the same internal substeps).
""" if fmi == "3.0" else ""))
    return files


def _write_csv(path: Path, data: dict, columns) -> None:
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for k in range(len(data["time"])):
            w.writerow([repr(float(data[c][k])) for c in columns])


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    with Path(path).open() as f:
        rows = list(csv.reader(f))
    head, body = rows[0], np.array(rows[1:], dtype=float)
    return {name: body[:, k] for k, name in enumerate(head)}


def run_fmpy(fmu: str | Path, kit: str | Path) -> dict[str, np.ndarray]:
    """The kit's run through fmpy (FMU2Slave, inputs held over each step, outputs after each)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    inp = read_csv(Path(kit) / f"{NAME}_in.csv")
    unzip = extract(str(fmu))
    md = read_model_description(unzip)
    vr = {v.name: v for v in md.modelVariables}
    f = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="crosscheck")
    f.instantiate()
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    f.setReal([vr["Omega"].valueReference, vr["imbalance"].valueReference], [inp["Omega"][0], inp["imbalance"][0]])
    f.exitInitializationMode()
    reals = [o for o in OUTPUTS if vr[o].type == "Real"]
    ints = [o for o in OUTPUTS if vr[o].type != "Real"]
    rows = []

    def read():
        vals = dict(zip(reals, f.getReal([vr[o].valueReference for o in reals])))
        vals.update(zip(ints, f.getInteger([vr[o].valueReference for o in ints])))
        rows.append([vals[o] for o in OUTPUTS])

    read()
    t = inp["time"]
    for k in range(len(t) - 1):
        f.setReal([vr["Omega"].valueReference, vr["imbalance"].valueReference], [inp["Omega"][k], inp["imbalance"][k]])
        f.doStep(currentCommunicationPoint=t[k], communicationStepSize=t[k + 1] - t[k])
        read()
    f.terminate()
    f.freeInstance()
    arr = np.array(rows)
    return {"time": t, **{o: arr[:, i] for i, o in enumerate(OUTPUTS)}}


def run_libcosim(fmu: str | Path, kit: str | Path) -> dict[str, np.ndarray]:
    """The kit's run through OSP libcosim (its fixed-step algorithm, inputs by an override manipulator)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    inp = read_csv(Path(kit) / f"{NAME}_in.csv")
    t = inp["time"]
    h = float(t[1] - t[0])
    ex = CosimExecution.from_step_size(round(h * 1e9))
    slave = CosimLocalSlave(fmu_path=str(fmu), instance_name="rotor")
    i = ex.add_local_slave(slave)
    observer = CosimObserver.create_last_value()
    manipulator = CosimManipulator.create_override()
    ex.add_observer(observer)
    ex.add_manipulator(manipulator)
    refs = {v.name.decode(): (v.reference, v.type) for v in ex.slave_variables(i)}
    ins = [refs["Omega"][0], refs["imbalance"][0]]
    ex.real_initial_value(i, ins[0], float(inp["Omega"][0]))
    ex.real_initial_value(i, ins[1], float(inp["imbalance"][0]))
    rows = []
    for k in range(len(t) - 1):
        manipulator.slave_real_values(i, ins, [float(inp["Omega"][k]), float(inp["imbalance"][k])])
        if not ex.step(1):
            raise RuntimeError(f"libcosim step {k} failed")
        vals = []
        for o in OUTPUTS:
            ref, _typ = refs[o]
            vals.append(observer.last_integer_values(i, [ref])[0] if o == "n_contact"
                        else observer.last_real_values(i, [ref])[0])
        rows.append(vals)
    del ex, manipulator, observer, slave
    arr = np.array(rows)
    return {"time": t[1:], **{o: arr[:, j] for j, o in enumerate(OUTPUTS)}}


def compare(result: dict[str, np.ndarray], kit: str | Path) -> dict[str, float]:
    """Largest difference of each output against the reference, relative to the column's largest value
    (rows matched by time)."""
    ref = read_csv(Path(kit) / f"{NAME}_ref.csv")
    rows = np.searchsorted(ref["time"], result["time"] - 1e-12)
    out = {}
    for o in OUTPUTS:
        r = ref[o][rows]
        scale = max(float(np.abs(ref[o]).max()), 1e-300)
        out[o] = float(np.abs(result[o] - r).max() / scale)
    return out
