"""RotorCasingContact's FMI cross-check kit, written next to each FMU (the files: fmu_src/fmi/crosscheck.py):

* ``RotorCasingContact_in.csv``: every input of the FMU, one row per communication point: ``time, Omega,
  imbalance, clearance_closure, casing_offset.x, casing_offset.y, casing_lobe2.amplitude, ...`` (a run-up through
  the first critical speed; half-way the engine ovalizes the casing: lobe 2 steps to ``RUN["oval"]``; every other
  input moves too, each at its own times (:data:`ENGINE`, :data:`IMBALANCE`), so that a mis-wired host fails);
* ``RotorCasingContact_ref.csv``: the reference outputs at the same points (FMI 3.0 kit: the per-blade outputs in
  the array columns, ``blade.F_N[1]``, ...);
* ``RotorCasingContact_ref.opt`` and ``ReadMe.txt``.

Every parameter keeps its default (the FMU's start values: g0 = 1 mm, 3D, transient), so any importing tool can
run it without setting anything but the inputs. The reference comes from the library (``run_transient(hold=h)``),
which every flavour reproduces to round-off. fmu_src/masters/crosscheck.py runs an FMU against it.

**Reference experiments** (below the kit): shipped inside the FMU (FMI-LS-REF, fmu_src/fmi/lsref.py) and replayed
by ``rotorub fmu-check`` in any importer; the kit is the ``run_up`` experiment with every blade's force compared.

Each experiment is what a system engineer would check the FMU on: the paper's section-6 transients (2D and 3D, at
Omega = 3.3 omega_ref and g0 = 0.8 mm, the imbalance ramped over 1 s), a run-up through the first critical speed (the
cross-check kit's run), a casing ovalizing while the blades rub, an abradable liner worn by the rub, and a
divergence (a penetration beyond ``max_penetration``: the FMU ends the run, status 1).

**Every input moves in every experiment**, each at its own times and to its own values (:data:`ENGINE`): a host that
wires two inputs the wrong way round (swaps the casing offsets, the lobe phases, ...) computes another rub and fails
the experiment's tolerance. The moves are small beside the clearance (at most 0.1 mm), so each experiment stays the
case it is named after.

The reference results come from the library (``run_transient(hold=h)``, run in pieces between the input changes),
not from the FMU: the FMU's kernel is the library's, and an importer that runs it as FMI says reproduces these
numbers to round-off (measured: about 1e-10 of each column's largest value; tolerance 1e-8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...fmi import crosscheck as kit
from ...fmi.variables import declared, scalars
from . import variables as cv

NAME = cv.MODEL_IDENTIFIER
RUN = {"speed_from": 3.2, "speed_to": 3.8, "duration": 2.0, "h": 1e-3,  # normalised speeds; s
       "oval_at": 1.0, "oval": 0.3e-3}  # s; m (against the kit's 1 mm clearance)


def outputs(n_blades: int = 10) -> tuple[str, ...]:
    """The reference's outputs, by their FMI 2.0 names."""
    return ("friction_torque", "gap_min", "n_contact", "disk_displacement.x", "disk_displacement.y",
            "casing_force.x", "casing_force.y", "casing_force.z") + tuple(f"blade[{j}].F_N"
                                                                          for j in range(1, n_blades + 1))


OUTPUTS = outputs()


def _variables(params):
    return cv.variables(cv.Defaults.from_parameters(params))


def reference(params=None) -> dict[str, np.ndarray]:
    """Every input (by name) and the reference outputs (FMI 2.0 names) at the communication points 0, h, ...: the
    ``run_up`` experiment with every blade's normal force."""
    from rotorub_model.structure.params import reference_parameters

    p = params or reference_parameters()
    run_up = next(e for e in experiments() if e.name == "run_up")
    return experiment_reference(replace(run_up, outputs=outputs(p.blades.count)), p)


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
{RUN['speed_to']} x omega_ref (through the first critical speed) in {RUN['duration']} s; at t = {RUN['oval_at']} s the
engine ovalizes the casing (casing_lobe2.amplitude steps to {RUN['oval'] * 1e3:g} mm). Every other input moves
too, each at its own times and to its own values (the imbalance by +15 % and -10 %, the clearance closure, the
casing offsets and the lobes by at most 0.1 mm): a host that mis-wires two inputs computes another rub and fails;
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


