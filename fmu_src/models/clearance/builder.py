"""TipClearance.fmu in C (fmu_src/native/clearance_model.c behind the shared FMI wrapper): the engine's
clearance closure for the wear scenario (fmu_src/engine/wear_scenario.py)."""

from __future__ import annotations

import math
from pathlib import Path

from . import clearance_interface as ci
from .system import EngineError, build_small_native_fmu, specs_variables

C_ORDER = ("Omega", "closure0", "c_centrifugal", "c_thermal", "tau_thermal", "closure", "closure_centrifugal",
           "closure_thermal")


def clearance_variables(values: dict | None = None):
    """clearance_interface.SPECS as interface.Var (value reference = position)."""
    return specs_variables(ci.SPECS, {**ci.DEFAULTS, **(values or {})})


def build_clearance_fmu(dest: str | Path = "fmus/native", platforms: tuple[str, ...] | None = None,
                        **defaults) -> Path:
    """Build ``dest/TipClearance.fmu``; keyword arguments override the start values of the parameters and of the
    Omega input (a system whose spool starts turning: the closure at t0, and its thermal part warm there, are
    then the engine's before a master's first exchange, in every master alike)."""
    for k, v in defaults.items():
        spec = next((s for s in ci.SPECS if s[0] == k and s[2] in ("parameter", "input")), None)
        if spec is None:
            raise EngineError(f"clearance FMU: unknown parameter '{k}'; known: {', '.join(ci.DEFAULTS)}")
        if not (math.isfinite(float(v)) and spec[5][0] <= float(v) <= spec[5][1]):
            raise EngineError(f"clearance FMU: {k} = {v!r} out of range; accepted range {list(spec[5])}")
    facts = ("closure = closure0 + c_centrifugal Omega<sup>2</sup> + d_thermal, tau_thermal dd_thermal/dt = "
             "c_thermal Omega<sup>2</sup> - d_thermal, with Omega held over each step and the lag integrated "
             "exactly.")
    return build_small_native_fmu(dest, ci.MODEL_IDENTIFIER, "clearance_model.c", clearance_variables(defaults),
                                  C_ORDER, ci, facts, platforms)
