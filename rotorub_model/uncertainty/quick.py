"""``run_uq_quick``: the main job's uncertainty section on any configuration, in seconds.

Two studies on the model's own parameters, at its first critical speed (where its rub studies centre):

1. the rub probability under build tolerances: the clearance normal about the parameter file's g0 (sd 10 % of
   it, at least 0.05 mm), the imbalance lognormal about the file's m e (coefficient of variation 30 %), its
   angle uniform, an engine closure uniform on [0, 20 %] of g0; randomised QMC, 8 x 256 points, detection
   level; the P(rub) curve against the build clearance;
2. mistuning: 64 disks with a 2 % frequency scatter (truncnormal at 3 sd, independent blades), at the file's
   g0 and m e: linear against contact (static solution) amplification factors, their correlation.

Returned: the two results and a markdown section (the lead adds it to the report).
"""

from __future__ import annotations

from pathlib import Path

from ..structure.model import Model
from .results import UQResult
from .runner import run_uq
from .study import study_from_dict


def quick_studies(model: Model) -> dict:
    p = model.params
    g0, me = p.contact.g0, p.imbalance.me
    sd_g0 = max(0.1 * abs(g0), 0.05e-3)
    tol = {
        "study": {"name": "build tolerances (quick)", "method": "montecarlo", "sampler": "qmc", "n": 256,
                  "replicates": 8, "quantities": ["margin", "rub"], "events": ["rub"], "seed": 28},
        "operating": {"speed": "first_critical", "formulation": "3D"},
        "inputs": {
            "clearance": {"parameter": "contact.g0", "distribution": "normal", "mean": g0, "sd": sd_g0},
            "imbalance": {"parameter": "imbalance.me", "distribution": "lognormal", "mean": me, "sd": 0.3 * me},
            "imbalance_angle": {"parameter": "imbalance.angle_deg", "distribution": "uniform", "low": 0.0,
                                "high": 360.0},
            "closure": {"parameter": "engine.closure", "distribution": "uniform", "low": 0.0,
                        "high": max(0.2 * abs(g0), 1e-6)},
        },
    }
    mist = {
        "study": {"name": "mistuning (quick)", "method": "montecarlo", "sampler": "qmc", "n": 16, "replicates": 4,
                  "quantities": ["amp_linear", "amp_contact", "amp_force"], "events": [], "quantiles": [0.5],
                  "seed": 28},
        "operating": {"speed": "first_critical", "formulation": "3D"},
        "mistuning": {"kind": "frequency", "sd": 0.02, "distribution": "truncnormal", "truncate": 3.0},
    }
    return {"tolerances": study_from_dict(tol, params=p), "mistuning": study_from_dict(mist, params=p)}


def run_uq_quick(model: Model, out: str | Path, executor=None, progress: bool = False) -> tuple[dict, str]:
    """Both quick studies on ``model``'s parameters, saved in out/tolerances and out/mistuning; returns
    ({name: UQResult}, the markdown section). A configuration without imbalance, or without a critical speed
    within its validity, gets the rub studies' one-line :class:`ParameterError`."""
    from ..errors import ParameterError

    if model.params.imbalance.me == 0.0:
        raise ParameterError("imbalance.me: 0 kg m; the rub-probability study scatters the imbalance about the "
                             "parameter file's (accepted range (0, inf) kg m)")
    out = Path(out)
    res: dict[str, UQResult] = {}
    md = ["## Will it rub? Uncertainty (quick)", "",
          "Two small studies on this configuration at its first critical speed (rotorub_model/uncertainty/"
          "quick.py): build tolerances (clearance, imbalance, closure) and a 2 % blade frequency scatter. A full "
          "study: `rotorub uq STUDY.toml` (README, \"Will it rub?\").", ""]
    for name, st in quick_studies(model).items():
        r = run_uq(st, executor=executor, out=out / name, progress=progress)
        r.save(out / name)
        res[name] = r
        md.append(r.markdown(title=st.name, level=3))
    return res, "\n".join(md)
