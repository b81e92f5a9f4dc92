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

import ctypes
from dataclasses import dataclass

import numpy as np

from .. import kernel
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
    K = np.ascontiguousarray(model.K_omega(omega), dtype=float)
    F = np.ascontiguousarray(model.force(omega, me), dtype=float)
    n = model.n_dofs
    q = np.empty(n)
    start = None if q0 is None else np.ascontiguousarray(q0, dtype=float)
    rel, its = ctypes.c_double(), ctypes.c_int()
    work = np.empty(contact.lib.rr_static_work_size(n))
    iwork = np.empty(n, dtype=np.intc)
    # Newton, its starts and the imbalance continuation run in the kernel (one call): the FMUs'
    # quasi-static steps are the same code
    ok = bool(contact.lib.rr_static_solve(
        contact.kernel, float(omega), kernel.ptr(K), kernel.ptr(F), None if start is None else kernel.ptr(start),
        float(tol), int(max_iter), kernel.ptr(q), ctypes.byref(rel), ctypes.byref(its), kernel.ptr(work),
        kernel.iptr(iwork)))
    rel, its = rel.value, its.value
    if not ok and raise_on_failure:
        raise ConvergenceError(
            f"static solution at omega={omega:g} rad/s, g0={contact.g0:g} m did not converge "
            f"(relative residual {rel:.2e} after {its} iterations)"
        )
    bf = contact.blade_forces(q, omega)
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
