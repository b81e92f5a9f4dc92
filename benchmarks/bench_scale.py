"""How the analyses' cost grows with the model: 38 to 120 dofs, as ratios to the reference in one run.

    .venv/bin/python benchmarks/bench_scale.py [--quick]

Configurations (the reference with one section changed; dofs = 18 + blades x functions per blade):
the reference (10 blades x 2), 18 and 24 blades, 5 polynomials kept per blade (68 dofs), 5 polynomials
reduced to the default 2 modes (38 dofs: what `blades.n_ritz = 5` costs now), and 34 blades x 3 modes
(120 dofs). For each, measured here:

* a map cell: static solution + stability indicators, per cell of a 3D map row over the configuration's
  own first critical, in a 2-worker process pool as `rotorub stability` runs it (each task's BLAS on one
  thread), and the same pool without the pinning (what the maps did before: the workers' BLAS threads
  fought for the cores);
* a 1 s 3D transient with rub at the configuration's own first critical;
* a continuation point: a 3D branch in g0 at that speed, time per point;
* a Campbell speed: all modes with their fixed-frame labels, time per speed.

Prints each cost and its ratio to the reference's, and the growth exponent a of cost ~ dofs^a fitted over
the configurations that keep their blade functions. Targets (issue 18, "cost that grows like the
physics"): a map cell (a Newton solve and a dense eigenvalue problem of 2 x dofs) with an exponent of at
most 3, the dense eigen-solver's; a 1 s transient with n_ritz = 5 at most 2x the reference's (the reduced
blade basis keeps the reference's step). A cell does not use the cyclic blocks of the modes: a rub breaks
the symmetry.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from rotorub_model import build_model, reference_parameters  # noqa: E402
from rotorub_model.analyses.continuation.branch import continue_static  # noqa: E402
from rotorub_model.analyses.continuation.equilibria import Equilibria  # noqa: E402
from rotorub_model.analyses.linear import run_campbell, run_response  # noqa: E402
from rotorub_model.analyses.maps import map_row  # noqa: E402
from rotorub_model.analyses.sweeps import single_threaded  # noqa: E402
from rotorub_model.analyses.transient import run_transient  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402
from rotorub_model.structure.params import to_dict  # noqa: E402

CONFIGS = (
    ("reference", {}),
    ("18 blades", {"blades": {"count": 18}}),
    ("24 blades", {"blades": {"count": 24}}),
    ("n_ritz 5, all kept", {"blades": {"n_ritz": 5, "n_modes": 5}}),
    ("n_ritz 5 -> 2 modes", {"blades": {"n_ritz": 5}}),
    ("34 blades x 3 modes", {"blades": {"count": 34, "n_ritz": 5, "n_modes": 3}}),
)
REDUCED = "n_ritz 5 -> 2 modes"  # not in the growth fit: the reduction is the point


def _pool_cells(params_json: str, speeds, g0s, pinned: bool) -> float:
    """Seconds per cell of 3D map rows in a 2-worker pool (pinned: as run_tasks runs them)."""
    payloads = [{"params_json": params_json, "formulation": "3D", "variant": "full", "speed": float(s),
                 "g0s": [float(g) for g in g0s]} for s in speeds]
    with ProcessPoolExecutor(max_workers=2) as ex:
        list(ex.map(_warm, [params_json] * 2))  # model built and kernel loaded in both workers
        t0 = time.perf_counter()
        futs = [ex.submit(single_threaded, map_row, pl) if pinned else ex.submit(map_row, **pl) for pl in payloads]
        for f in futs:
            f.result()
        return (time.perf_counter() - t0) / (len(speeds) * len(g0s))


def _warm(params_json: str) -> int:
    from rotorub_model.analyses.maps import _cached_model

    return _cached_model(params_json).n_dofs


def measure(label: str, change: dict, quick: bool) -> dict:
    import json

    p = reference_parameters().replace(**change) if change else reference_parameters()
    m = build_model(p)
    w_ref = p.normalisation.omega_ref
    r = run_response(m, n_speeds=400)
    crit, amp = float(r.critical_speeds[0]), float(r.peak_amplitudes[0])
    g_hi = 1.2 * amp
    n_sp, n_g = (4, 10) if quick else (8, 16)
    speeds = np.linspace(crit - 0.4, crit + 0.4, n_sp)
    g0s = g_hi * np.linspace(0.0, 1.0, n_g) ** 2
    pj = json.dumps(to_dict(p))
    out = {"label": label, "dofs": m.n_dofs, "critical": crit}
    out["cell_s"] = _pool_cells(pj, speeds, g0s, pinned=True)
    out["cell_unpinned_s"] = _pool_cells(pj, speeds, g0s, pinned=False)
    c = make_contact(m, "3D", g0=0.5 * amp)
    t0 = time.perf_counter()
    tr = run_transient(m, c, crit * w_ref, t_end=1.0, t_ramp=0.5)
    out["transient_1s_s"] = time.perf_counter() - t0
    out["transient_steps"] = int(round(1.0 / tr.dt))
    eq = Equilibria(m, "3D")
    t0 = time.perf_counter()
    b = continue_static(eq, "g0", crit * w_ref, g_hi, 0.0, h_max=0.05 if quick else 0.02)
    out["continuation_point_s"] = (time.perf_counter() - t0) / max(len(b.points), 1)
    n_c = 10 if quick else 40
    t0 = time.perf_counter()
    run_campbell(m, speed_max=10.0, n_speeds=n_c)
    out["campbell_speed_s"] = (time.perf_counter() - t0) / n_c
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller grids and branches (a rough figure)")
    ns = ap.parse_args(argv)
    from threadpoolctl import threadpool_limits

    print(f"{os.cpu_count()} cores; timings in this process with BLAS on one thread, map cells in a 2-worker pool")
    rows = []
    with threadpool_limits(limits=1):
        for label, change in CONFIGS:
            rows.append(measure(label, change, ns.quick))
            print(f"  measured {label} ({rows[-1]['dofs']} dofs)", flush=True)
    ref = rows[0]
    keys = (("cell_s", "map cell"), ("cell_unpinned_s", "cell, BLAS not pinned"), ("transient_1s_s", "1 s transient"),
            ("continuation_point_s", "continuation point"), ("campbell_speed_s", "Campbell speed"))
    head = f"{'configuration':22s} {'dofs':>4s} " + " ".join(f"{name:>24s}" for _, name in keys) + "   steps/s"
    print(head)
    for r in rows:
        cells = " ".join(f"{r[k] * 1e3:9.2f} ms ({r[k] / ref[k]:5.2f}x)  " for k, _ in keys)
        print(f"{r['label']:22s} {r['dofs']:4d} {cells} {r['transient_steps']:7d}")
    fit = [r for r in rows if r["label"] != REDUCED]
    x = np.log([r["dofs"] for r in fit])
    print("growth exponent a (cost ~ dofs^a, configurations keeping their functions):")
    for k, name in keys:
        a = np.polyfit(x, np.log([r[k] for r in fit]), 1)[0]
        print(f"  {name:24s} a = {a:.2f}")
    by = {r["label"]: r for r in rows}
    a_cell = np.polyfit(x, np.log([r["cell_s"] for r in fit]), 1)[0]
    tr5 = by[REDUCED]["transient_1s_s"] / ref["transient_1s_s"]
    print(f"targets: a map cell grows no faster than the dense eigen-problem it solves, a = {a_cell:.2f} (<= 3: "
          f"{'met' if a_cell <= 3 else 'NOT met'}); a 1 s transient with n_ritz = 5 costs {tr5:.2f}x the "
          f"reference's (<= 2: {'met' if tr5 <= 2 else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
