"""``run_uq``: a study from its design to its result, every evaluation through the project's executor.

The evaluations are cut into tasks of ``chunk`` samples (by default about two seconds of work each, and at
least eight tasks, so that a pool balances and an interruption loses little) and run by
:func:`rotorub_model.analyses.sweeps.run_tasks`: a process pool by default, ``"serial"``, or a Dask
executor (``Client(address).get_executor()``: a LocalCluster, or a scheduler and its workers anywhere). With
``out``, each task's result is written to ``out/evaluations/rows/<hash>.npz`` when it completes, the hash
that of its inputs (the spec and the samples, which a seed fixes): run again with the same ``out``, a study
skips what is there and computes the rest, to the same numbers (tests/library/test_uncertainty_store.py).
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np

from ..analyses.sweeps import run_tasks, task_key
from ..structure.model import build_model
from .evaluate import evaluate_chunk
from .methods import (
    clearance_curve,
    correlation,
    design,
    estimate_probability,
    estimate_value,
    morris_indices,
    sobol_indices,
    to_physical,
)
from .results import UQResult
from .study import Study, load_study, spec_json

# seconds per evaluation guessed by analysis level, to size the tasks (measured at 38 dofs; the cost table
# reports the real ones)
COST_GUESS = {"analytic": 1e-6, "detection": 1e-4, "static": 3e-3, "transient": 1.2e-2, "wear": 1.5e-2}
TASK_SECONDS = 2.0
MIN_TASKS = 8


def operating_speeds(study: Study) -> list[float]:
    """The normalised speeds of the study: one point, or the run-up grid (critical speeds inserted with
    their dense cluster, analyses/detection.speed_grid)."""
    if study.model != "rotorub":
        return []
    if study.speeds is None:
        if study.speed == "first_critical":
            from ..app.studies import first_critical

            return [first_critical(build_model(study.params))[0]]
        return [float(study.speed)]
    from ..analyses.detection import speed_grid
    from ..analyses.linear import run_response

    lo, hi = study.speeds
    resp = run_response(build_model(study.params), lo, hi, n_speeds=2000)
    return [float(s) for s in speed_grid(resp.critical_speeds, lo, hi, n_speeds=200)]


def chunk_size(study: Study, n_points: int) -> int:
    if study.chunk:
        return study.chunk
    per = sum(COST_GUESS[lv] * (study.t_end if lv in ("transient", "wear") else 1.0) for lv in study.levels_needed)
    if study.mistuning is not None and "detection" in study.levels_needed:
        per += 2e-4  # the mistuned disk's own linear solves
    if any(i.target.kind == "list" or (i.target.kind == "param" and i.target.section not in ("contact", "imbalance"))
           for i in study.inputs):
        per += 0.1  # a model rebuilt for every sample
    c = int(max(1, min(5000, TASK_SECONDS / per)))
    return max(1, min(c, math.ceil(n_points / MIN_TASKS)))


class Evaluator:
    """Evaluations of one study through the executor, with the store and the cost bookkeeping."""

    def __init__(self, study: Study, spec: str, executor=None, out: str | Path | None = None,
                 progress: bool = True):
        self.study, self.spec, self.executor, self.progress = study, spec, executor, progress
        self.store = Path(out) / "evaluations" if out is not None else None
        self.tasks = self.reused = self.points = 0
        self.wall = 0.0
        self.seconds: dict[str, list[np.ndarray]] = {}
        self.chunk = 0
        self.load = [_load()]

    def __call__(self, X: np.ndarray, D: np.ndarray | None, desc: str = "uq", progress: bool | None = None,
                 chunk: int | None = None) -> dict[str, np.ndarray]:
        n = len(X)
        c = chunk or chunk_size(self.study, n)
        self.chunk = c
        payloads = [{"spec": self.spec, "x": X[a:a + c].tolist(),
                     "mistuning": None if D is None else D[a:a + c].tolist()} for a in range(0, n, c)]
        if self.store is not None:
            rows = self.store / "rows"
            self.reused += sum((rows / f"{task_key(p)}.npz").exists() for p in payloads)
        t = time.perf_counter()
        res = run_tasks(evaluate_chunk, payloads, executor=self.executor, out=self.store,
                        progress=self.progress if progress is None else progress,
                        desc=f"{desc} ({c} evaluations a task)")
        self.wall += time.perf_counter() - t
        self.tasks += len(payloads)
        self.points += n
        out = {k: np.concatenate([r[k] for r in res]) for k in res[0]}
        for k in [k for k in out if k.startswith("seconds_")]:
            self.seconds.setdefault(k[8:], []).append(out.pop(k))
        return out

    def cost(self) -> dict:
        """The per-evaluation cost table (seconds inside the workers by analysis, tasks, wall, load)."""
        levels = {}
        for lv, parts in self.seconds.items():
            s = np.concatenate(parts)
            levels[lv] = {"evaluations": int(s.size), "seconds_total": float(s.sum()),
                          "ms_per_evaluation_mean": float(s.mean() * 1e3) if s.size else None,
                          "ms_per_evaluation_median": float(np.median(s) * 1e3) if s.size else None,
                          "ms_per_evaluation_max": float(s.max() * 1e3) if s.size else None}
        busy = sum(v["seconds_total"] for v in levels.values())
        self.load.append(_load())
        return {"levels": levels, "evaluations": self.points, "tasks": self.tasks, "evaluations_per_task": self.chunk,
                "tasks_reused_from_store": self.reused, "wall_s": self.wall,
                "evaluations_per_s": self.points / self.wall if self.wall > 0 else None,
                "seconds_in_evaluations": busy,
                "executor": _executor_name(self.executor),
                "machine": {"cores": os.cpu_count(), "load_average_1min_start_end": [self.load[0], self.load[-1]]},
                "note": "seconds per evaluation measured inside the workers (reused tasks: their first run's); "
                        "wall_s includes the executor's overhead and, on a resumed run, only the tasks computed"}


def _load() -> float | None:
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def _executor_name(ex) -> str:
    if ex is None:
        return "process pool (all cores)"
    if ex == "serial":
        return "serial"
    from concurrent.futures import ProcessPoolExecutor

    if isinstance(ex, ProcessPoolExecutor):
        return f"process pool ({ex._max_workers} workers)"
    return type(ex).__name__


def run_uq(study: Study | str | Path, params=None, executor=None, out: str | Path | None = None,
           progress: bool = True, quick: bool = False) -> UQResult:
    """Run a study (a :class:`Study`, or a study file with ``params`` overriding its parameter file)."""
    if not isinstance(study, Study):
        study = load_study(study, params=params)
    if quick:
        study = study.quick()
    t0 = time.perf_counter()
    speeds = operating_speeds(study)
    ev = Evaluator(study, spec_json(study, speeds), executor, out, progress)
    est: dict = {}
    names = [q.name for q in study.quantities]
    X = D = None
    values: dict[str, np.ndarray] = {}
    rep = None
    if study.method in ("form", "subset"):
        from ..analyses.sweeps import default_executor
        from .small_probability import run_small_probability

        qname = study.events[0].limit_state[0]
        # FORM and subset sampling ask for many small batches: one pool for all of them (run_tasks would
        # start and stop a pool, and its workers would build their model, for every batch)
        own = executor is None
        if own:
            ev.executor = default_executor()
        bar = None
        if progress:  # the algorithm decides how many evaluations it needs: a bar that counts them
            from tqdm import tqdm

            bar = tqdm(desc=f"uq {study.method}", unit="evaluation")

        def limit_state(U):
            y = ev(*to_physical(study, U), desc=study.method, progress=False)[qname]
            if bar is not None:
                bar.update(len(U))
            return y

        try:
            est["small_probability"] = run_small_probability(study, limit_state)
        finally:
            if own:
                ev.executor.shutdown()
            if bar is not None:
                bar.close()
    else:
        des = design(study)
        X, D = to_physical(study, des["U"])
        values = ev(X, D, desc=f"uq {study.method}")
        rep = des.get("replicate")
        if study.method == "montecarlo":
            est["probabilities"] = {e.text: estimate_probability(e.of(values[e.quantity]), rep, study)
                                    for e in study.events}
            est["values"] = {q: estimate_value(values[q], rep, study) for q in names
                             if _kind(q) == "value"}
            if "margin" in values and study.model == "rotorub":
                g0 = next((i.distribution.mean for i in study.inputs if i.target.name == "contact.g0"),
                          study.params.contact.g0)
                est["clearance_curve"] = clearance_curve(values["margin"], rep, study, g0)
            if "amp_linear" in values:
                est["mistuning"] = {k: correlation(values["amp_linear"], values[k], study.confidence)
                                    for k in ("amp_contact", "amp_force", "amp_contact_transient") if k in values}
        elif study.method == "sobol":
            est["sobol"] = {q: sobol_indices(study, _numeric(values[q])) for q in names}
        elif study.method == "morris":
            est["morris"] = {q: morris_indices(study, des["U_design"], _numeric(values[q])) for q in names}
    return UQResult(study=study, speeds=speeds, X=X, D=D, replicate=rep, values=values, estimates=est,
                    cost=ev.cost(), wall_s=time.perf_counter() - t0)


def _kind(q: str) -> str:
    from .quantities import QUANTITIES

    return QUANTITIES[q].kind


def _numeric(y: np.ndarray) -> np.ndarray:
    return np.asarray(y, dtype=float)
