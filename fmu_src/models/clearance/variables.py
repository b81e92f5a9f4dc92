"""TipClearance.fmu's variables: the closure of the fan's tip clearance from the spool speed.

    closure = closure0 + c_centrifugal Omega^2 + d_thermal,   tau_thermal dd_thermal/dt = c_thermal Omega^2 - d_thermal

What an engine's performance model would hand the contact model (issue 19.5): the blades and the disk grow
with the centrifugal load at once, the casing's thermal growth lags the speed. The defaults are of a 2 m fan
at the reference's top speed (224 rad/s): 0.3 mm centrifugal (titanium blades of 0.6 m on a 0.4 m hub:
rho Omega^2 / E ~ 2e-3 1/m^2 over the blade gives about 0.28 mm, the disk adds a little), 0.2 mm thermal with
a 2 s lag (a real casing takes tens of seconds; 2 s lets a 5 s scenario show the lag). The thermal growth
starts warm at the initial speed (the engine was running there). The model is model.c next to this file.
"""

from __future__ import annotations

from ...fmi.description import ModelInfo
from ...fmi.variables import TIME, Var, numbered, ranged

MODEL_IDENTIFIER = "TipClearance"
DESCRIPTION = ("Closure of a fan's tip clearance from the spool speed: centrifugal growth c_centrifugal Omega^2 at "
               "once, thermal growth c_thermal Omega^2 through a first-order lag tau_thermal, plus a constant "
               "closure0; Omega held over each step (the lag integrated exactly)")
STATUS_OK = 0

DEFAULTS = {
    "closure0": 0.0,  # m
    "c_centrifugal": 6.0e-9,  # m s^2/rad^2: 0.3 mm at 224 rad/s
    "c_thermal": 4.0e-9,  # m s^2/rad^2: 0.2 mm at 224 rad/s, once warm
    "tau_thermal": 2.0,  # s
}

# unit -> (SI base-unit exponents, display units)
UNITS = {"rad/s": ({"rad": 1, "s": -1}, {}), "m": ({"m": 1}, {}), "m.s2/rad2": ({"m": 1, "rad": -2, "s": 2}, {}),
         "s": ({"s": 1}, {})}

DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 5.0, "stepSize": 1e-3}

MODEL = ModelInfo(identifier=MODEL_IDENTIFIER, description=DESCRIPTION, units=UNITS,
                  default_experiment=DEFAULT_EXPERIMENT)


def variables(values: dict | None = None) -> list[Var]:
    """TipClearance's variables in value-reference order, numbered; the start values of the parameters DEFAULTS
    and of the input Omega 0, overridden by ``values``. New variables go at the end."""
    x = {**DEFAULTS, **(values or {})}

    def par(name: str, unit: str, rng: tuple[float, float], text: str, *kind: str) -> Var:
        return ranged(name, unit, rng, text, x.get(name, 0.0), *kind)

    return numbered([
        par("Omega", "rad/s", (0.0, 1e4), "Spin speed of the LP spool, held over each step", "input", "continuous"),
        par("closure0", "m", (-0.01, 0.01), "Constant part of the closure (a cold build clearance offset; > 0 closes)"),
        par("c_centrifugal", "m.s2/rad2", (0.0, 1e-6), "Centrifugal growth of blades and disk per Omega^2 (at once)"),
        par("c_thermal", "m.s2/rad2", (-1e-6, 1e-6),
            "Steady thermal closure per Omega^2 (> 0: the rotor grows more than the casing)"),
        par("tau_thermal", "s", (1e-3, 1e5), "Time constant of the thermal growth"),
        Var("closure", "Real", "output", "continuous",
            "Closure of the tip clearance, to the contact FMU's clearance_closure (> 0 closes)", unit="m"),
        Var("closure_centrifugal", "Real", "output", "continuous", "Centrifugal part c_centrifugal Omega^2", unit="m"),
        Var("closure_thermal", "Real", "output", "continuous", "Thermal part (lagging the speed)", unit="m"),
        Var("status", "Integer", "output", "discrete", "0 = ok; 2 = bad parameter or input (call refused)"),
        Var("message", "String", "output", "discrete", "Cause of the last refused call"),
        TIME,  # the FMI 3.0 build's independent variable (FMI 2.0: none, a gap)
    ])
