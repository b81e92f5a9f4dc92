"""CasingLoad's FMI cross-check kit (the files: fmu_src/fmi/crosscheck.py): the default manoeuvre, a pull-up to
2.5 g held 2 s.

* ``CasingLoad_in.csv``: ``time`` only (the model has no input);
* ``CasingLoad_ref.csv``: ``load_factor, schedule, casing_lobe2.amplitude, casing_lobe2.phase, casing_offset.x,
  casing_offset.y`` at the communication points;
* every parameter at its default.

The reference is the closed form of the schedule, written here independently of model.c (the fall as the rise
mirrored in time, (1 - cos(pi (t_end - t) / t_fall)) / 2, where model.c writes (1 + cos(pi (t - t_hold_end) /
t_fall)) / 2: the same function, other round-off).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...fmi import crosscheck as kit
from . import variables as lv

NAME = lv.MODEL_IDENTIFIER
RUN = {"duration": 5.0, "h": 1e-3}
OUTPUTS = ("load_factor", "schedule", "casing_lobe2.amplitude", "casing_lobe2.phase", "casing_offset.x",
           "casing_offset.y")


def closed_form(t: np.ndarray, **values: float) -> dict[str, np.ndarray]:
    """The outputs at the times ``t`` for the parameters DEFAULTS updated by ``values``.

    >>> out = closed_form(np.array([0.0, 1.25, 2.0, 4.0]))  # before, half-way up, held, back to level flight
    >>> [round(float(x), 12) for x in out["load_factor"]]
    [1.0, 1.75, 2.5, 1.0]
    >>> round(float(closed_form(np.array([2.0]), load_factor_peak=-1.0)["casing_lobe2.amplitude"][0]), 12)
    -0.0006
    """
    p = {**lv.DEFAULTS, **values}
    t = np.asarray(t, dtype=float)
    t0, tr, th, tf = p["t_start"], p["t_rise"], p["t_hold"], p["t_fall"]
    t_up, t_end = t0 + tr, t0 + tr + th + tf
    with np.errstate(divide="ignore", invalid="ignore"):
        rise = 0.5 * (1.0 - np.cos(math.pi * (t - t0) / tr))
        fall = 0.5 * (1.0 - np.cos(math.pi * (t_end - t) / tf))
    s = np.select([t < t0, t < t_up, t <= t_up + th, t < t_end], [0.0, rise, 1.0, fall], 0.0)
    dn = (p["load_factor_peak"] - 1.0) * s
    return {"load_factor": 1.0 + dn, "schedule": s, "casing_lobe2.amplitude": p["ovalization_per_g"] * dn,
            "casing_lobe2.phase": np.full_like(t, p["ovalization_phase"]),
            "casing_offset.x": p["offset_per_g"] * dn * math.cos(p["offset_angle"]),
            "casing_offset.y": p["offset_per_g"] * dn * math.sin(p["offset_angle"])}


def reference() -> dict[str, np.ndarray]:
    h, T = RUN["h"], RUN["duration"]
    t = np.round(np.arange(0.0, T + 0.5 * h, h) / h) * h
    return {"time": t, **closed_form(t)}


def write_kit(dest: str | Path) -> dict[str, Path]:
    """Write the kit into ``dest`` (next to the FMU)."""
    ref = reference()
    p = lv.DEFAULTS
    readme = f"""{NAME}: FMI cross-check kit (co-simulation)

The fan case's distortion during a pull-up: the load factor rises from 1 to {p['load_factor_peak']:g} from
t = {p['t_start']:g} s over {p['t_rise']:g} s (half-cosine), holds {p['t_hold']:g} s, falls back over {p['t_fall']:g} s;
the ovalization ({p['ovalization_per_g'] * 1e3:g} mm per g) and the casing centre's offset
({p['offset_per_g'] * 1e3:g} mm per g) follow it. Every parameter at its default; the model has no input
({NAME}_in.csv holds the time column only).

Run {NAME}.fmu from 0 to {RUN['duration']:g} s with a fixed communication step of {RUN['h']:g} s and compare with
{NAME}_ref.csv: the closed form of the schedule at the communication points, to round-off (1e-9 of each column's
largest value is the kit's bound).

Written by rotorub (fmu_src/models/casing_load/crosscheck.py).
"""
    return kit.write_kit(dest, NAME, ref["time"], {}, {c: ref[c] for c in OUTPUTS}, RUN["h"], readme)
