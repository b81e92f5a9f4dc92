"""Build TipClearance.fmu (model.c behind the FMI layer's wrapper) from its variable list (variables.py): the
engine's clearance closure for the wear scenario (fmu_src/systems/wear_scenario.py)."""

from __future__ import annotations

import math
from pathlib import Path

from ...fmi.package import NativeBuild, build_native
from . import variables as cv

HERE = Path(__file__).resolve().parent  # fmu_src/models/clearance/
FACTS = ("closure = closure0 + c_centrifugal Omega<sup>2</sup> + d_thermal, tau_thermal dd_thermal/dt = "
         "c_thermal Omega<sup>2</sup> - d_thermal, with Omega held over each step and the lag integrated exactly.")


class ClearanceError(ValueError):
    """A clearance FMU that cannot be built as asked (one line: the parameter and what is accepted)."""


def build_clearance_fmu(dest: str | Path = "fmus/native", platforms: tuple[str, ...] | None = None,
                        fmi: str = "2.0", **defaults) -> Path:
    """Build ``dest/TipClearance.fmu`` (FMI ``fmi``: the wear scenario uses "2.0"; "3.0" from the same wrappers);
    keyword arguments override the start values of the parameters and of the Omega input (a system whose spool
    starts turning: the closure at t0, and its thermal part warm there, are then the engine's before a master's
    first exchange, in every master alike)."""
    from rotorub_model import __version__ as lib_version

    settable = {v.name: v for v in cv.variables() if v.settable}
    for k, x in defaults.items():
        v = settable.get(k)
        if v is None:
            raise ClearanceError(f"clearance FMU: unknown parameter '{k}'; known: {', '.join(settable)}")
        if not (math.isfinite(float(x)) and v.min <= float(x) <= v.max):
            raise ClearanceError(f"clearance FMU: {k} = {x!r} out of range; accepted range [{v.min!r}, {v.max!r}]")
    out = build_native(NativeBuild(model=cv.MODEL, variables=cv.variables(defaults), model_dir=HERE, fmi=fmi,
                                   facts=FACTS), dest, platforms, f"rotorub {lib_version}", lib_version)
    return Path(out["fmu"])
