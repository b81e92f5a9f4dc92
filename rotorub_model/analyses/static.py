"""Balanced static solutions with contact (eq. 10): K(Omega) q0 = F_nl(q0) + F(Omega^2).

Newton's method on R(q) = K(Omega) q - F_nl(q) - F with the analytic contact
Jacobian and a backtracking line search on |R|. The contact forces are piecewise
smooth (2D: piecewise linear), so a full Newton step can jump between contact
states and cycle. Near the critical speed the contact stiffening bends the
resonance (as a hardening Duffing oscillator): the solution branch followed by a
continuation in g0 or in the imbalance can end at a fold, beyond which the
equilibrium lies on another branch. So when Newton fails from the warm start, it
is restarted from a set of candidates: the linear response, the responses with
all contacts closed (full and half stiffness), scaled linear responses, and a
continuation in the imbalance. The first converged one is returned; the result
always says whether it converged and with what residual.

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> from rotorub_model.contact import make_contact
>>> m = build_model()
>>> r = solve_static(m, make_contact(m, "3D", g0=0.2e-3), 3.3 * 53.4)
>>> r.converged, r.n_contact
(True, 4)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import ContactModel
from ..errors import ConvergenceError, ParameterError
from ..structure.model import Model


@dataclass
class StaticResult:
    q: np.ndarray
    omega: float  # rad/s
    g0: float
    converged: bool
    residual: float  # |R| / |F|
    iterations: int
    n_contact: int
    fractions: np.ndarray  # chord fraction in contact per blade (2D: 0/1)
    forces_N: np.ndarray  # F_N per blade

    def summary(self) -> dict:
        return {
            "omega_rad_s": self.omega,
            "g0_m": self.g0,
            "converged": self.converged,
            "relative_residual": self.residual,
            "iterations": self.iterations,
            "blades_in_contact": self.n_contact,
            "chord_fractions": self.fractions,
            "normal_forces_N": self.forces_N,
        }


def _check_omega(omega: float) -> None:
    if not np.isfinite(omega) or omega < 0:
        raise ParameterError(f"omega: {omega} out of range; accepted range [0, inf) rad/s")


def _newton(K: np.ndarray, F: np.ndarray, contact: ContactModel, q: np.ndarray, tol: float, max_iter: int):
    scale = max(np.linalg.norm(F), 1e-12 * np.linalg.norm(K, 1), 1e-30)

    def res(x):
        return K @ x - contact.forces(x) - F

    r = res(q)
    nr = np.linalg.norm(r)
    for it in range(1, max_iter + 1):
        if nr <= tol * scale:
            return q, nr / scale, it - 1, True
        dq = np.linalg.solve(K - contact.jacobian(q), -r)
        step = 1.0
        while step > 1e-6:
            qn = q + step * dq
            rn = res(qn)
            nn = np.linalg.norm(rn)
            if nn < (1 - 1e-4 * step) * nr:
                break
            step *= 0.5
        else:
            return q, nr / scale, it, False
        q, r, nr = qn, rn, nn
    return q, nr / scale, max_iter, nr <= tol * scale


def _candidates(K, F, contact, q_lin, starts):
    """Starting points, cheapest and most likely first (a generator: built lazily)."""
    yield from starts
    yield q_lin
    from .transient import all_closed_stiffness

    Kc = all_closed_stiffness(contact)
    for frac in (1.0, 0.5, 0.1):
        yield np.linalg.solve(K + frac * Kc, F)
    for a in (0.5, 0.25, 1.5, 2.0):
        yield a * q_lin


def solve_static(
    model: Model,
    contact: ContactModel,
    omega: float,
    me: float | None = None,
    q0: np.ndarray | None = None,
    tol: float = 1e-10,
    max_iter: int = 60,
    raise_on_failure: bool = False,
) -> StaticResult:
    """Balanced static solution at spin speed omega [rad/s], warm-started from q0.

    Starts from q0 (default: the linear response, which is exact when nothing
    touches); if Newton fails, continues in the imbalance from 0 to m e.
    """
    _check_omega(omega)
    K = model.K_omega(omega)
    F = model.force(omega, me)
    q_lin = np.linalg.solve(K, F)
    starts = [q0] if q0 is not None else []
    its_total = 0
    best = None
    for start in _candidates(K, F, contact, q_lin, starts):
        q, rel, its, ok = _newton(K, F, contact, np.array(start, dtype=float), tol, max_iter)
        its_total += its
        if best is None or rel < best[1]:
            best = (q, rel)
        if ok:
            break
    if not ok:
        q = np.zeros(model.n_dofs)
        for lam in np.linspace(0.1, 1.0, 10):
            q, rel, its, ok = _newton(K, lam * F, contact, q, tol, max_iter)
            its_total += its
            if not ok:
                break
        if not ok:
            q, rel = best
    its = its_total
    if not ok and raise_on_failure:
        raise ConvergenceError(
            f"static solution at omega={omega:g} rad/s, g0={contact.g0:g} m did not converge "
            f"(relative residual {rel:.2e} after {its} iterations)"
        )
    bf = contact.blade_forces(q)
    return StaticResult(
        q=q,
        omega=float(omega),
        g0=contact.g0,
        converged=bool(ok),
        residual=float(rel),
        iterations=int(its),
        n_contact=int(np.sum(bf["F_N"] > 0)),
        fractions=bf["fraction"],
        forces_N=bf["F_N"],
    )
