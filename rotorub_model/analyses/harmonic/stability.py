"""Stability of a harmonic-balance orbit: Floquet multipliers from the monodromy (primary), and Hill's method
(the cross-check).

A perturbation x of the orbit obeys M x'' + (C - Jv(t)) x' + (K - J(t)) x = 0, J, Jv the contact force's
Jacobians along the orbit (T-periodic), C = D + G(Omega), K = K(Omega).

**Monodromy (primary).** The first-order form z' = (A0 + dA(t)) z, A0 the linear part and
dA(t) = B [J(t), Jv(t)]-rows of rank r (the contact coordinates of :mod:`.problem`: dA = B Cr(t),
B = [0; M^-1 P^T], Cr = [Jp P, Jvp P]), is integrated over one period by Strang splitting on a grid of steps
(default m / 2, at least 64): z <- e^{A0 h/2} e^{dA h} e^{A0 h/2} z, with e^{A0 h} exact (A0's real modal form:
2 x 2 rotation-scalings) and e^{dA h} = I + h B phi1(h Cr B) Cr exact (rank r; phi1(x) = (e^x - 1)/x), the
Jacobian averaged over 4 samples of each step (the 2D law switches inside steps). The product runs in C
(``rr_batch_monodromy``); the Jacobians come from the orbit's Fourier series through the kernel
(``rr_batch_reduced``). An orbit that touches at no sample has the contact-free spectrum's multipliers. Why
primary: it needs no sorting of spurious exponents, its cost grows with the grid, not with (2n(2H+1))^3, and
it is a time integration of the same orbit, independent of the balance's own Jacobian.

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

from ... import kernel
from .problem import HBProblem, _lib

MULTIPLIER_TOL = 1e-6  # a multiplier within this of the unit circle is neutral (the splitting's resolution)
# the default grid: half a step per AFT sample (at least 64 steps), the Jacobian averaged over 4 samples in each
# step. Measured on the oval reference at 3.25-3.75 Omega_ref against 4096 steps: the leading multiplier within
# 4e-5 in 2D and 3D; without the averaging the 2D law's switching within a step costs up to 5e-3 (docs/THEORY.md
# section 8)
DEFAULT_SUBSTEPS = None
DEFAULT_SUBSAMPLES = 4


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
    """A0's eigen-decomposition at (Omega) in real modal form: z = S u, u' = Lambda u, Lambda block-diagonal (a real
    eigenvalue, or a pair a +- i b acting on (Re v, Im v) as [[a, b], [-b, a]]): the monodromy's product then runs
    in real arithmetic (a quarter of the complex flops)."""

    def __init__(self, problem: HBProblem, omega: float):
        m = problem.model
        n = problem.n
        K, C = m.K_omega(omega), m.D + m.G(omega)
        Minv = m.M_inv
        A0 = np.zeros((2 * n, 2 * n))
        A0[:n, n:] = np.eye(n)
        A0[n:, :n] = -Minv @ K
        A0[n:, n:] = -Minv @ C
        lam, V = np.linalg.eig(A0)
        self.lam = lam
        cols, size, re, im = [], [], [], []
        scale = np.abs(lam).max() if lam.size else 1.0
        for i in np.argsort(-lam.imag):  # pairs first (one of each), then the real ones
            li = lam[i]
            if li.imag > 1e-12 * scale:
                cols += [V[:, i].real, V[:, i].imag]
                size.append(2)
                re.append(li.real)
                im.append(li.imag)
            elif abs(li.imag) <= 1e-12 * scale:
                cols.append(V[:, i].real)
                size.append(1)
                re.append(li.real)
                im.append(0.0)
        S = np.column_stack(cols)
        if S.shape != (2 * n, 2 * n):
            raise np.linalg.LinAlgError("the modal form did not pair A0's eigenvalues")
        self.S = S
        self.Sinv = np.linalg.inv(S)
        self.size = np.array(size, dtype=np.int32)
        self.re, self.im = np.array(re), np.array(im)
        B = np.zeros((2 * n, problem.r))
        B[n:] = Minv @ problem.P.T
        self.Bt = np.ascontiguousarray(self.Sinv @ B)  # B in modal coordinates (2n x r)
        P = problem.P
        self.Pq = np.ascontiguousarray(np.hstack([P, np.zeros_like(P)]) @ S)  # (r x 2n) y = P q in modal coordinates
        self.Pv = np.ascontiguousarray(np.hstack([np.zeros_like(P), P]) @ S)  # y' = P q'
        self.MB = P @ Minv @ P.T  # Cr B = Jvp (P M^-1 P^T)


def _modal(problem: HBProblem, omega: float) -> _Modal:
    """The modal form at omega, kept on the problem for the next call at the same speed (a continuation's
    stability checks, the agreement's)."""
    cache = getattr(problem, "_modal_cache", None)
    if cache is None or cache[0] != float(omega):
        cache = (float(omega), _Modal(problem, omega))
        problem._modal_cache = cache
    return cache[1]


def linear_multipliers(problem: HBProblem, omega: float, w: float, autonomous: bool = False) -> Floquet:
    """The multipliers of an orbit that touches nowhere: e^{lambda T}, lambda the contact-free spectrum at omega."""
    m = problem.model
    n = problem.n
    A0 = np.zeros((2 * n, 2 * n))
    A0[:n, n:] = np.eye(n)
    A0[n:, :n] = -m.M_inv @ m.K_omega(omega)
    A0[n:, n:] = -m.M_inv @ (m.D + m.G(omega))
    lam = np.linalg.eigvals(A0)
    return Floquet(_sorted(np.exp(lam * 2 * math.pi / w), autonomous), "linear (no contact on the orbit)", 0)


def default_steps(problem: HBProblem) -> int:
    """The monodromy's steps by default: m / 2, at least 64."""
    return max(64, problem.basis.m // 2)


def monodromy_multipliers(problem: HBProblem, Y: np.ndarray, omega: float, w: float,
                          substeps: float | None = None,
                          autonomous: bool = False, steps: int | None = None,
                          subsamples: int = DEFAULT_SUBSAMPLES, return_matrix: bool = False) -> Floquet:
    """Floquet multipliers of the orbit Y by the split-exponential monodromy on ``steps`` steps (or ``substeps``
    per AFT sample; default :func:`default_steps`), each step's contact exponential taken with the mean of the
    Jacobian over ``subsamples`` points of the step (where a blade enters or leaves contact within a step, the
    mean weighs the part of the step it touches: the step's error there falls by that factor). An orbit that
    touches at none of the samples has the contact-free system's multipliers (no product needed)."""
    b = problem.basis
    if steps is None:
        steps = default_steps(problem) if substeps is None else int(round(substeps * b.m))
    ms, sub = int(steps), int(subsamples)
    if ms < 2 * b.harmonics + 2 or sub < 1:
        raise ValueError(f"steps, subsamples: {ms}, {sub}; accepted steps >= 2 H + 2 = {2 * b.harmonics + 2}, "
                         "subsamples >= 1")
    Yc = Y.reshape(b.size, problem.r)
    # the step centres tau_j = 2 pi j / ms; the sub-samples at the centres of sub equal parts of each step
    tau = (2 * math.pi / ms) * (np.arange(ms)[:, None] + (np.arange(sub)[None, :] + 0.5) / sub - 0.5).ravel()
    E = b.evaluate(np.eye(b.size), tau)
    dE = b.evaluate(b.derivative(), tau)
    y, yd = E @ Yc, w * (dE @ Yc)
    phi = problem.phases(w, omega, tau)
    _, Jp, Jvp, touching = problem.kernel_batch(y, yd, omega, phi, jacobians=True)
    if touching == 0 and not return_matrix:
        return linear_multipliers(problem, omega, w, autonomous)
    r = problem.r
    Jp = Jp.reshape(ms, sub, r, r).mean(axis=1)
    Jvp = Jvp.reshape(ms, sub, r, r).mean(axis=1)
    md = _modal(problem, omega)
    T = 2 * math.pi / w
    h = T / ms
    r = problem.r
    has_v = Jvp.any(axis=(1, 2))
    act_mask = Jp.any(axis=(1, 2)) | has_v
    active = np.flatnonzero(act_mask)
    Jpa = np.ascontiguousarray(Jp[active])
    Jva = np.ascontiguousarray(Jvp[active]) if has_v.any() else None
    hB = np.ascontiguousarray(h * md.Bt)
    Bx = None
    if Jva is not None:  # where friction damps (low tip speeds): the rank-r exponential I + h B phi1(h Cr B) Cr
        Bx = np.empty((active.size, 2 * problem.n, r))
        for a, j in enumerate(active):
            if not has_v[j]:
                Bx[a] = hB
                continue
            G = h * (Jvp[j] @ md.MB)
            aug = np.zeros((2 * r, 2 * r))
            aug[:r, :r] = G
            aug[:r, r:] = np.eye(r)
            Bx[a] = hB @ expm(aug)[:r, r:]
    U = np.eye(2 * problem.n)
    work = np.empty(2 * r * 2 * problem.n)
    ptr = kernel.ptr
    act_i = np.ascontiguousarray(act_mask.astype(np.int32))
    done = _lib().rr_batch_monodromy(2 * problem.n, md.size.size, md.size.ctypes.data, ptr(md.re), ptr(md.im), ms,
                                     float(h), act_i.ctypes.data, r, ptr(Jpa), None if Jva is None else ptr(Jva),
                                     ptr(md.Pq), ptr(md.Pv), ptr(hB), None if Bx is None else ptr(Bx), ptr(U),
                                     ptr(work))
    if done < 0:
        raise RuntimeError("rr_batch_monodromy: the modal blocks do not fill the state")
    if return_matrix:
        return md.S @ U @ md.Sinv  # the monodromy in (q, q')
    rho = np.linalg.eigvals(U)  # similar to the monodromy (modal coordinates)
    return Floquet(_sorted(rho, autonomous), "monodromy (split exponential)", ms)


def monodromy_matrix(problem: HBProblem, Y: np.ndarray, omega: float, w: float, steps: int | None = None,
                     subsamples: int = 4) -> np.ndarray:
    """The monodromy matrix (2n x 2n, in (q, q') from t = -h/2) of the orbit Y (a Newton Jacobian for a
    shooting reference: its fixed point does not depend on it)."""
    return monodromy_multipliers(problem, Y, omega, w, steps=steps, subsamples=subsamples, return_matrix=True)


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
