"""Autonomous harmonic balance: the periodic orbits of the rotating frame past a Hopf point, whose frequency is
an unknown, and their comparison with the shooting orbits.

With a round casing the equations of the rotating frame are autonomous (the imbalance is a constant load there),
so an orbit born where the static solution loses stability has its own fundamental w, and any time shift of an
orbit is an orbit. The balance then has one more unknown, w, and one more equation, the **phase condition**: the
sine coefficient of harmonic 1 of one contact coordinate vanishes, Y_s1[i] = 0, i the coordinate whose harmonic 1
is largest (its first harmonic peaks at t = 0). Newton on (Y, w) with the exact dR/dY and dR/dw by central
differences (:func:`.problem.frequency_derivative`); the continuation (:func:`.continuation.continue_hb` with
``autonomous``) follows such orbits in g0 or Omega, from a Hopf point along its critical eigenvector
(:func:`hopf_branch`) as the shooting of :mod:`..continuation.periodic` does. The Floquet multipliers drop the
trivial one (the time shift).

Examples
--------
>>> import numpy as np
>>> from .basis import HarmonicBasis
>>> b = HarmonicBasis(2, 16)
>>> t = b.tau
>>> Y = coefficients_of(b, np.c_[np.cos(t + 0.3), np.sin(t + 0.3)])   # a circle, shifted in time
>>> Z = shift_to_phase(b, Y, 0)
>>> bool(abs(Z[2, 0]) < 1e-12 and abs(Z[1, 0] - 1) < 1e-12)
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from .basis import HarmonicBasis
from .problem import HBProblem, frequency_derivative


@dataclass
class AutonomousResult:
    Y: np.ndarray
    w: float
    converged: bool
    iterations: int
    residual: float  # |R| / scale
    phase: int  # index of the phase condition's coefficient in Y


def phase_index(problem: HBProblem, Y: np.ndarray) -> int:
    """Index in Y (stacked (2H+1, r)) of the sine coefficient of harmonic 1 of the contact coordinate whose
    harmonic 1 is largest: the phase condition holds it at zero."""
    r = problem.r
    Yc = np.asarray(Y).reshape(problem.basis.size, r)
    i = int(np.argmax(np.hypot(Yc[1], Yc[2])))
    return 2 * r + i


def coefficients_of(basis: HarmonicBasis, samples: np.ndarray) -> np.ndarray:
    """Coefficients (2H+1, ...) of one period sampled at the basis' m phases."""
    return basis.to_coefficients(samples)


def shift_to_phase(basis: HarmonicBasis, Y: np.ndarray, coordinate: int) -> np.ndarray:
    """The same orbit with its time origin moved so that harmonic 1 of ``coordinate`` is a pure cosine (its
    sine coefficient zero, its cosine positive): harmonic k turns by k times the phase."""
    Y = np.array(Y, dtype=float)
    theta = math.atan2(Y[2, coordinate], Y[1, coordinate])  # X_c cos + X_s sin = A cos(tau - theta)
    out = Y.copy()
    for k in range(1, basis.harmonics + 1):
        c, s = Y[2 * k - 1], Y[2 * k]
        # x(tau + theta): cos k(tau + theta) = cos k tau cos k theta - sin k tau sin k theta
        ck, sk = math.cos(k * theta), math.sin(k * theta)
        out[2 * k - 1] = c * ck + s * sk
        out[2 * k] = s * ck - c * sk
    return out


def newton_autonomous(problem: HBProblem, Y0: np.ndarray, w0: float, omega: float, phase: int | None = None,
                      tol: float = 1e-10, max_iter: int = 40) -> AutonomousResult:
    """Newton on the autonomous balance (Y, w) at fixed Omega and g0, from (Y0, w0); the start is first moved in
    time to satisfy the phase condition. Backtracking on |R|."""
    if problem.forced:
        raise ParameterError("newton_autonomous: the casing forces the response (offset or lobes); accepted: a "
                             "round casing (an autonomous orbit of the rotating frame)")
    b, r = problem.basis, problem.r
    Y = np.asarray(Y0, dtype=float).reshape(b.size, r)
    phase = phase_index(problem, Y) if phase is None else int(phase)
    Y = shift_to_phase(b, Y, phase - 2 * r).ravel()
    w = float(w0)
    N = problem.N
    scale = max(float(np.abs(Y).max()), abs(problem.g0), 1e-12)

    def system(Y, w):
        ev = problem.evaluate(Y, omega, w)
        R = np.concatenate([ev.R, [Y[phase]]])
        return R, ev

    R, ev = system(Y, w)
    res = float(np.linalg.norm(R)) / scale
    it = 0
    for it in range(1, max_iter + 1):
        if res <= tol:
            return AutonomousResult(Y, w, not is_trivial(problem, Y), it - 1, res, phase)
        A = np.zeros((N + 1, N + 1))
        A[:N, :N] = ev.J
        A[:N, N] = frequency_derivative(problem, Y, omega, w)
        A[N, phase] = 1.0
        try:
            d = np.linalg.solve(A, -R)
        except np.linalg.LinAlgError:
            break
        lam = 1.0
        while lam > 1e-4:
            Yn, wn = Y + lam * d[:N], w + lam * d[N]
            Rn, evn = system(Yn, wn)
            resn = float(np.linalg.norm(Rn)) / scale
            if np.isfinite(resn) and resn < (1 - 1e-4 * lam) * res:
                break
            lam *= 0.5
        else:
            break
        Y, w, R, ev, res = Yn, wn, Rn, evn, resn
    if res <= tol and is_trivial(problem, Y):
        return AutonomousResult(Y, w, False, it, res, phase)
    return AutonomousResult(Y, w, res <= tol, it, res, phase)