# ----------------------------------------------------------------------- reference experiments (FMI-LS-REF)
TOLERANCE = 1e-8  # of each output's largest absolute value over the run (round-off: about 1e-10)

# the engine's inputs, moving in every experiment: input -> [(fraction of the experiment's duration, value)], held
# from there on (the input's start value before)
ENGINE: dict[str, list[tuple[float, float]]] = {
    "clearance_closure": [(0.125, 0.05e-3), (0.625, 0.1e-3)],
    "casing_offset.x": [(0.175, 0.02e-3), (0.725, -0.01e-3)],
    "casing_offset.y": [(0.325, -0.03e-3), (0.875, 0.015e-3)],
    "casing_lobe2.amplitude": [(0.275, 0.02e-3)],
    "casing_lobe2.phase": [(0.0, 0.5), (0.475, 0.7)],
    "casing_lobe3.amplitude": [(0.2, 0.04e-3)],
    "casing_lobe3.phase": [(0.0, 0.2), (0.575, 0.9)],
    "casing_lobe4.amplitude": [(0.35, 0.03e-3)],
    "casing_lobe4.phase": [(0.0, 1.1), (0.675, 0.4)],
}
# the imbalance where an experiment does not drive it itself (a ramp, or its own steps): factors of the reference's
IMBALANCE = [(0.4, 1.15), (0.8, 0.9)]

EXP_OUTPUTS = outputs(1)  # the kit's outputs with blade 1's force only (at most ten outputs an experiment)


@dataclass(frozen=True)
class Experiment:
    """One reference experiment: parameters (FMI start values), a spin-speed ramp, input steps, a duration."""

    name: str
    description: str
    duration: float  # s
    speed: tuple[float, float]  # Omega / omega_ref at t = 0 and at t = duration (linear between)
    parameters: dict[str, float | int] = field(default_factory=dict)
    # input steps on top of ENGINE (they replace an input's ENGINE list): input -> [(t, value)]
    stimuli: dict[str, list[tuple[float, float]]] = field(default_factory=dict)
    imbalance_ramp: float = 0.0  # s: the imbalance rises from 0 to the reference over this time (0: held)
    outputs: tuple[str, ...] = EXP_OUTPUTS
    h: float = 1e-3
    tolerance: float = TOLERANCE


def experiments() -> list[Experiment]:
    """The contact FMU's experiments (parameters by their FMI names; enumerations by value)."""
    return [
        Experiment("section6_3D", "The paper's section-6 transient in 3D: Omega = 3.3 omega_ref, g0 = 0.8 mm, the "
                   "imbalance ramped over 1 s; three blades touch, the rub settles on the stable static solution",
                   1.5, (3.3, 3.31), {"formulation": 2, "g0": 0.8e-3}, imbalance_ramp=1.0),
        Experiment("section6_2D", "The paper's section-6 transient in 2D (point blade tips on a cylindrical casing), "
                   "same point and ramp", 1.5, (3.3, 3.31), {"formulation": 1, "g0": 0.8e-3}, imbalance_ramp=1.0),
        Experiment("run_up", f"A run-up through the first critical speed ({RUN['speed_from']} to {RUN['speed_to']} "
                   f"omega_ref in {RUN['duration']:g} s), the casing ovalized half-way (lobe 2 steps to "
                   f"{RUN['oval'] * 1e3:g} mm at t = {RUN['oval_at']:g} s); the cross-check kit's run",
                   RUN["duration"], (RUN["speed_from"], RUN["speed_to"]), {},
                   {"casing_lobe2.amplitude": [(RUN["oval_at"], RUN["oval"])]}, h=RUN["h"]),
        Experiment("oval_casing", "An ovalizing casing (lobe 2: 0.1, 0.2, 0.3 mm at 0.3, 0.6, 0.9 s) under rubbing "
                   "blades at 3.3 omega_ref, g0 = 0.5 mm", 1.2, (3.3, 3.35), {"g0": 0.5e-3},
                   {"casing_lobe2.amplitude": [(0.3, 0.1e-3), (0.6, 0.2e-3), (0.9, 0.3e-3)]}),
        Experiment("wear", "The rub against an abradable liner (yield force 100 N): the liner is cut where the tips "
                   "press it, g0 = 0.3 mm at 3.4 omega_ref", 1.0, (3.4, 3.42), {"g0": 0.3e-3, "liner": 2},
                   outputs=EXP_OUTPUTS[:8] + ("wear.depth_max",)),
        Experiment("divergence", "A blade lost (the imbalance steps to 0.5 kg m at t = 0.1 s) with g0 = 0.1 mm in 3D: "
                   "the penetration passes max_penetration (3 mm) about 40 ms later and the FMU ends the run "
                   "(terminate, status 1)", 0.3, (3.3, 3.31), {"g0": 0.1e-3}, {"imbalance": [(0.1, 0.5)]},
                   outputs=EXP_OUTPUTS[:8] + ("status",)),
    ]


