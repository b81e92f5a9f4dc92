"""Checks of a harmonic-balance problem shared by the HB test files (built-in and imported blades): the residual's
Jacobian by central differences, and the balance rebuilt in every dof with the kernel's own contact force."""

from __future__ import annotations

import numpy as np

from rotorub_model import kernel
from rotorub_model.analyses.harmonic.problem import newton


def fd_jacobian(pb, Y: np.ndarray, omega: float, w: float, h: float) -> np.ndarray:
    """dR/dY of ``pb``'s residual at Y by central differences of step h in every coefficient."""
    return np.column_stack([(pb.evaluate(Y + h * e, omega, w, False).R - pb.evaluate(Y - h * e, omega, w, False).R)
                            / (2 * h) for e in np.eye(Y.size)])


def jacobian_error_in_contact(pb, omega: float) -> float:
    """max |analytic dR/dY - central differences| / max |dR/dY| near ``pb``'s forced orbit at ``omega`` (the orbit
    moved by 1e-6 in every coefficient, seed 0, so that no sample sits on a contact event); asserts blades touch."""
    Y = newton(pb, pb.linear_start(omega, omega), omega, omega).Y
    Y = Y + 1e-6 * np.random.default_rng(0).standard_normal(Y.size)
    ev = pb.evaluate(Y, omega, omega)
    assert ev.touching > 0
    Jfd = fd_jacobian(pb, Y, omega, omega, 1e-9)
    return float(np.abs(Jfd - ev.J).max() / np.abs(ev.J).max())


def balance_in_every_dof(pb, Y: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lhs, rhs, F) of a forced orbit (w = omega) rebuilt from its contact coordinates: lhs the structure's
    M q'' + C q' + K q per harmonic, rhs the harmonics of the kernel's rr_force at every sample (each at its own
    frame angle of the casing surface) plus the imbalance, F the sampled force (m, n)."""
    m = pb.model
    Q = pb.full(Y, omega, omega)
    b = pb.basis
    q, qd = b.E @ Q, omega * (b.dE @ Q)
    F = np.empty_like(q)
    c, liner = pb.contact, pb.liner
    for i in range(b.m):
        liner.struct.phi = float(b.tau[i])
        k = liner.attach(c.kernel)
        qi, qdi, fi = np.ascontiguousarray(q[i]), np.ascontiguousarray(qd[i]), np.empty(m.n_dofs)
        c.lib.rr_force(k, kernel.ptr(qi), kernel.ptr(qdi), omega, kernel.ptr(fi))
        F[i] = fi
    D = b.derivative()
    lhs = (omega * omega) * (D @ D @ Q) @ m.M.T + omega * (D @ Q) @ (m.D + m.G(omega)).T + Q @ m.K_omega(omega).T
    rhs = b.P @ F
    rhs[0] += m.force(omega)
    return lhs, rhs, F
