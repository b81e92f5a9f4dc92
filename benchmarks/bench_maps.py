"""Static + stability maps: cells per second, serial against the process pool on all cores.

    python benchmarks/bench_maps.py [--n 40] [--formulations 2D 3D]

An n x n (Omega, g0) grid over the full study's range (app.studies.default_grid), one
formulation at a time, once in this process (executor "serial") and once on a process pool
over every core (the default of run_stability_map); each cell is a warm-started Newton
solve plus an eigenvalue problem of the 76 x 76 first-order system. Printed: cells/s of
each, the pool's speed-up over serial, and the split of a serial cell between the static
solve and the eigen-analysis.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from rotorub_model.analyses.maps import run_stability_map
from rotorub_model.analyses.stability import stability_of
from rotorub_model.analyses.static import solve_static
from rotorub_model.app.studies import default_grid
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model


def split(m, formulation: str, speeds: np.ndarray, g0s: np.ndarray) -> tuple[float, float]:
    """Mean seconds per cell of the static solve and of the eigen-analysis (one speed row)."""
    omega = speeds[len(speeds) // 2] * m.params.normalisation.omega_ref
    base = make_contact(m, formulation)
    t_static = t_eig = 0.0
    q = None
    for g in g0s[::-1]:
        c = base.with_clearance(float(g))
        t0 = time.perf_counter()
        st = solve_static(m, c, omega, q0=q)
        t1 = time.perf_counter()
        stability_of(m, c, omega, st.q)
        t2 = time.perf_counter()
        q = st.q if st.converged else None
        t_static += t1 - t0
        t_eig += t2 - t1
    return t_static / len(g0s), t_eig / len(g0s)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40)
    ap.add_argument("--formulations", nargs="+", default=["2D", "3D"])
    ns = ap.parse_args(argv)
    m = build_model()
    speeds, g0s = default_grid(m, quick=False)
    speeds = np.linspace(speeds[0], speeds[-1], ns.n)
    g0s = np.linspace(g0s[0], g0s[-1], ns.n)
    cells = ns.n * ns.n
    print(f"{ns.n} x {ns.n} = {cells} cells per map, {os.cpu_count()} cores")
    for f in ns.formulations:
        t = time.perf_counter()
        run_stability_map(m, f, speeds, g0s, executor="serial", progress=False)
        serial = time.perf_counter() - t
        t = time.perf_counter()
        r = run_stability_map(m, f, speeds, g0s, progress=False)
        pool = time.perf_counter() - t
        ts, te = split(m, f, speeds, g0s)
        print(f"{f}: serial {serial:6.1f} s ({cells / serial:6.0f} cells/s), pool {pool:6.1f} s "
              f"({cells / pool:6.0f} cells/s), speed-up {serial / pool:.2f} x on {os.cpu_count()} cores; "
              f"a cell: static {ts * 1e3:.2f} ms + eigen {te * 1e3:.2f} ms; "
              f"{r.summary()['contact_points']} contact cells")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
