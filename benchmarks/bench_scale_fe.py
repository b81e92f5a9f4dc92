"""A time step's cost with imported blades against the blade count, at a fixed blade size, in one run.

    .venv/bin/python benchmarks/bench_scale_fe.py [--dofs 50] [--counts 8 12 16 24 32] [--quick]

The blade: the reference's beam blade written as an FE model (rotorub_model/fe/beam_blade.py, max(120, 4 x dofs)
elements) and reduced to ``--dofs`` modes (the condensed basis, a cut-off between the dofs-th and the next rest
frequency), its tip twelve stations along the reference chord on the 5 deg cone (``with_chord_ends``): 11 contact
segments a blade, as the example's. The disk: ``count`` such blades on the reference shaft and casing
(n = 10 + count x dofs + 8), 3D contact with an interference of 0.1 mm so that every blade rubs from the first step,
at 3.3 omega_ref.

Measured for each count, in the same run:

* a step by blocks (``CentralDifference(blocks=True)``: hub, blades, casing; rr_cd_blocks), the library's
  choice from BLOCK_MIN_DOFS = 200 dofs on, best of 3 runs of ``--steps`` steps;
* the dense step (``blocks=False``: three n x n products a step) at the counts up to ``--dense-max``;
* the setup: the model's assembly, the contact geometry, the step's matrices (by blocks; dense) and the dense
  eigen-solve of the stability limit (rr_critical_step, O(n^3)) up to ``--eigen-max`` blades.

The stability limit is the blade's highest mode's with the contact closed, not the count's: it is computed once,
at the smallest count (the dense eigen-solve, 418 dofs), and passed to the larger disks (``dt_limit``); the
eigen-solve's own cost, which grows as n^3, is printed beside (the FMUs and an unattended run compute it once at
their start). Targets (issue 26.7): the block step's cost ~ count^a with a <= 1.15 from 8 to 32 blades at 30-100
dofs a blade; at 24 blades x 50 dofs, blocks >= 5 x faster than the dense step. Two cores shared with other work:
the ratios, measured in one run, are what count.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from rotorub_model.analyses.transient import CentralDifference, critical_time_step  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402
from rotorub_model.fe import read_matrix_market, reduce_blade  # noqa: E402
from rotorub_model.fe.beam_blade import with_chord_ends, write_beam_blade  # noqa: E402
from rotorub_model.structure.model import build_model  # noqa: E402
from rotorub_model.structure.params import reference_parameters  # noqa: E402

STATIONS = 12
SPEED = 3.3
G0 = -0.1e-3  # an interference: every blade rubs from the first step


def make_blade(folder: Path, dofs: int) -> Path:
    """The reference beam blade reduced to ``dofs`` modes, its tip STATIONS points along the chord."""
    from scipy.linalg import eigh

    p = reference_parameters()
    w = p.normalisation.speed_max * p.normalisation.omega_ref
    # enough elements that the kept modes are resolved (a mode is the beam's, not the mesh's)
    info = write_beam_blade(p, folder, speeds=(0.0, 0.5 * w, w), n_elements=max(120, 4 * dofs))
    fe = read_matrix_market(info["mass"], info["stiffness"], info["dofs"], info["coordinates"], "SI", info["speeds"],
                            mass_dofs=info["mass_dofs"])
    # the rest frequencies (M has massless slopes: the pencil (M, K), K positive definite)
    mu = eigh(fe.M_free.toarray(), fe.K0.toarray(), eigvals_only=True)[::-1]
    f = 1.0 / np.sqrt(mu[mu > 0]) / (2 * np.pi)
    cutoff = float(np.sqrt(f[dofs - 1] * f[dofs]))
    blade = reduce_blade(fe, [info["tip_node"]], cutoff_hz=cutoff, axis_direction=info["axis_direction"],
                         reference_speeds=False)
    if blade.m != dofs:
        raise SystemExit(f"the reduction kept {blade.m} modes, not {dofs}")
    path = folder / "blade.npz"
    with_chord_ends(blade, p, p.contact.chord, p.contact.theta_deg, STATIONS).save(path)
    return path


def step_cost(model, contact, omega: float, dt: float, limit: float, blocks: bool, steps: int, repeats: int) -> tuple:
    """(seconds per step, best of ``repeats``; the setup: the step's matrices)."""
    cd = CentralDifference(model, contact, dt=dt, t_ramp=0.0, dt_limit=limit, blocks=blocks)
    me = model.params.imbalance.me
    t0 = time.perf_counter()
    cd.advance(1, omega, me)  # builds the step's matrices
    setup = time.perf_counter() - t0
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        done, _ = cd.advance(steps, omega, me)
        dt_run = time.perf_counter() - t0
        if done != steps or cd.diverged:
            raise SystemExit(f"the run stopped after {done} of {steps} steps (diverged: {cd.diverged})")
        best = min(best, dt_run / steps)
    return best, setup


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dofs", type=int, default=50, help="reduced dofs a blade (30-100)")
    ap.add_argument("--counts", type=int, nargs="+", default=[8, 12, 16, 24, 32])
    ap.add_argument("--steps", type=int, default=2000, help="steps a timed run (block step)")
    ap.add_argument("--dense-max", type=int, default=24, help="the dense step up to this many blades")
    ap.add_argument("--eigen-max", type=int, default=16, help="the dense eigen-solve of the limit up to this many")
    ap.add_argument("--quick", action="store_true", help="fewer steps, counts 8 16 24")
    ns = ap.parse_args(argv)
    if ns.quick:
        ns.steps, ns.counts = 500, [8, 16, 24]
    print(f"# bench_scale_fe: {ns.dofs} dofs a blade, counts {ns.counts}; load average "
          f"{os.getloadavg()[0]:.2f} (2 cores)", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        blade = make_blade(Path(tmp), ns.dofs)
        base = reference_parameters().replace(fe_blade={"superelement": str(blade), "stations": STATIONS})
        omega = SPEED * base.normalisation.omega_ref
        rows, limit = [], None
        for count in sorted(ns.counts):
            t0 = time.perf_counter()
            model = build_model(base.replace(blades={"count": count}))
            t_model = time.perf_counter() - t0
            t0 = time.perf_counter()
            contact = make_contact(model, "3D", g0=G0)
            t_contact = time.perf_counter() - t0
            t_eigen = None
            if limit is None or count <= ns.eigen_max:
                t0 = time.perf_counter()
                lim = critical_time_step(model, contact, omega)
                t_eigen = time.perf_counter() - t0
                limit = lim if limit is None else limit
                if abs(lim / limit - 1.0) > 1e-3:
                    print(f"#   note: the limit at {count} blades is {lim:.4g} s, at the first count {limit:.4g} s")
            dt = 0.5 * limit
            blk, blk_setup = step_cost(model, contact, omega, dt, limit, True, ns.steps, 3)
            dense = dense_setup = None
            if count <= ns.dense_max:
                dense, dense_setup = step_cost(model, contact, omega, dt, limit, False, max(ns.steps // 10, 50), 2)
            rows.append((count, model.n_dofs, blk, dense, t_model, t_contact, blk_setup, dense_setup, t_eigen))
            print(f"{count:3d} blades, {model.n_dofs:5d} dofs: block step {blk * 1e6:8.1f} us"
                  + (f", dense {dense * 1e6:9.1f} us ({dense / blk:5.1f} x)" if dense else "")
                  + f"; setup: model {t_model:.2f} s, contact {t_contact:.2f} s, block matrices {blk_setup:.3f} s"
                  + (f", dense matrices {dense_setup:.2f} s" if dense_setup is not None else "")
                  + (f", dense eigen-solve of the limit {t_eigen:.2f} s" if t_eigen is not None else ""), flush=True)
    counts = np.array([r[0] for r in rows], dtype=float)
    blk = np.array([r[2] for r in rows])
    a = float(np.polyfit(np.log(counts), np.log(blk), 1)[0])
    print(f"block step ~ count^{a:.3f} from {int(counts[0])} to {int(counts[-1])} blades (target <= 1.15)")
    dense_rows = [r for r in rows if r[3] is not None]
    if len(dense_rows) > 1:
        ad = float(np.polyfit(np.log([r[0] for r in dense_rows]), np.log([r[3] for r in dense_rows]), 1)[0])
        print(f"dense step ~ count^{ad:.3f} (the n^2 products)")
    at24 = [r for r in rows if r[0] == 24 and r[3] is not None]
    if at24:
        print(f"24 blades x {ns.dofs} dofs: blocks {at24[0][3] / at24[0][2]:.1f} x faster than the dense step "
              "(target >= 5)")
    eig = [(r[1], r[8]) for r in rows if r[8] is not None]
    if len(eig) > 1:
        ae = float(np.polyfit(np.log([e[0] for e in eig]), np.log([e[1] for e in eig]), 1)[0])
        print(f"dense eigen-solve of the step limit ~ dofs^{ae:.2f} (computed once, at the start; passed on here)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
