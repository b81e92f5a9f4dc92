"""CasingLoad.fmu's variables: the engine side's distortion of the fan case during a manoeuvre.

    s(t)  = 0                                     t <= t_start
          = (1 - cos(pi (t - t_start) / t_rise)) / 2   while it rises (t_rise long)
          = 1                                     for t_hold
          = (1 + cos(pi (t - t_end_hold) / t_fall)) / 2 while it falls (t_fall long), then 0
    n(t)  = 1 + (load_factor_peak - 1) s(t)       the load factor (1: level flight)
    a2(t) = ovalization_per_g (n(t) - 1)          casing_lobe2.amplitude, at the fixed angle ovalization_phase
    e(t)  = offset_per_g (n(t) - 1) (cos offset_angle, sin offset_angle)     casing_offset.x, casing_offset.y

A trapezoid in time with half-cosine edges (the spool's run-up shape: the load rate is continuous, as an airframe's
short-period response makes it; the corners of a straight-edged trapezoid would be a load-rate jump no pilot or
airframe delivers). The distortion is that of a linear-elastic carcass: proportional to the load increment n - 1
over level flight, both for the inertia of the case and nacelle (g load) and for the gyroscopic moment of the
pitch rate, which in a steady pull-up is q = (n - 1) g / V (so at a given spool speed and airspeed it too is
proportional to n - 1: one offset per g, with its direction, holds both). Level flight (load_factor_peak = 1)
distorts nothing: the reference of fmu_src/systems/manoeuvre_scenario.py.

Defaults (reasons in FMU.md): load_factor_peak 2.5 (the limit manoeuvring load factor of a transport aeroplane,
CS/14 CFR 25.337); ovalization 0.3 mm per g (0.45 mm at 2.5 g; a choice, five times the reference ring's own under
the case's weight), widest on the vertical (phase pi/2: a ring pulled at its top mount lengthens along the pull);
offset 0.05 mm per g, vertical (a choice: the carcass bending the reference model does not have). The fixed frame's
Y is taken vertical, up. The model is model.c next to this file.
"""

from __future__ import annotations

import math

from ...fmi.description import ModelInfo
from ...fmi.variables import TIME, Var, numbered, ranged

MODEL_IDENTIFIER = "CasingLoad"
DESCRIPTION = ("Distortion of a turbofan's fan case during a manoeuvre: a load-factor schedule (a trapezoid in time "
               "with half-cosine edges) scaling an ovalization (lobe 2, fixed orientation) and a rigid offset of the "
               "casing centre per unit load-factor increment; outputs for the blade-tip/casing contact FMU's "
               "casing_lobe2 and casing_offset inputs, in closed form at every communication point")
STATUS_OK = 0

DEFAULTS = {
    "load_factor_peak": 2.5,  # CS/14 CFR 25.337: a transport aeroplane's limit manoeuvring load factor
    "t_start": 1.0,  # s
    "t_rise": 0.5,  # s
    "t_hold": 2.0,  # s
    "t_fall": 0.5,  # s
    "ovalization_per_g": 3.0e-4,  # m: lobe 2 amplitude per unit of n - 1 (0.45 mm at 2.5 g)
    "ovalization_phase": math.pi / 2,  # rad: widest on the vertical
    "offset_per_g": 5.0e-5,  # m per unit of n - 1 (0.075 mm at 2.5 g)
    "offset_angle": math.pi / 2,  # rad: the casing centre moves up
}
LOAD_FACTOR_RANGE = (-5.0, 10.0)  # a push-over to a fighter's pull-up
PER_G_RANGE = (-1.0e-3, 1.0e-3)  # m: at |n - 1| <= 9 every output stays inside the contact FMU's +-10 mm inputs
OFFSET_PER_G_RANGE = (0.0, 1.0e-3)  # m: a magnitude (offset_angle gives the direction)
ANGLE_RANGE = (-2.0 * math.pi, 2.0 * math.pi)  # rad: the contact FMU's casing_lobe phase range

UNITS = {"m": ({"m": 1}, {"mm": 1e3}), "rad": ({"rad": 1}, {"deg": 180.0 / math.pi}), "s": ({"s": 1}, {}),
         "1": ({}, {})}

DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 5.0, "stepSize": 1e-3}

MODEL = ModelInfo(identifier=MODEL_IDENTIFIER, description=DESCRIPTION, units=UNITS,
                  default_experiment=DEFAULT_EXPERIMENT, initial_from_parameters=True)


def variables(values: dict | None = None) -> list[Var]:
    """CasingLoad's variables in value-reference order, numbered; the parameters' start values DEFAULTS overridden by
    ``values``. New variables go at the end."""
    x = {**DEFAULTS, **(values or {})}

    def par(name: str, unit: str, rng: tuple[float, float], text: str) -> Var:
        return ranged(name, unit, rng, text, x[name])

    def out(name: str, unit: str, text: str, display: str | None = None) -> Var:
        return Var(name, "Real", "output", "continuous", text, unit=unit, display_unit=display)

    return numbered([
        par("load_factor_peak", "1", LOAD_FACTOR_RANGE,
            "Load factor held at the top of the manoeuvre (1: level flight, no distortion; < 1: a push-over)"),
        par("t_start", "s", (0.0, 1e5), "Time the load factor starts to rise"),
        par("t_rise", "s", (0.0, 1e4), "Duration of the rise (half-cosine; 0: a step)"),
        par("t_hold", "s", (0.0, 1e5), "Duration the peak load factor is held"),
        par("t_fall", "s", (0.0, 1e4), "Duration of the fall back to level flight (half-cosine; 0: a step)"),
        par("ovalization_per_g", "m", PER_G_RANGE,
            "Lobe-2 amplitude of the casing's inner radius per unit load-factor increment n - 1 (> 0: widest at "
            "ovalization_phase)"),
        par("ovalization_phase", "rad", ANGLE_RANGE, "Fixed-frame angle where the ovalized casing is widest"),
        par("offset_per_g", "m", OFFSET_PER_G_RANGE,
            "Rigid offset of the casing centre from the rotor per unit load-factor increment n - 1"),
        par("offset_angle", "rad", ANGLE_RANGE, "Fixed-frame direction the casing centre moves for n > 1"),
        out("load_factor", "1", "Load factor n(t) = 1 + (load_factor_peak - 1) s(t)"),
        out("schedule", "1", "Schedule s(t) in [0, 1]: the trapezoid with half-cosine edges"),
        out("casing_lobe2.amplitude", "m", "Ovalization ovalization_per_g (n - 1), to the contact FMU's input of "
            "the same name", "mm"),
        out("casing_lobe2.phase", "rad", "ovalization_phase, to the contact FMU's input of the same name", "deg"),
        out("casing_offset.x", "m", "offset_per_g (n - 1) cos(offset_angle), to the contact FMU's input", "mm"),
        out("casing_offset.y", "m", "offset_per_g (n - 1) sin(offset_angle), to the contact FMU's input", "mm"),
        Var("status", "Integer", "output", "discrete", "0 = ok; 2 = bad parameter (call refused)"),
        Var("message", "String", "output", "discrete", "Cause of the last refused call"),
        TIME,  # the FMI 3.0 build's independent variable (FMI 2.0: none, a gap)
    ])
