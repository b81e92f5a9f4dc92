"""TipClearance's FMI cross-check kit (the files: fmu_src/fmi/crosscheck.py): the closure through a run-up of the
spool speed.

* ``TipClearance_in.csv``: ``time, Omega``: 149.52 rad/s, then a linear ramp to 224.28 rad/s from 0.5 s to 4.5 s,
  held over each step;
* ``TipClearance_ref.csv``: ``closure, closure_centrifugal, closure_thermal`` at the communication points;
* every parameter at its default; the thermal growth warm at the first speed (``Omega``'s start value is the
  first row's, as a master that propagates the spool's initial speed gives it).

The reference is the closed form of tau dd/dt = c_thermal Omega^2 - d with Omega constant over each step,
d(t + h) = c Omega^2 + (d(t) - c Omega^2) exp(-h / tau), written here independently of model.c.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...fmi import crosscheck as kit
from . import variables as cv

NAME = cv.MODEL_IDENTIFIER
RUN = {"duration": 5.0, "h": 1e-3, "omega_from": 149.52, "omega_to": 224.28, "t_ramp": (0.5, 4.5)}
OUTPUTS = ("closure", "closure_centrifugal", "closure_thermal")


def reference() -> dict[str, np.ndarray]:
    p = dict(cv.DEFAULTS)
    h, T = RUN["h"], RUN["duration"]
    t = np.round(np.arange(0.0, T + 0.5 * h, h) / h) * h
    a, b = RUN["t_ramp"]
    w = RUN["omega_from"] + (RUN["omega_to"] - RUN["omega_from"]) * np.clip((t - a) / (b - a), 0.0, 1.0)
    d = np.empty_like(t)
    d[0] = p["c_thermal"] * w[0] ** 2  # warm at the first speed
    held = np.empty_like(t)  # the speed the outputs at t_k follow: the one held over the step that ended there
    held[0] = w[0]
    for k in range(len(t) - 1):
        target = p["c_thermal"] * w[k] ** 2
        d[k + 1] = target + (d[k] - target) * np.exp(-h / p["tau_thermal"])
        held[k + 1] = w[k]
    cen = p["c_centrifugal"] * held ** 2
    return {"time": t, "Omega": w, "closure": p["closure0"] + cen + d, "closure_centrifugal": cen,
            "closure_thermal": d}


def write_kit(dest: str | Path) -> dict[str, Path]:
    """Write the kit into ``dest`` (next to the FMU)."""
    ref = reference()
    readme = f"""{NAME}: FMI cross-check kit (co-simulation)

The closure of a fan's tip clearance while the spool runs up from {RUN['omega_from']} to {RUN['omega_to']} rad/s
(a linear ramp from {RUN['t_ramp'][0]:g} to {RUN['t_ramp'][1]:g} s), every parameter at its default.

Run {NAME}.fmu from 0 to {RUN['duration']:g} s with a fixed communication step of {RUN['h']:g} s, Omega's start
value set to the first row of {NAME}_in.csv (the engine's speed before the run: the thermal growth starts warm
there) and the input held over each step; compare with {NAME}_ref.csv: the closed form of the thermal lag with the
speed held, to round-off (1e-9 of each column's largest value is the kit's bound).

Written by rotorub (fmu_src/models/clearance/crosscheck.py).
"""
    return kit.write_kit(dest, NAME, ref["time"], {"Omega": ref["Omega"]}, {c: ref[c] for c in OUTPUTS},
                         RUN["h"], readme)
