"""RotorCasingContact's FMI cross-check kit, written next to each FMU (the files: fmu_src/fmi/crosscheck.py):

* ``RotorCasingContact_in.csv``: every input of the FMU, one row per communication point: ``time, Omega,
  imbalance, clearance_closure, casing_offset.x, casing_offset.y, casing_lobe2.amplitude, ...`` (a run-up through
  the first critical speed with the reference imbalance; half-way the engine ovalizes the casing: lobe 2 steps to
  ``RUN["oval"]`` at ``RUN["oval_phase"]``; the other engine inputs at their start values, 0);
* ``RotorCasingContact_ref.csv``: the reference outputs at the same points (FMI 3.0 kit: the per-blade outputs in
  the array columns, ``blade.F_N[1]``, ...);
* ``RotorCasingContact_ref.opt`` and ``ReadMe.txt``.

Every parameter keeps its default (the FMU's start values: g0 = 1 mm, 3D, transient), so any importing tool can
run it without setting anything but the inputs. The reference comes from the library (``run_transient(hold=h)``),
which every flavour reproduces to round-off. fmu_src/masters/crosscheck.py runs an FMU against it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...fmi import crosscheck as kit
from ...fmi.variables import declared, scalars
from . import variables as cv

NAME = cv.MODEL_IDENTIFIER
RUN = {"speed_from": 3.2, "speed_to": 3.8, "duration": 2.0, "h": 1e-3,  # normalised speeds; s
       "oval_at": 1.0, "oval": 0.3e-3, "oval_phase": 0.5}  # s; m (against the kit's 1 mm clearance); rad


def outputs(n_blades: int = 10) -> tuple[str, ...]:
    """The reference's outputs, by their FMI 2.0 names."""
    return ("friction_torque", "gap_min", "n_contact", "disk_displacement.x", "disk_displacement.y",
            "casing_force.x", "casing_force.y", "casing_force.z") + tuple(f"blade[{j}].F_N"
                                                                          for j in range(1, n_blades + 1))


OUTPUTS = outputs()


def _omega(w_ref: float):
    a, b, d = RUN["speed_from"], RUN["speed_to"], RUN["duration"]
    return lambda t: w_ref * (a + (b - a) * min(max(t / d, 0.0), 1.0))


def _variables(params):
    return cv.variables(cv.Defaults.from_parameters(params))


