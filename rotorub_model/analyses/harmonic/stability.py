"""Stability of a harmonic-balance orbit: Floquet multipliers from the monodromy (primary), and Hill's method
(the cross-check).

A perturbation x of the orbit obeys M x'' + (C - Jv(t)) x' + (K - J(t)) x = 0, J, Jv the contact force's
Jacobians along the orbit (T-periodic), C = D + G(Omega), K = K(Omega).

**Monodromy (primary).** The first-order form z' = (A0 + dA(t)) z, A0 the linear part and
dA(t) = B [J(t), Jv(t)]-rows of rank r (the contact coordinates of :mod:`.problem`: dA = B Cr(t),
B = [0; M^-1 P^T], Cr = [Jp P, Jvp P]), is integrated over one period by Strang splitting on a grid of
``substeps`` x m steps: z <- e^{A0 h/2} e^{dA h} e^{A0 h/2} z, with e^{A0 h} exact (A0's eigen-decomposition,
diagonal in its modal coordinates) and e^{dA h} = I + h B phi1(h Cr B) Cr exact (rank r; phi1(x) = (e^x - 1)/x).
The splitting's error is O(h^2) in the multipliers; the Jacobians at the fine grid come from the orbit's
Fourier series through the kernel (``rr_batch_eval``). Why primary: it needs no sorting of spurious
exponents, its cost grows with the grid, not with (2n(2H+1))^3, and it is a time integration of the same
orbit, independent of the balance's own Jacobian.

**Hill's method (check).** With x = e^{lambda t} p(t), p on the HB basis (coefficients (2H+1) x n, derivative
operator N = w nabla (x) I):
(lambda^2 M^ + lambda (2 M^ N + C^) + (M^ N^2 + C^ N + K^)) p = 0, M^ = I (x) M, C^ = I (x) C - T[Jv],
K^ = I (x) K - T[J], T[.] the AFT's operator of a time-varying matrix. Its 2n(2H+1) eigenvalues repeat each
Floquet exponent at lambda + i k w; the 2n kept are those whose eigenvectors weigh most on harmonic 0 (the
centred representatives). Multipliers rho = exp(lambda T). Cost: a dense eigen-problem of 2n(2H+1): a test's
check at small H, not the continuation's tool.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from .basis import HarmonicBasis
from .problem import HBProblem

MULTIPLIER_TOL = 1e-6  # a multiplier within this of the unit circle is neutral (the splitting's resolution)
DEFAULT_SUBSTEPS = 2  # measured: the leading multiplier moves by < 2e-5 from 2 to 16 substeps (3D), 1e-7 (2D)


@dataclass
class Floquet:
    multipliers: np.ndarray  # by decreasing modulus (the trivial one removed for an autonomous orbit)
    method: str
    steps: int = 0

    @property
    def largest(self) -> float:
        return float(np.abs(self.multipliers).max()) if self.multipliers.size else 0.0

    @property
    def stable(self) -> bool:
        return self.largest < 1.0 + MULTIPLIER_TOL

    def kind(self) -> str:
        """How the leading multiplier leaves the unit circle: through +1 (fold or branch point), -1 (period
        doubling) or as a complex pair (Neimark-Sacker: a quasi-periodic response)."""
        if self.stable:
            return "stable"
        rho = self.multipliers[0]
        if abs(rho.imag) > 1e-6 * abs(rho):
            return "neimark-sacker"
        return "fold/branch (+1)" if rho.real > 0 else "period doubling (-1)"


class _Modal:
    """A0's eigen-decomposition at (Omega): z = S u, u' = Lambda u."""

    def __init__(self, problem: HBProblem, omega: float):
        m = problem.model
        n = problem.n
        K, C = m.K_omega(omega), m.D + m.G(omega)
        Minv = m.M_inv
        A0 = np.zeros((2 * n, 2 * n))
        A0[:n, n:] = np.eye(n)
        A0[n:, :n] = -Minv @ K
        A0[n:, n:] = -Minv @ C
        lam, S = np.linalg.eig(A0)
        self.lam, self.S = lam, S
        self.Sinv = np.linalg.inv(S)
        B = np.zeros((2 * n, problem.r))
        B[n:] = Minv @ problem.P.T
        self.Bt = self.Sinv @ B  # B in modal coordinates (2n x r)
        P = problem.P
        self.Pq = np.hstack([P, np.zeros_like(P)]) @ S  # (r x 2n) y = P q in modal coordinates
        self.Pv = np.hstack([np.zeros_like(P), P]) @ S  # y' = P q'
        self.MB = P @ Minv @ P.T  # Cr B = Jvp (P M^-1 P^T)


def monodromy_multipliers(problem: HBProblem, Y: np.ndarray, omega: float, w: float, substeps: int = DEFAULT_SUBSTEPS,
                          autonomous: bool = False) -> Floquet:
    """Floquet multipliers of the orbit Y by the split-exponential monodromy on substeps x m steps."""
    b = problem.basis
    ms = int(substeps) * b.m
    fine = HarmonicBasis(b.harmonics, ms)
    Yc = Y.reshape(b.size, problem.r)
    y, yd = fine.E @ Yc, w * (fine.dE @ Yc)
    phi = None if not problem.forced else np.ascontiguousarray(fine.tau * (omega / w))
    _, Jp, Jvp, _ = problem.kernel_batch(y, yd, omega, phi, jacobians=True)
    md = _Modal(problem, omega)
    T = 2 * math.pi / w
    h = T / ms
    d = np.exp(md.lam * h)
    U = np.eye(2 * problem.n, dtype=complex)
    has_v = Jvp.any(axis=(1, 2))
    active = np.flatnonzero(Jp.any(axis=(1, 2)) | has_v)
    # the contact rows in modal coordinates at every active step at once: Cr_j = Jp_j Pq + Jvp_j Pv (r x 2n)
    Cr = np.einsum("juv,vk->juk", Jp[active], md.Pq)
    if has_v.any():
        Cr += np.einsum("juv,vk->juk", Jvp[active], md.Pv)
    hB = h * md.Bt
    half = np.exp(md.lam * h * 0.5)
    last = -1  # free steps between active ones: one diagonal scaling (e^{A0 h} is diagonal here)
    for a, j in enumerate(active):
        # the free flow up to the middle of this step, the contact's exact exponential, then half a step
        U *= (d ** (j - last - 1) * half)[:, None]
        last = j
        if has_v[j]:
            G = h * (Jvp[j] @ md.MB)
            r = G.shape[0]
            aug = np.zeros((2 * r, 2 * r))
            aug[:r, :r] = G
            aug[:r, r:] = np.eye(r)
            U += (hB @ expm(aug)[:r, r:]) @ (Cr[a] @ U)
        else:
            U += hB @ (Cr[a] @ U)
        U *= half[:, None]
    U *= (d ** (ms - 1 - last))[:, None]
    rho = np.linalg.eigvals(U)  # similar to the monodromy (modal coordinates)
    return Floquet(_sorted(rho, autonomous), "monodromy (split exponential)", ms)


def _sorted(rho: np.ndarray, autonomous: bool) -> np.ndarray:
    if autonomous and rho.size:
        rho = np.delete(rho, int(np.argmin(np.abs(rho - 1.0))))
    return rho[np.argsort(-np.abs(rho))]


def hill_exponents(problem: HBProblem, Y: np.ndarray, omega: float, w: float) -> tuple[np.ndarray, np.ndarray]:
    """(all 2n(2H+1) Hill eigenvalues, the 2n centred Floquet exponents)."""
    b = problem.basis
    n, r, nh = problem.n, problem.r, b.size
    Yc = Y.reshape(nh, r)
    y, yd = b.E @ Yc, w * (b.dE @ Yc)
    _, Jp, Jvp, _ = problem.kernel_batch(y, yd, omega, problem.phases(w, omega), jacobians=True)
    P = problem.P
    m = problem.model
    K, C, M = m.K_omega(omega), m.D + m.G(omega), m.M

    def operator(Jr: np.ndarray) -> np.ndarray:  # T[P^T J P]: (a,u),(b,v) = sum_i Pdft[a,i] J_i[u,v] E[i,b]
        Jfull = np.einsum("ur,irs,sv->iuv", P.T, Jr, P)
        return np.einsum("ai,iuv,ib->aubv", b.P, Jfull, b.E).reshape(nh * n, nh * n)

    I_h = np.eye(nh)
    Mh = np.kron(I_h, M)
    Ch = np.kron(I_h, C) - operator(Jvp)
    Kh = np.kron(I_h, K) - operator(Jp)
    N = w * np.kron(b.derivative().T, np.eye(n))  # d/dt on stacked coefficients (harmonic-major)
    A2, A1, A0 = Mh, 2 * Mh @ N + Ch, Mh @ N @ N + Ch @ N + Kh
    size = nh * n
    Minv = np.linalg.inv(A2)
    comp = np.zeros((2 * size, 2 * size))
    comp[:size, size:] = np.eye(size)
    comp[size:, :size] = -Minv @ A0
    comp[size:, size:] = -Minv @ A1
    lam, vec = np.linalg.eig(comp)
    weight = np.sum(np.abs(vec[:n]) ** 2, axis=0) / np.sum(np.abs(vec[:size]) ** 2, axis=0)
    keep = np.argsort(-weight)[: 2 * n]
    return lam, lam[keep]


def hill_multipliers(problem: HBProblem, Y: np.ndarray, omega: float, w: float, autonomous: bool = False) -> Floquet:
    _, lam = hill_exponents(problem, Y, omega, w)
    return Floquet(_sorted(np.exp(lam * 2 * math.pi / w), autonomous), "Hill")
