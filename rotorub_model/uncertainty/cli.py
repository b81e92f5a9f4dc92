"""``rotorub uq STUDY.toml``: the command's work (app/cli.py registers it and parses its arguments).

The study file is read and checked first (one error line, exit code 2, nothing written); then the executor
starts (a Dask cluster only now: a bad study never waits for one), the study runs with its progress bar,
its figures and JSON go to --out, and the command prints a short summary ending with the verdict.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from .runner import run_uq
from .study import load_study


def run_uq_command(ns: argparse.Namespace, make_executor: Callable[[], object]) -> dict:
    study = load_study(ns.study, params=ns.params)
    if ns.quick:
        study = study.quick()
    r = run_uq(study, executor=make_executor(), out=ns.out, progress=True)
    s = r.save(ns.out)
    c = s["cost"]
    return {"study": study.name, "method": study.method, "points": c["evaluations"],
            "analyses_ms_per_evaluation": {k: v["ms_per_evaluation_mean"] for k, v in c["levels"].items()},
            "wall_s": round(c["wall_s"], 3), "tasks_reused": c["tasks_reused_from_store"],
            "written": [str(Path(ns.out) / "uq_summary.json")] + [str(Path(ns.out) / f"uq_{k}.png") for k in r.figures],
            "verdict": s["verdict"]}
