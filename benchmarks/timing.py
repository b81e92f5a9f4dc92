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
