"""Balanced static solutions as functions of (Omega, g0), their linearisation and their critical
eigenvalue: what the continuation and the stability-boundary tracking are built on.

At spin speed Omega and clearance g0 the balanced solution solves (eq. 10)

    R(q; Omega, g0) = K(Omega) q - F_nl(q; Omega, g0) - m e Omega^2 f = 0,

and a perturbation obeys M x'' + C_e x' + K_e x = 0 with K_e = K(Omega) - dF_nl/dq and
C_e = D + G(Omega) - dF_nl/dq' (eq. 11). Its eigenvalues mu solve the quadratic eigenproblem
P(mu) v = (mu^2 M + mu C_e + K_e) v = 0. The full spectrum comes from the first-order matrix
(LAPACK); the critical eigenvalue (rightmost of an oscillatory pair) is then refined by Newton's
method on P(mu) v = 0 with a normalisation, which resolves its real part to ~1e-12 /s where the
dense eigen-solver, working on a matrix of norm 1e9, resolves ~1e-7.

Contact sets: a blade touches where its law gives F_N > 0; in 3D each edge is in contact or not
(the chord law is C^1 across an edge entering contact, the 2D point law only C^0, so in 2D the
linearisation jumps when the contact set changes and is constant in g0 between changes).
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np

from ... import kernel
from ...contact import ContactModel, make_contact
from ...structure.model import Model
from ..static import solve_static


@dataclass
class Point:
    """One balanced solution and what the continuation records of it."""

    omega: float  # [rad/s]
    g0: float  # [m]
    q: np.ndarray
    contact_set: tuple  # per contact point: True where its gap is negative
    n_contact: int
    max_force: float  # [N] largest blade normal force
    disk_amplitude: float  # [m] fan-disk centre displacement
    mu: complex | None = None  # critical eigenvalue (rightmost of an oscillatory pair)
    max_real: float | None = None  # [1/s] rightmost real part of the whole spectrum


class Equilibria:
    """Static solutions of one formulation on one model, at any (Omega, g0)."""

    def __init__(self, model: Model, formulation: str, variant: str = "full", me: float | None = None,
                 tol: float = 1e-12):
        self.model = model
        self.formulation = formulation
        self.base = make_contact(model, formulation, variant)
        self.me = model.params.imbalance.me if me is None else me
        self.tol = tol
        # a continuation step starts next to the solution: Newton converges in 1-3 iterations (up to ~8
        # near a fold); one that has not in 10 has lost the branch, and a lost one is what costs
        self.follow_iterations = 10
        self.n = model.n_dofs
        self._contacts: dict[float, ContactModel] = {}
        self._Minv = model.M_inv
        T, _ = model.disk_maps
        self._T2 = T[:2]
        self._speed_cache = None
        self._rel, self._its = ctypes.c_double(), ctypes.c_int()
        self._swork = np.empty(self.base.lib.rr_static_work_size(self.n))
        self._iwork = np.empty(self.n, dtype=np.intc)
        self._wptr = (kernel.ptr(self._swork), kernel.iptr(self._iwork))
        # one contact model whose clearance is set in place, for the solver's and the spectra's own use:
        # a continuation visits a new g0 at nearly every call, and building a model per g0 (its kernel
        # view, its work array) cost as much as the Newton solve itself
        self._scratch = self.base.with_clearance(float(self.base.g0))

    def _law(self, g0: float) -> ContactModel:
        c = self._scratch
        if c.g0 != g0:
            c.g0 = float(g0)
            c.kernel.g0 = float(g0)
        return c

    # ------------------------------------------------------------------ pieces
    def contact(self, g0: float) -> ContactModel:
        c = self._contacts.get(g0)
        if c is None:
            if len(self._contacts) > 64:
                self._contacts.clear()
            c = self._contacts[g0] = self.base.with_clearance(float(g0))
        return c

    def residual(self, q: np.ndarray, omega: float, g0: float) -> np.ndarray:
        return self.model.K_omega(omega) @ q - self._law(g0).forces(q, omega) - self.model.force(omega, self.me)

    def jacobian(self, q: np.ndarray, omega: float, g0: float) -> np.ndarray:
        """dR/dq = K(Omega) - dF_nl/dq."""
        self._at_speed(omega)
        return self._speed_cache[1] - self._law(g0).jacobian(q, omega)

    def orientation(self, q: np.ndarray, omega: float, g0: float) -> tuple[float, float]:
        """(sign, log|det|) of dR/dq. The sign changes across a fold, so it tells the two branches
        meeting there apart; approaching a smooth fold det^2 vanishes linearly in the parameter."""
        sign, logdet = np.linalg.slogdet(self.jacobian(q, omega, g0))
        return float(sign), float(logdet)

    def d_param(self, q: np.ndarray, omega: float, g0: float, which: str) -> np.ndarray:
        """dR/d(parameter) by central differences (the laws are C^1 in 3D, and piecewise linear in
        2D with the kinks at contact events, which the continuation steps onto and never across)."""
        if which == "g0":
            h = 1e-9 * max(abs(g0), 1e-4)
            return (self.residual(q, omega, g0 + h) - self.residual(q, omega, g0 - h)) / (2 * h)
        h = 1e-7 * max(abs(omega), 1.0)
        return (self.residual(q, omega + h, g0) - self.residual(q, omega - h, g0)) / (2 * h)

    def _at_speed(self, omega: float) -> tuple[int, int]:
        """Addresses of K(Omega) and the imbalance load at Omega (kept while the speed is unchanged)."""
        hit = self._speed_cache
        if hit is None or hit[0] != omega:
            K = np.ascontiguousarray(self.model.K_omega(omega), dtype=float)
            F = np.ascontiguousarray(self.model.force(omega, self.me), dtype=float)
            hit = self._speed_cache = (omega, K, F, kernel.ptr(K), kernel.ptr(F))
        return hit[3], hit[4]

    def solve(self, omega: float, g0: float, q0: np.ndarray | None = None, follow: bool = False,
              max_iter: int | None = None) -> np.ndarray | None:
        """The balanced solution from the warm start q0 (None if it does not converge): the kernel's
        solver, as in :func:`.static.solve_static`, with the speed's matrices kept between calls.
        ``follow``: Newton from q0 only (a continuation step: no other start, no jump to another branch),
        at most ``max_iter`` iterations (``follow_iterations`` by default)."""
        if not (np.isfinite(omega) and omega >= 0):
            return solve_static(self.model, self.contact(g0), omega).q  # raises the parameter error
        K, F = self._at_speed(omega)
        c = self._law(g0)
        k, lib = c.kernel, c.lib
        if follow and q0 is not None:
            q = np.array(q0, dtype=float)
            its = max_iter or self.follow_iterations
            ok = lib.rr_static_newton(k, float(omega), K, F, float(self.tol), its, q.ctypes.data,
                                      ctypes.byref(self._rel), ctypes.byref(self._its), *self._wptr)
            return q if ok else None
        q = np.empty(self.n)
        start = None if q0 is None else np.ascontiguousarray(q0, dtype=float)
        ok = lib.rr_static_solve(k, float(omega), K, F, None if start is None else kernel.ptr(start),
                                 float(self.tol), 60, q.ctypes.data, ctypes.byref(self._rel),
                                 ctypes.byref(self._its), *self._wptr)
        return q if ok else None

    def contact_set(self, q: np.ndarray, g0: float) -> tuple:
        return tuple(bool(x) for x in (self._law(g0).gaps(q) < 0.0).ravel())

    def gaps(self, q: np.ndarray, g0: float) -> np.ndarray:
        """Gaps (N, P) [m] of the balanced solution q at clearance g0."""
        return self._law(g0).gaps(q)

    def point(self, q: np.ndarray, omega: float, g0: float, spectrum: bool = True) -> Point:
        gaps, laws = self._law(g0)._eval(q)  # one evaluation of the law for both
        p = Point(float(omega), float(g0), q, tuple(bool(x) for x in (gaps < 0.0).ravel()),
                  int(np.sum(laws[:, 0] > 0)), float(laws[:, 0].max()), float(np.hypot(*(self._T2 @ q))))
        if spectrum:
            p.mu, p.max_real = self.critical(q, omega, g0)
        return p

    def unstable_start(self, q: np.ndarray, omega: float, g0: float, mu: complex,
                       amplitude: float) -> tuple[np.ndarray, np.ndarray]:
        """(q0, v0) next to the balanced solution q along the eigenvector of mu (refined), scaled so
        that the fan-disk moves by ``amplitude`` [m]: where a transient leaves an unstable solution."""
        mu, v = self.refine(q, omega, g0, mu)
        v = v / np.abs(self._T2 @ v).max()
        return q + amplitude * np.real(v), amplitude * np.real(mu * v)

    # ------------------------------------------------------------------ linearisation
    def linearisation(self, q: np.ndarray, omega: float, g0: float) -> tuple[np.ndarray, np.ndarray]:
        """(K_e, C_e) of the perturbation equation at the balanced solution q."""
        J, Jv = self._law(g0).jacobians(q, omega)
        m = self.model
        return m.K_omega(omega) - J, m.D + m.G(omega) - Jv

    def spectrum(self, q: np.ndarray, omega: float, g0: float) -> np.ndarray:
        """All eigenvalues of the linearised system (first-order form, LAPACK)."""
        K, C = self.linearisation(q, omega, g0)
        n = self.n
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -self._Minv @ K
        A[n:, n:] = -self._Minv @ C
        return np.linalg.eigvals(A)

    def refine(self, q: np.ndarray, omega: float, g0: float, mu: complex,
               v: np.ndarray | None = None) -> tuple[complex, np.ndarray]:
        """Newton on (mu^2 M + mu C + K) v = 0, u.v = 1, from mu (and v): the eigenvalue to ~1e-12."""
        K, C = self.linearisation(q, omega, g0)
        M = self.model.M
        n = self.n
        if v is None:  # inverse iteration from the guess
            P = mu * mu * M + mu * C + K
            v = np.linalg.solve(P + 1e-9 * np.abs(P).max() * np.eye(n), np.ones(n, dtype=complex))
        v = v / v[np.argmax(np.abs(v))]
        u = np.conj(v) / np.vdot(v, v)
        u = u / (u @ v)
        B = np.zeros((n + 1, n + 1), dtype=complex)
        for _ in range(30):
            P = mu * mu * M + mu * C + K
            r = np.concatenate([P @ v, [u @ v - 1.0]])
            B[:n, :n] = P
            B[:n, n] = (2 * mu * M + C) @ v
            B[n, :n] = u
            d = np.linalg.solve(B, -r)
            v = v + d[:n]
            mu = mu + d[n]
            if abs(d[n]) <= 1e-7 * abs(mu):
                # quadratic convergence: the correction just applied leaves an error ~ |d|^2/|mu| <=
                # 1e-14 |mu| (|mu| ~ 300 /s: 3e-12 /s, far below the 1e-8 asked of a Hopf point)
                break
        return complex(mu), v

    def critical(self, q: np.ndarray, omega: float, g0: float) -> tuple[complex, float]:
        """(mu, max real part): mu the rightmost eigenvalue with Im > 0, refined; the whole
        spectrum's largest real part (a real eigenvalue could lead: a static divergence)."""
        lam = self.spectrum(q, omega, g0)
        osc = lam[lam.imag > 1e-6 * np.maximum(1.0, np.abs(lam))]
        mu0 = osc[np.argmax(osc.real)]
        mu, _ = self.refine(q, omega, g0, mu0)
        return mu, float(max(lam.real.max(), mu.real))
