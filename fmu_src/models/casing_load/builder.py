"""Build CasingLoad.fmu (model.c behind the FMI layer's wrapper) from its variable list (variables.py): the engine
side's casing distortion for the manoeuvre scenario (fmu_src/systems/manoeuvre_scenario.py)."""

from __future__ import annotations

import math
from pathlib import Path

from ...fmi.package import NativeBuild, build_native
from . import variables as lv

HERE = Path(__file__).resolve().parent  # fmu_src/models/casing_load/
FACTS = ("n(t) = 1 + (load_factor_peak - 1) s(t), s a trapezoid in time with half-cosine edges; casing_lobe2.amplitude "
         "= ovalization_per_g (n - 1) at the angle ovalization_phase; casing_offset = offset_per_g (n - 1) (cos, sin) "
         "offset_angle; the closed form at every communication point.")


class CasingLoadError(ValueError):
    """A casing-load FMU that cannot be built as asked (one line: the parameter and what is accepted)."""


def build_casing_load_fmu(dest: str | Path = "fmus/native", platforms: tuple[str, ...] | None = None,
                          fmi: str = "2.0", **defaults) -> Path:
    """Build ``dest/CasingLoad.fmu`` (FMI ``fmi``: "2.0", which the systems use, or "3.0" from the same model.c);
    keyword arguments override the parameters' start values (checked against their declared ranges)."""
    from rotorub_model import __version__ as lib_version

    settable = {v.name: v for v in lv.variables() if v.settable}
    for k, x in defaults.items():
        v = settable.get(k)
        if v is None:
            raise CasingLoadError(f"casing load FMU: unknown parameter '{k}'; known: {', '.join(settable)}")
        try:
            ok = math.isfinite(float(x)) and v.min <= float(x) <= v.max
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise CasingLoadError(f"casing load FMU: {k} = {x!r} out of range; accepted range [{v.min!r}, {v.max!r}]")
    out = build_native(NativeBuild(model=lv.MODEL, variables=lv.variables(defaults), model_dir=HERE, fmi=fmi,
                                   facts=FACTS), dest, platforms, f"rotorub {lib_version}", lib_version)
    return Path(out["fmu"])
