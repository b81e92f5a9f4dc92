"""A tightly integrated periodic orbit of the full model: the reference the harmonic balance and the
central-difference shooting are both measured against where no exact solution exists (the 3D chord law).

The flow is the model's ODE, M q'' + (D + G) q' + K(Omega) q = F(Omega) + F_nl(q, q'; phi = Omega t), the
contact force from the kernel's ``rr_force`` (the function the transients' outputs use, not the harmonic
balance's batch), integrated by an 8th-order Runge-Kutta (DOP853, scipy) at rtol 1e-12: its error on an orbit
is ~1e-10 relative, four orders below the 1e-6 asked of the balance, whatever the chord law's C1 kinks cost
it in steps. Periodic orbits by shooting: Newton on Phi_T(x) - x (forced: T = 2 pi / Omega; autonomous: T an
unknown, with the section q'_k(0) = 0), whose Jacobian may be any fair approximation (forward differences of
the tight flow, :func:`fd_monodromy`): the orbit found is the fixed point of the tight flow, not of the
Jacobian.
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ... import kernel
from ...contact import ContactModel
from ...structure.model import Model
from .surface import CasingForcing

RTOL = 1e-12


@dataclass
class TightOrbit:
    x0: np.ndarray
    period: float
    converged: bool
    residual: float
    iterations: int
    rhs_calls: int

    def sample(self, flow: TightFlow, t: np.ndarray) -> np.ndarray:
        """q (G, n) at times t in [0, period]."""
        sol = solve_ivp(flow.rhs, (0.0, self.period), self.x0, method="DOP853", rtol=flow.rtol,
                        atol=flow.atol, t_eval=np.asarray(t))
        return sol.y[: flow.n].T


class TightFlow:
    """The model's ODE at spin omega, the casing surface of ``forcing`` at phi = omega t."""

    def __init__(self, model: Model, contact: ContactModel, omega: float, forcing: CasingForcing | None = None,
                 me: float | None = None, rtol: float = RTOL, q_scale: float = 1e-4):
        self.model, self.contact, self.omega = model, contact, float(omega)
        self.n = n = model.n_dofs
        forcing = forcing or CasingForcing()
        self.liner = forcing.liner(contact)
        self._view = self.liner.attach(contact.kernel) if self.liner is not None else \
            kernel.RRContact.from_buffer_copy(contact.kernel)
        self._ref = ctypes.byref(self._view)
        self._surface = self.liner.struct if self.liner is not None else None
        self._lib = contact.lib
        self.Minv = model.M_inv
        self.K = model.K_omega(omega)
        self.C = model.D + model.G(omega)
        self.F = model.force(omega, model.params.imbalance.me if me is None else me)
        self.rtol = rtol
        # absolute tolerances per component: positions to 1e-12 of their scale, velocities likewise
        self.atol = np.concatenate([np.full(n, 1e-12 * q_scale), np.full(n, 1e-12 * q_scale * max(omega, 1.0))])
        self._f = np.empty(n)
        self.calls = 0

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        n = self.n
        q = np.ascontiguousarray(x[:n])
        v = np.ascontiguousarray(x[n:])
        if self._surface is not None:
            self._surface.phi = self.omega * t
        self._lib.rr_force(self._ref, kernel.ptr(q), kernel.ptr(v), self.omega, kernel.ptr(self._f))
        self.calls += 1
        return np.concatenate([v, self.Minv @ (self.F + self._f - self.K @ q - self.C @ v)])

    def flow(self, x0: np.ndarray, T: float) -> np.ndarray:
        sol = solve_ivp(self.rhs, (0.0, T), x0, method="DOP853", rtol=self.rtol, atol=self.atol)
        if not sol.success:
            raise RuntimeError(f"the reference integration failed: {sol.message}")
        return sol.y[:, -1]


def fd_monodromy(flow: TightFlow, x0: np.ndarray, T: float, rel: float = 1e-6) -> np.ndarray:
    """dPhi_T/dx by forward differences of the tight flow (steps rel of each component's scale; the adaptive
    step's noise, ~rtol / rel = 1e-6 relative, is far below what Newton needs)."""
    n2 = x0.size
    base = flow.flow(x0, T)
    scale = np.maximum(np.abs(x0), np.concatenate([np.full(n2 // 2, np.abs(x0[: n2 // 2]).max()),
                                                    np.full(n2 // 2, np.abs(x0[n2 // 2:]).max())]))
    J = np.empty((n2, n2))
    for i in range(n2):
        h = rel * max(scale[i], 1e-30)
        xp = x0.copy()
        xp[i] += h
        J[:, i] = (flow.flow(xp, T) - base) / h
    return J


def shoot_forced(flow: TightFlow, x0: np.ndarray, jacobian: np.ndarray, tol: float = 1e-11,
                 max_iter: int = 12) -> TightOrbit:
    """The orbit of period 2 pi / Omega through (near) x0: Newton on Phi_T(x) - x with ``jacobian`` (2n x 2n) the
    monodromy (approximate: the convergence is linear at the approximation's error)."""
    T = 2 * math.pi / flow.omega
    x = np.array(x0, dtype=float)
    A = jacobian - np.eye(x.size)
    res, done = math.inf, 0
    for it in range(1, max_iter + 1):
        done = it
        r = flow.flow(x, T) - x
        res = float(np.abs(r).max()) / max(float(np.abs(x).max()), 1e-30)
        if res <= tol:
            break
        x = x - np.linalg.solve(A, r)
    return TightOrbit(x, T, res <= tol, res, done, flow.calls)


def shoot_autonomous(flow: TightFlow, x0: np.ndarray, T0: float, section: int, jacobian: np.ndarray,
                     tol: float = 1e-11, max_iter: int = 16) -> TightOrbit:
    """The autonomous orbit through (near) x0, period near T0, on the section q'_section(0) = 0: Newton on
    (Phi_T(x) - x, x[n + section]) in (x, T), the monodromy ``jacobian`` approximate."""
    n2 = x0.size
    n = n2 // 2
    x, T = np.array(x0, dtype=float), float(T0)
    res, done = math.inf, 0
    for it in range(1, max_iter + 1):
        done = it
        xT = flow.flow(x, T)
        r = np.concatenate([xT - x, [x[n + section]]])
        res = float(np.abs(r).max()) / max(float(np.abs(x).max()), 1e-30)
        if res <= tol:
            break
        J = np.zeros((n2 + 1, n2 + 1))
        J[:n2, :n2] = jacobian - np.eye(n2)
        J[:n2, n2] = flow.rhs(T, xT)
        J[n2, n + section] = 1.0
        d = np.linalg.solve(J, -r)
        x, T = x + d[:n2], T + d[n2]
    return TightOrbit(x, T, res <= tol, res, done, flow.calls)