def _at(steps: list[tuple[float, float]], t: float, start: float) -> float:
    v = start
    for ts, x in steps:
        if ts <= t + 1e-12:
            v = x
    return v


def stimuli_of(e: Experiment) -> dict[str, list[tuple[float, float]]]:
    """Every engine input's steps in this experiment, in seconds (ENGINE scaled to its duration, with the
    experiment's own steps in place of some)."""
    def snap(f: float) -> float:  # on a communication point: an input changes at the start of a step
        return round(f * e.duration / e.h) * e.h

    return {**{k: [(snap(f), v) for f, v in s] for k, s in ENGINE.items()}, **e.stimuli}


def experiment_reference(e: Experiment, params=None) -> dict[str, np.ndarray]:
    """``time``, every input of the FMU and the experiment's outputs at the communication points 0, h, ..., from
    the library (the FMU's inputs held over each step, as a co-simulation master holds them). A run that
    diverges ends at the step where it did (its last row: that step's outputs)."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.contact.liner import Liner
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import reference_parameters

    from ...fmi.variables import declared, scalars

    p = params or reference_parameters()
    m = build_model(p)
    variables = cv.variables(cv.Defaults.from_parameters(p, m))
    defaults = {v.name: v.start for v in variables if v.settable}
    par = {**defaults, **e.parameters}
    w_ref = p.normalisation.omega_ref
    h, T = e.h, e.duration
    a, b = e.speed

    def omega(t: float) -> float:
        return w_ref * (a + (b - a) * min(max(t / T, 0.0), 1.0))

    me_ref = p.imbalance.me
    formulation = {1: "2D", 2: "3D"}[int(par["formulation"])]
    c = make_contact(m, formulation, g0=float(par["g0"]))
    wears = int(par["liner"]) == 2
    liner = Liner.for_model(m, c, wears=True) if wears else Liner(c, wears=False)
    steps = stimuli_of(e)
    inputs = [v.name for v in scalars(declared(variables, ("fmi2", "native"))) if v.causality == "input"]
    n_steps = int(round(T / h))
    grid = np.arange(n_steps + 1) * h
    own_imbalance = "imbalance" in steps or e.imbalance_ramp > 0
    imbalance = [(round(f * T / h) * h, x) for f, x in IMBALANCE]
    cuts = sorted({int(round(t / h)) for s in [*steps.values(), [] if own_imbalance else imbalance] for t, _ in s
                   if 0 < t < T} | {n_steps})
    if e.imbalance_ramp > 0:  # the ramp is an input history: one piece per step while it rises
        cuts = sorted(set(cuts) | set(range(1, int(round(e.imbalance_ramp / h)) + 1)))
    if wears:  # the FMU's wear outputs are the liner's summary after each step: one piece per step
        cuts = list(range(1, n_steps + 1))

    def me_at(k: int) -> float:
        if "imbalance" in steps:
            return _at(steps["imbalance"], k * h, me_ref)
        if e.imbalance_ramp > 0:
            return me_ref * min(k * h / e.imbalance_ramp, 1.0)
        return me_ref * _at(imbalance, k * h, 1.0)

    rows: list[dict[str, np.ndarray]] = []
    state, k0, diverged, t_stop = None, 0, False, math.inf
    for k1 in cuts:
        t0 = k0 * h
        val = {name: _at(s, t0, float(defaults[name])) for name, s in steps.items()}
        liner.set_inputs(closure=val["clearance_closure"], offset=(val["casing_offset.x"], val["casing_offset.y"]),
                         distortion={n: (val[f"casing_lobe{n}.amplitude"], val[f"casing_lobe{n}.phase"])
                                     for n in (2, 3, 4)})
        r = run_transient(m, c, omega, t_end=(k1 - k0) * h, t_ramp=0.0, me=me_at(k0), record_dt=h, hold=h,
                          liner=liner, start=state, max_penetration=float(par["max_penetration"]),
                          wear_record_dt=h)
        o = r.outputs
        piece = {"F_N": o["F_N"], "gap": o["gap"].min(axis=tuple(range(1, o["gap"].ndim))),
                 "friction_torque": o["friction_torque"], "disk": o["disk_fixed"][:, :2],
                 "casing": o["casing_force_fixed"][:, :3]}
        if wears:
            piece["wear"] = np.array([liner.summary()["depth_max"]])
        rows.append(piece)
        state, k0 = r.final_state, k1
        if r.penetration_limit_hit:
            diverged = True
            t_stop = r.t_end
            break
    cat = {k: np.concatenate([piece[k] for piece in rows]) for k in rows[0]}
    n = len(cat["F_N"])  # steps completed
    # a diverged run: the FMU ends the step where the penetration passed the limit, with the outputs of the state
    # it stopped in and status 1. Crossed at the step's very end (at_row), that state is the last row's; inside the
    # step, one more row: its time and status are the reference, its other values are not (NaN: not compared)
    at_row = diverged and abs(t_stop - n * h) < 1e-9 * max(h, 1.0)
    extra = int(diverged and not at_row)
    t = grid[:n + 1 + extra]
    out: dict[str, np.ndarray] = {"time": t}
    for name in inputs:
        if name == "Omega":
            out[name] = np.array([omega(x) for x in t])
        elif name == "imbalance":  # a ramp or steps
            out[name] = np.array([me_at(k) for k in range(len(t))])
        else:
            out[name] = np.array([_at(steps.get(name, []), x, float(defaults[name])) for x in t])
    tail = np.full(extra, np.nan)

    def col(first: float, values: np.ndarray) -> np.ndarray:
        return np.concatenate([[first], values, tail])

    full = {"friction_torque": col(0.0, cat["friction_torque"]), "gap_min": col(float(par["g0"]), cat["gap"]),
            "n_contact": col(0.0, (cat["F_N"] > 0).sum(axis=1)),
            "disk_displacement.x": col(0.0, cat["disk"][:, 0]), "disk_displacement.y": col(0.0, cat["disk"][:, 1]),
            "casing_force.x": col(0.0, cat["casing"][:, 0]), "casing_force.y": col(0.0, cat["casing"][:, 1]),
            "casing_force.z": col(0.0, cat["casing"][:, 2]),
            "status": np.concatenate([np.zeros(n + 1 - int(at_row)), np.ones(int(diverged))])}
    for j in range(p.blades.count):
        full[f"blade[{j + 1}].F_N"] = col(0.0, cat["F_N"][:, j])
    if wears:
        full["wear.depth_max"] = col(0.0, cat["wear"])
    out.update({k: full[k] for k in e.outputs})
    return out


def ref_experiments(params=None, fmi: str = "2.0") -> list:
    """The experiments as they travel in the FMU (fmu_src/fmi/lsref.py): enumerations by item name, the FMI 3.0
    FMU's array elements as ``name[k]`` columns, every parameter the reference depends on set explicitly."""
    from rotorub_model.structure.params import reference_parameters

    from ...fmi.lsref import RefExperiment

    p = params or reference_parameters()
    variables = cv.variables(cv.Defaults.from_parameters(p))
    enum_items = {name: [item for item, _ in items] for name, items in cv.MODEL.enumerations.items()}
    by_name = {v.name: v for v in variables}
    rename = kit.element_columns(variables) if fmi == "3.0" else {}
    out = []
    for e in experiments():
        ref = experiment_reference(e, p)
        pars: dict[str, float | int | str] = {}
        for name, value in {"formulation": 2, "liner": 1, **e.parameters}.items():
            v = by_name[name]
            pars[name] = enum_items[v.declared_type][int(value) - 1] if v.type == "Enumeration" else value
        inputs = {k: ref[k] for k in ref if k not in e.outputs}
        reference_cols = {"time": ref["time"], **{rename.get(c, c): ref[c] for c in e.outputs}}
        out.append(RefExperiment(e.name, e.description, pars, inputs, reference_cols, e.h, e.tolerance))
    return out
