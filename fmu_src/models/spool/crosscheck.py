"""LPSpool's FMI cross-check kit (the files: fmu_src/fmi/crosscheck.py): a run-up through its speed schedule with a
braking torque switched on half way, as the contact's rub would apply it.

* ``LPSpool_in.csv``: ``time, friction_torque``: 0 until 2.5 s, then -2000 N.m (held over each step);
* ``LPSpool_ref.csv``: ``Omega, Omega_schedule, drive_torque, windage_torque`` at the communication points;
* every parameter at its default (J = 55.5 kg.m2, the half-cosine run-up 149.52 -> 224.28 rad/s from 0.5 s in 4 s).

The reference is an independent solution of J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque by scipy's
DOP853 (relative tolerance 1e-13), in pieces split at the communication points where the torque changes and at the
schedule's kinks; the FMU's RK4 in 1 ms substeps agrees to about 2e-11 of each column's largest value.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...fmi import crosscheck as kit
from . import variables as sv

NAME = sv.MODEL_IDENTIFIER
RUN = {"duration": 5.0, "h": 1e-3, "t_brake": 2.5, "tau_brake": -2000.0}  # s, s, s, N.m
OUTPUTS = ("Omega", "Omega_schedule", "drive_torque", "windage_torque")


def _schedule(t: float, p: dict) -> tuple[float, float]:
    x = (t - p["t_ramp_start"]) / p["t_ramp"]
    if x <= 0.0:
        return p["Omega0"], 0.0
    if x >= 1.0:
        return p["Omega1"], 0.0
    d = p["Omega1"] - p["Omega0"]
    return (p["Omega0"] + 0.5 * d * (1.0 - math.cos(math.pi * x)),
            0.5 * d * math.pi / p["t_ramp"] * math.sin(math.pi * x))


def reference() -> dict[str, np.ndarray]:
    """The input and the reference outputs at the communication points 0, h, ..., duration."""
    from scipy.integrate import solve_ivp

    p = dict(sv.DEFAULTS)
    h, T = RUN["h"], RUN["duration"]
    t = np.round(np.arange(0.0, T + 0.5 * h, h) / h) * h
    tau = np.where(t >= RUN["t_brake"] - 1e-12, RUN["tau_brake"], 0.0)

    def rhs(s, y, torque):
        w, wd = _schedule(s, p)
        return [(p["J"] * wd + p["c_w"] * w * w - p["c_w"] * y[0] ** 2 + torque) / p["J"]]

    kinks = sorted({0.0, RUN["t_brake"], p["t_ramp_start"], p["t_ramp_start"] + p["t_ramp"], T})
    omega = np.empty_like(t)
    omega[0], y0 = p["Omega0"], p["Omega0"]
    for a, b in zip(kinks[:-1], kinks[1:]):
        m = (t > a + 1e-12) & (t <= b + 1e-12)
        sol = solve_ivp(rhs, (a, b), [y0], method="DOP853", t_eval=t[m], rtol=1e-13, atol=1e-10,
                        args=(RUN["tau_brake"] if a >= RUN["t_brake"] - 1e-12 else 0.0,))
        if not sol.success:
            raise RuntimeError(f"LPSpool reference: {sol.message}")
        omega[m] = sol.y[0]
        y0 = float(sol.y[0, -1])  # at b: every piece ends at a communication point
    ws = np.array([_schedule(x, p) for x in t])
    return {"time": t, "friction_torque": tau, "Omega": omega, "Omega_schedule": ws[:, 0],
            "drive_torque": p["J"] * ws[:, 1] + p["c_w"] * ws[:, 0] ** 2, "windage_torque": p["c_w"] * omega ** 2}


def write_kit(dest: str | Path) -> dict[str, Path]:
    """Write the kit into ``dest`` (next to the FMU)."""
    ref = reference()
    readme = f"""{NAME}: FMI cross-check kit (co-simulation)

The spool runs up its speed schedule (parameters at their defaults) while a braking torque of
{RUN['tau_brake']:g} N.m, as the blade-tip rub would apply it, is set from t = {RUN['t_brake']:g} s on.

Run {NAME}.fmu from 0 to {RUN['duration']:g} s with a fixed communication step of {RUN['h']:g} s, the input of
{NAME}_in.csv held over each step, and compare with {NAME}_ref.csv: the reference solves the spool's equation
with scipy's DOP853 (relative tolerance 1e-13); the FMU's RK4 agrees to about 2e-11 of each column's largest value
(1e-9 is the kit's bound).

Written by rotorub (fmu_src/models/spool/crosscheck.py).
"""
    return kit.write_kit(dest, NAME, ref["time"], {"friction_torque": ref["friction_torque"]},
                         {c: ref[c] for c in OUTPUTS}, RUN["h"], readme)
