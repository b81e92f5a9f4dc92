"""The main job: reproduce the paper's analyses on a configuration and summarise them.

Each analysis writes its PNG/JSON into its own sub-folder of ``out``; the summary
gathers the paper's facts (MODEL-NOTES section 4) with our values and whether
they hold.
"""

from __future__ import annotations

from pathlib import Path

from .model import Model
from .results import write_json


def fact1(resp: dict) -> dict:
    c = resp["critical_speeds"]
    a = resp["peak_amplitudes_m"]
    holds = len(c) == 2 and abs(c[0] - 3.5) <= 0.2 and abs(c[1] - 8.0) <= 0.5 and a[0] >= 5 * a[1]
    return {
        "id": 1,
        "statement": "two critical speeds in 0 < Omega <= 10, near 3.5 and 8, first peak > 5x the second",
        "paper": {"critical_speeds": [3.5, 8.0], "peak_ratio_min": 5.0},
        "ours": {"critical_speeds": c, "peak_ratio": a[0] / a[1] if len(a) > 1 else None},
        "holds": bool(holds),
    }


def run_reproduce(model: Model, out: str | Path, quick: bool = False) -> dict:
    from .linear import run_campbell, run_modes, run_response

    out = Path(out)
    resp = run_response(model, n_speeds=600 if quick else 2000).save(out / "response")
    run_modes(model, resp["critical_speeds"][0]).save(out / "modes")
    run_campbell(model, n_speeds=25 if quick else 80).save(out / "campbell")
    from .detection import paper_facts as detection_facts
    from .detection import run_detection

    det = run_detection(model, n_speeds=200 if quick else 400).save(out / "detection")
    summary = {
        "n_dofs": model.n_dofs,
        "omega_ref_rad_s": model.params.normalisation.omega_ref,
        "response": resp,
        "detection": det,
        "paper_facts": [fact1(resp), *detection_facts(det)],
    }
    write_json(out / "summary.json", summary)
    return summary
