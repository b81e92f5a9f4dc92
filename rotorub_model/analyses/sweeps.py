"""Parameter sweeps through an executor: a process pool by default, a Dask cluster if given.

Work is cut into independent tasks (one task = one speed row of a map), each a
pure top-level function of plain data (the parameter dict, formulation, speed,
clearances), so it pickles to any worker. Results are written to ``out/rows/`` as
each task completes, and a re-run with the same ``out`` skips rows already there:
an interrupted sweep resumes.

Every task runs with its BLAS on one thread (threadpoolctl): the parallelism is the executor's, one
task per core. Left alone, each of the pool's workers starts as many BLAS threads as there are cores,
and above about 50 dofs their eigen-analyses fight for the cores: an 18-blade map took 74-442 s
instead of 15-24 s, a 68-dof one 1088 s instead of 27 s.

Use a Dask cluster::

    from dask.distributed import Client
    client = Client("tcp://scheduler:8786")
    run_map(model, "3D", speeds, g0s, executor=client.get_executor())
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable, Iterable
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np


def default_executor(max_workers: int | None = None) -> Executor:
    return ProcessPoolExecutor(max_workers=max_workers or os.cpu_count() or 1)


def single_threaded(fn: Callable[..., dict[str, np.ndarray]], payload: dict[str, Any]) -> dict[str, np.ndarray]:
    """fn(**payload) with every BLAS/OpenMP pool of this process limited to one thread (top-level: it
    pickles to any worker, process pool or Dask)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        return fn(**payload)


def task_key(payload: dict[str, Any]) -> str:
    """Stable hash of a task's inputs (identifies a finished row on resume)."""
    blob = json.dumps(payload, sort_keys=True, default=lambda x: np.asarray(x).tolist())
    return hashlib.sha1(blob.encode()).hexdigest()[:16]


def run_tasks(
    fn: Callable[..., dict[str, np.ndarray]],
    payloads: list[dict[str, Any]],
    executor: Executor | None = None,
    out: str | Path | None = None,
    progress: bool = True,
    desc: str = "sweep",
) -> list[dict[str, np.ndarray]]:
    """Run fn(**payload) for every payload; results in payload order.

    With ``out``, each result is saved to out/rows/<key>.npz when it completes and
    reused on a later call (resume). ``executor=None`` uses a process pool over all
    cores; pass ``"serial"`` to run in this process (tests, debugging).
    """
    rows_dir = Path(out) / "rows" if out is not None else None
    results: list[dict[str, np.ndarray] | None] = [None] * len(payloads)
    todo = []
    for i, pl in enumerate(payloads):
        if rows_dir is not None:
            f = rows_dir / f"{task_key(pl)}.npz"
            if f.exists():
                with np.load(f) as z:
                    results[i] = {k: z[k] for k in z.files}
                continue
        todo.append(i)
    bar = _bar(len(payloads), len(payloads) - len(todo), desc, progress)

    def finish(i: int, res: dict[str, np.ndarray]) -> None:
        results[i] = res
        if rows_dir is not None:
            rows_dir.mkdir(parents=True, exist_ok=True)
            tmp = rows_dir / f"{task_key(payloads[i])}.tmp.npz"
            np.savez(tmp, **res)
            os.replace(tmp, rows_dir / f"{task_key(payloads[i])}.npz")
        if bar is not None:
            bar.update(1)

    if executor == "serial" or (executor is None and len(todo) <= 1):
        for i in todo:
            finish(i, fn(**payloads[i]))
    else:
        own = executor is None
        ex = default_executor() if own else executor
        try:
            futs = {ex.submit(single_threaded, fn, payloads[i]): i for i in todo}
            for fut in as_completed(futs):
                finish(futs[fut], fut.result())
        finally:
            if own:
                ex.shutdown()
    if bar is not None:
        bar.close()
    return results  # type: ignore[return-value]


def _bar(total: int, done: int, desc: str, progress: bool):
    if not progress:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=done, desc=desc, unit="task")


def chunks(seq: Iterable, n: int) -> list[list]:
    seq = list(seq)
    return [seq[i : i + n] for i in range(0, len(seq), n)]
