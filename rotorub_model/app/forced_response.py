"""The forced rub response of a distorted casing over speed (CLI ``rotorub forced-response``) and its quick version
for the main job (:func:`run_forced_quick`: the result and a markdown section; the lead wires it in)."""

from __future__ import annotations

import math
from pathlib import Path

from ..analyses.harmonic.interaction import InteractionMap, run_interaction_map
from ..analyses.harmonic.surface import CasingForcing
from ..errors import ParameterError
from ..structure.model import Model


def forcing_from_args(g0: float, lobe: int | None, amplitude: float | None, phase_deg: float,
                      offset: tuple[float, float] | None) -> CasingForcing:
    """The casing surface from the command's arguments (one lobe count, the rigid offset, or both); neither: the
    oval casing the issue studies, 2 lobes of 0.3 g0 widest at 0."""
    if lobe is not None:
        if amplitude is None:
            raise ParameterError("--amplitude: needed with --lobe (the lobe's amplitude a_n [m])")
        f = CasingForcing(lobes={int(lobe): (float(amplitude), math.radians(phase_deg))},
                          offset=offset or (0.0, 0.0))
    elif amplitude is not None:
        # without it the amplitude was dropped and the default oval (0.3 g0) run instead, the verdict naming it
        raise ParameterError(f"--lobe: needed with --amplitude {amplitude:g} (the lobe count n >= 2 it belongs to)")
    elif offset is not None and any(offset):
        f = CasingForcing(offset=offset)
    else:
        f = CasingForcing.lobe(2, 0.3 * g0)
    f.check(g0)
    return f


def run_forced_response(model: Model, out: str | Path, speeds: tuple[float, float], formulation: str = "2D",
                        g0: float | None = None, forcing: CasingForcing | None = None, harmonics: int = 10,
                        transients: int = 0, t_end: float = 60.0, wear: bool = True, executor=None,
                        refine: int | None = None) -> dict:
    """The interaction map written to ``out``. Transients of ``t_end`` seconds (60 s settles multipliers up to
    ~0.99 to the classifier's 2e-3), at the step T/64 divided by ``refine`` (default 2 in 3D: at T/64 the fast
    blade mode's error alone is 3 % of the tip amplitude on the oval reference; docs/THEORY.md section 8)."""
    refine = (2 if formulation == "3D" else 1) if refine is None else int(refine)
    r = run_interaction_map(model, formulation, speeds, g0=g0, forcing=forcing, harmonics=harmonics,
                            n_transients=transients, t_end=t_end, wear=wear, executor=executor, progress=True,
                            refine=refine)
    s = r.save(out)
    return {"verdict": s["verdict"], "specials": s["specials"], "timings_s": s["timings_s"],
            "written": [str(Path(out) / n) for n in ("interaction_map.png", "interaction_map_harmonics.png",
                                                     "interaction_map.json")]}


def run_forced_quick(model: Model, out: str | Path) -> tuple[InteractionMap, str]:
    """The main job's quick forced response: 2D, clearance 0.5 g0 of the file, an oval casing (2 lobes of 0.3 of that
    clearance), speeds 2.5-4.5, H = 10, five 60 s transients through the process pool. Returns the result and its
    report section (the HB-transient agreement with each speed's verdict)."""
    g0 = 0.5 * model.params.contact.g0
    lo, hi = 2.5, min(4.5, model.params.normalisation.speed_max)
    r = run_interaction_map(model, "2D", (lo, hi), g0=g0, forcing=CasingForcing.lobe(2, 0.3 * g0),
                            harmonics=10, n_transients=5, t_end=60.0, wear=True, progress=False)
    s = r.save(out)
    rows = "\n".join(f"| {a['speed']:.3g} | {a['transient']} | "
                     + (f"{100 * a['relative_difference']:.2g} %" if "relative_difference" in a else "-")
                     + f" | {a['verdict']}: {a['why']} |" for a in r.agreement())
    md = (f"## Forced response of an oval casing (harmonic balance)\n\n{s['verdict']}.\n\n"
          "| speed | transient | HB vs transient (tip, disk) | verdict |\n|---|---|---|---|\n" + rows +
          f"\n\n![interaction map]({Path(out).name}/interaction_map.png)\n")
    return r, md
