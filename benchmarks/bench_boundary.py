"""Stability boundary: curves by continuation at 10x the grid's resolution against the quick grid map.

    python benchmarks/bench_boundary.py [--workers 2]

Both on the same process pool (2 workers by default: the CI machine): the quick grid maps of the
main job (40 speeds x 36 clearances, 2D and 3D, each cell a warm-started Newton solve plus the
eigenvalues of the 76 x 76 first-order system) and the boundary curves over the same range (2D and 3D
in parallel, points at most a tenth of a grid cell apart, each located to 1e-6 of a cell). Printed:
the wall time of each, their ratio (target: curves < grid), the points and the evaluations of the
curves, and how many grid cells contradict them.
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

from rotorub_model.analyses.continuation import agreement, boundary_curves_only
from rotorub_model.analyses.maps import run_stability_map
from rotorub_model.app.studies import default_grid
from rotorub_model.structure.model import build_model


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2)
    ns = ap.parse_args(argv)
    m = build_model()
    speeds, g0s = default_grid(m, quick=True)
    with ProcessPoolExecutor(ns.workers) as pool:
        list(pool.map(abs, range(ns.workers)))  # workers up before the clock starts
        t0 = time.perf_counter()
        maps = {f: run_stability_map(m, f, speeds, g0s, executor=pool, progress=False) for f in ("2D", "3D")}
        t_grid = time.perf_counter() - t0
        t0 = time.perf_counter()
        futs = {f: pool.submit(boundary_curves_only, m, f, speeds, g0s, 0.1) for f in ("2D", "3D")}
        curves = {f: fu.result() for f, fu in futs.items()}
        t_curves = time.perf_counter() - t0
    print(f"grid: {len(speeds)} x {len(g0s)} cells, 2D + 3D, {ns.workers} workers: {t_grid:6.2f} s")
    print(f"curves at 1/10 cell, 2D + 3D in parallel           : {t_curves:6.2f} s")
    print(f"ratio curves / grid: {t_curves / t_grid:.2f} (target < 1)")
    for f, (cv, info) in curves.items():
        a = agreement(cv, maps[f], tuple(info["cell"]))
        by = info["points_by_corrector"]
        print(f"  {f}: {len(cv)} curves, {sum(len(c) for c in cv)} points ({by['fast']} by the fast corrector, "
              f"{by['bracket']} by the bracketing one), {info['evaluations']} equilibria; "
              f"grid cells contradicting them: {a['contradicting_cells']} of {a['grid_cells']} "
              f"({a['contradicting_beyond_one_cell']} beyond one cell)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