TRIVIAL = 1e-9  # an orbit whose harmonics are below this share of its mean is the static solution (any w fits it)


def is_trivial(problem: HBProblem, Y: np.ndarray) -> bool:
    """Whether Y is the static solution (which solves the autonomous balance for any w and phase): its harmonics
    k >= 1 below ``TRIVIAL`` of its mean, or of 1 um."""
    Yc = np.asarray(Y).reshape(problem.basis.size, problem.r)
    return float(np.abs(Yc[1:]).max()) <= TRIVIAL * max(float(np.abs(Yc[0]).max()), 1e-6)


def hopf_start(problem: HBProblem, q_static: np.ndarray, omega: float, mu: complex, v: np.ndarray,
               amplitude_dof: int | None = None) -> tuple[np.ndarray, float, tuple[np.ndarray, float, float]]:
    """(Y0, w0, tangent) of the orbit branch born at a Hopf point: the static solution q_static in harmonic 0,
    w0 = |Im mu|, and the first step along the critical eigenvector v (the first-order system's: its q part),
    harmonic 1 = Re(P v e^{i w t}) turned so that the phase condition holds."""
    b, r = problem.basis, problem.r
    n = problem.n
    vq = np.asarray(v)[:n] if np.asarray(v).size == 2 * n else np.asarray(v)
    y1 = problem.P @ vq
    i = int(np.argmax(np.abs(y1))) if amplitude_dof is None else amplitude_dof
    y1 = y1 * np.exp(-1j * np.angle(y1[i]))
    y1 = y1 / np.abs(y1).max()
    Y0 = np.zeros((b.size, r))
    Y0[0] = problem.P @ q_static
    dY = np.zeros((b.size, r))
    dY[1] = y1.real  # Re(y1 e^{i tau}) = Re y1 cos - Im y1 sin
    dY[2] = -y1.imag
    return Y0.ravel(), abs(mu.imag), (dY.ravel(), 0.0, 0.0)


def section_phase(problem: HBProblem, Q: np.ndarray, dof: int, grid: int = 512) -> float:
    """The phase tau* at which dof's velocity vanishes where the dof is largest: the HB orbit's point on the
    section a shooting takes (q'_dof(0) = 0), to compare orbits whose time origins differ. Q: (2H+1, n)."""
    from scipy.optimize import brentq

    b = problem.basis
    c = Q[:, dof : dof + 1]
    dc = b.derivative() @ c

    def vel(tau: float) -> float:
        return float(b.evaluate(dc, np.array([tau]))[0, 0])

    taus = np.linspace(0.0, 2 * math.pi, grid + 1)
    v = b.evaluate(dc, taus)[:, 0]
    roots = [brentq(vel, taus[i], taus[i + 1], xtol=1e-15) for i in range(grid) if v[i] * v[i + 1] < 0]
    if not roots:
        raise ValueError(f"dof {dof} does not oscillate on this orbit")
    return max(roots, key=lambda t: float(b.evaluate(c, np.array([t]))[0, 0]))


def section_state(problem: HBProblem, Y: np.ndarray, omega: float, w: float, dof: int) -> tuple[float, np.ndarray]:
    """(tau*, x*) the HB orbit's phase and state (q, q') on the section q'_dof = 0 at the dof's largest value."""
    Q = problem.full(Y, omega, w)
    tau = section_phase(problem, Q, dof)
    b = problem.basis
    q = b.evaluate(Q, np.array([tau]))[0]
    v = w * b.evaluate(b.derivative() @ Q, np.array([tau]))[0]
    return tau, np.concatenate([q, v])


def seed_from_samples(problem: HBProblem, q: np.ndarray) -> np.ndarray:
    """Y (raveled) of one period of full states q (N, n) sampled at N equal steps (a settled transient's, a
    shooting orbit's): the contact coordinates' Fourier coefficients up to the problem's H (N > 2 H)."""
    b = HarmonicBasis(problem.H, q.shape[0])
    return b.to_coefficients(np.asarray(q) @ problem.P.T).ravel()
