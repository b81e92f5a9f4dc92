"""Cost per step of the 38-dof 3D transient against a bare compiled linear
central-difference loop (same sizes, same machine, same run).

Run: python benchmarks/bench_transient.py
"""

from __future__ import annotations

import time

import numpy as np

from rotorub_model.analyses.transient import CentralDifference, _linear_cd
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model


def best_of(fn, repeat=5):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main(n_steps: int = 5_000) -> None:
    m = build_model()
    # a point in light permanent contact that stays bounded for the whole run
    omega = 3.0 * m.params.normalisation.omega_ref
    c = make_contact(m, "3D", g0=0.0)
    cd = CentralDifference(m, c, omega_max_for_dt=omega)
    cd.advance(10, omega, m.params.imbalance.me)  # compile
    Ainv, K2, Cm1, _ = cd._matrices(omega, 0.0)

    done = []

    def full():
        cd.t, cd.steps, cd.diverged = 0.0, 0, False
        cd.q[:] = 0.0
        cd.q_prev[:] = 0.0
        done.append(cd.advance(n_steps, omega, m.params.imbalance.me)[0])

    q, qp = np.zeros(m.n_dofs), np.zeros(m.n_dofs)
    f = m.force(omega)
    _linear_cd(qp, q, 10, Ainv, K2, Cm1, f)

    def bare():
        _linear_cd(qp, q, n_steps, Ainv, K2, Cm1, f)

    t_full, t_bare = best_of(full), best_of(bare)
    if min(done) < n_steps:
        raise SystemExit(f"the transient stopped early ({min(done)} of {n_steps} steps): timing not comparable")
    print(f"model: {m.n_dofs} dofs, 3D contact ({c.n_blades} blades x {c.n_points} points), dt = {cd.dt:.3e} s")
    print(f"3D transient with contact : {t_full / n_steps * 1e9:8.1f} ns/step")
    print(f"bare linear CD loop       : {t_bare / n_steps * 1e9:8.1f} ns/step")
    print(f"ratio                     : {t_full / t_bare:8.2f}  (target <= 3)")
    print(f"simulated seconds per wall second: {n_steps * cd.dt / t_full:8.1f}")


if __name__ == "__main__":
    main()
