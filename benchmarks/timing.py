"""The one timing rule of the benchmark scripts: the best of a few runs (the least disturbed by the
rest of the machine), in seconds."""

from __future__ import annotations

import time
from collections.abc import Callable


def best_of(fn: Callable[[], object], repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def best_of_interleaved(fns: dict[str, Callable[[], object]], repeat: int = 5) -> dict[str, float]:
    """The best of ``repeat`` runs of each function, the functions taken in turn within each round: a ratio of two
    of them then compares runs made under the same conditions (a machine that warms up, or gets busier, over the
    measurement moves both alike)."""
    best = {k: float("inf") for k in fns}
    for _ in range(repeat):
        for k, fn in fns.items():
            t = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t)
    return best


def pin_to_one_cpu() -> str:
    """Run this process, and the processes it starts, on one CPU: a ratio then compares two codes on the same core.
    On the project's 2-vCPU VM the host program and the bare loop landed on either vCPU: unpinned, three runs of
    bench_native.py printed 1.12, 1.14 and 1.22; pinned, four printed 1.12-1.13. Returns what was done, for the
    printout (nothing where the OS has no affinity call)."""
    import os

    if not hasattr(os, "sched_setaffinity"):
        return "not pinned (no CPU affinity on this OS)"
    cpus = sorted(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpus[-1]})
    return f"pinned to CPU {cpus[-1]} of {len(cpus)}"