def reference(params=None) -> dict[str, np.ndarray]:
    """Every input (by name) and the reference outputs (FMI 2.0 names) at the communication points 0, h, ..."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.contact.liner import Liner
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import reference_parameters

    p = params or reference_parameters()
    m = build_model(p)
    w = _omega(p.normalisation.omega_ref)
    h, T, t1 = RUN["h"], RUN["duration"], RUN["oval_at"]
    c = make_contact(m, "3D")
    # the casing as the FMU holds it: round until t1, then oval (a rigid surface, the engine's input at a step)
    casing = Liner(c, wears=False)
    first = run_transient(m, c, w, t_end=t1, t_ramp=0.0, me=p.imbalance.me, record_dt=h, hold=h, liner=casing)
    casing.set_distortion({2: (RUN["oval"], RUN["oval_phase"])})
    second = run_transient(m, c, w, t_end=T - t1, t_ramp=0.0, me=p.imbalance.me, record_dt=h, hold=h,
                           liner=casing, start=first.final_state)
    n = len(first.t) + len(second.t)
    t = np.concatenate([[0.0], first.t, second.t])
    o = {k: np.concatenate([first.outputs[k], second.outputs[k]]) for k in first.outputs}
    out = {"time": t}
    # every input of the FMU: the run's speed and imbalance, the others held at their start values
    for v in scalars(declared(_variables(p), ("fmi2", "native"))):
        if v.causality == "input":
            out[v.name] = np.full(n + 1, float(v.start))
    out["Omega"] = np.array([w(x) for x in t])
    out["imbalance"] = np.full(n + 1, p.imbalance.me)
    # held over the step that starts at each row: the row at t1 starts the oval casing's first step
    out["casing_lobe2.amplitude"] = np.where(t >= t1 - 0.5 * h, RUN["oval"], 0.0)
    out["casing_lobe2.phase"] = np.full(n + 1, RUN["oval_phase"])
    zero = np.zeros(1)
    out["friction_torque"] = np.concatenate([zero, o["friction_torque"]])
    out["gap_min"] = np.concatenate([[p.contact.g0], o["gap"].min(axis=(1, 2))])
    out["n_contact"] = np.concatenate([zero, (o["F_N"] > 0).sum(axis=1)])
    for k, ax in enumerate("xy"):
        out[f"disk_displacement.{ax}"] = np.concatenate([zero, o["disk_fixed"][:, k]])
    for k, ax in enumerate("xyz"):
        out[f"casing_force.{ax}"] = np.concatenate([zero, o["casing_force_fixed"][:, k]])
    for j in range(p.blades.count):
        out[f"blade[{j + 1}].F_N"] = np.concatenate([zero, o["F_N"][:, j]])
    return out


def columns3(params=None) -> dict[str, str]:
    """The kit's FMI 2.0 column names -> the FMI 3.0 FMU's (``blade[j].F_N`` is ``blade.F_N[j]``)."""
    from rotorub_model.structure.params import reference_parameters

    return kit.element_columns(_variables(params or reference_parameters()))


def write_kit(dest: str | Path, params=None, fmi: str = "2.0") -> dict[str, Path]:
    """Write the kit into ``dest`` (next to the FMU). ``fmi = "3.0"``: the FMI 3.0 FMU's kit, the same run and
    numbers with the array elements as its columns (blade.F_N[1], ...)."""
    from rotorub_model.structure.params import reference_parameters

    p = params or reference_parameters()
    ref = reference(p)
    inputs = [v.name for v in scalars(declared(_variables(p), ("fmi2", "native"))) if v.causality == "input"]
    outs = outputs(p.blades.count)
    rename = columns3(p) if fmi == "3.0" else {}
    readme = f"""{NAME}: FMI cross-check kit (co-simulation)

A run-up with blade-tip / casing rub: the spin speed Omega rises linearly from {RUN['speed_from']} to
{RUN['speed_to']} x omega_ref (through the first critical speed) in {RUN['duration']} s, the imbalance is held at
the reference value; at t = {RUN['oval_at']} s the engine ovalizes the casing (casing_lobe2.amplitude steps to
{RUN['oval'] * 1e3:g} mm, casing_lobe2.phase {RUN['oval_phase']:g} rad); the engine's other inputs
({', '.join(i for i in inputs if i not in ('Omega', 'imbalance') and not i.startswith('casing_lobe2'))}) stay 0;
every parameter keeps its default (3D contact, transient mode, g0 = 1 mm).

Run {NAME}.fmu from 0 to {RUN['duration']} s with a fixed communication step of {RUN['h']} s, the inputs of
{NAME}_in.csv (every input of the FMU, one row per communication point: hold each value over the step that starts
there, or interpolate linearly: the same), and compare the outputs with {NAME}_ref.csv: they agree to round-off
(the FMU computes them in double precision with the same operations as the reference; 1e-9 relative to
each column's largest value is a generous bound: measured, about 1e-11). The native FMU's binaries give
identical numbers on every platform they were run on (linux64, aarch64-linux under qemu, win64 under
wine): the kernel has its own elementary functions. The outputs at t = 0 are those after initialisation.

Reference written by rotorub (fmu_src/models/contact/crosscheck.py) from the library's run_transient(hold=h).
""" + ("""
FMI 3.0: the per-blade outputs are arrays of n_blades elements; column blade.F_N[j] is element j of the
array blade.F_N (fmi3GetFloat64 of its value reference with nValues = n_blades). Instantiate without early
return (earlyReturnAllowed = false) to take the communication steps of this table; with early return the
same run, continued from each early return to the next communication point, gives the same numbers here
(the step's remainder is a whole number of the same internal substeps).
""" if fmi == "3.0" else "")
    return kit.write_kit(dest, NAME, ref["time"], {k: ref[k] for k in inputs},
                     {rename.get(c, c): ref[c] for c in outs}, RUN["h"], readme)
