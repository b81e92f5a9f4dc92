"""The truncated Fourier basis of a periodic response and its alternating frequency-time (AFT) maps.

A T-periodic signal x(t), T = 2 pi / w, is held by its 2H + 1 real coefficients

    x(t) = X_0 + sum_{k=1..H} (X_ck cos k tau + X_sk sin k tau),    tau = w t,

stacked harmonic by harmonic: [X_0, X_c1, X_s1, ..., X_cH, X_sH] (each a vector of the signal's
components). ``E`` (m x 2H+1) evaluates it at m equally spaced samples tau_i = 2 pi i / m, ``dE`` its
derivative in tau (the time derivative is w dE), and ``P`` (2H+1 x m) is the discrete Fourier transform
back: P E = I exactly for m > 2H (the samples' trigonometric sums are orthogonal).

Samples. A contact force is continuous with a kink (2D point law: dF/dq jumps) or with a jump of its
second derivative (3D chord law) where a blade enters contact, so its Fourier coefficients decay only
like k^-2 or k^-3 and the samples alias what lies beyond m/2 back onto the kept harmonics. The rule here:
m is the smallest power of two >= ``SAMPLES_PER_HARMONIC`` H, and at least ``MIN_SAMPLES``: 16 samples per
kept harmonic put the first aliased harmonic at 8 H, where the force's spectrum has fallen by 64 (2D) to
512 (3D) from harmonic H (the convergence study in docs/THEORY.md section 8 measures what this costs).

Examples
--------
>>> import numpy as np
>>> b = HarmonicBasis(3)
>>> b.m, b.size
(64, 7)
>>> x = np.array([1.0, 0.5, -0.2, 0, 0, 0.1, 0])          # 1 + 0.5 cos - 0.2 sin + 0.1 cos 3
>>> bool(np.allclose(b.P @ (b.E @ x), x))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError

SAMPLES_PER_HARMONIC = 16
MIN_SAMPLES = 64
MAX_HARMONICS = 200


def samples_for(harmonics: int) -> int:
    """The rule: the smallest power of two >= 16 H, and >= 64."""
    need = max(MIN_SAMPLES, SAMPLES_PER_HARMONIC * int(harmonics))
    return 1 << int(math.ceil(math.log2(need)))


@dataclass
class HarmonicBasis:
    """H harmonics on m samples (default: :func:`samples_for`)."""

    harmonics: int
    samples: int | None = None
    E: np.ndarray = field(init=False, repr=False)
    dE: np.ndarray = field(init=False, repr=False)
    P: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        H = self.harmonics
        if not (isinstance(H, int | np.integer) and 1 <= H <= MAX_HARMONICS):
            raise ParameterError(f"harmonics: {H!r} out of range; accepted range [1, {MAX_HARMONICS}] (an integer)")
        self.harmonics = int(H)
        m = samples_for(H) if self.samples is None else self.samples
        if not (isinstance(m, int | np.integer) and m >= 2 * H + 2):
            raise ParameterError(f"samples: {m!r} out of range; accepted: an integer >= 2 H + 2 = {2 * H + 2} "
                                 f"(the rule here gives {samples_for(H)})")
        self.samples = int(m)
        tau = self.tau
        k = np.arange(1, H + 1)
        E = np.empty((m, 2 * H + 1))
        dE = np.zeros((m, 2 * H + 1))
        E[:, 0] = 1.0
        E[:, 1::2] = np.cos(np.outer(tau, k))
        E[:, 2::2] = np.sin(np.outer(tau, k))
        dE[:, 1::2] = -k * E[:, 2::2]
        dE[:, 2::2] = k * E[:, 1::2]
        self.E, self.dE = E, dE
        w = np.full(2 * H + 1, 2.0 / m)
        w[0] = 1.0 / m
        self.P = w[:, None] * E.T

    @property
    def m(self) -> int:
        return int(self.samples)

    @property
    def size(self) -> int:
        """Coefficients per component: 2 H + 1."""
        return 2 * self.harmonics + 1

    @property
    def tau(self) -> np.ndarray:
        """The samples' phases w t_i = 2 pi i / m."""
        return 2 * np.pi * np.arange(self.samples) / self.samples

    def derivative(self) -> np.ndarray:
        """The coefficients' derivative in tau, (2H+1) x (2H+1): d/dtau of the series is the series of D X."""
        H = self.harmonics
        D = np.zeros((2 * H + 1, 2 * H + 1))
        for k in range(1, H + 1):
            D[2 * k - 1, 2 * k] = k  # d/dtau (s sin k tau) = k s cos k tau
            D[2 * k, 2 * k - 1] = -k
        return D

    def to_time(self, X: np.ndarray) -> np.ndarray:
        """Samples (m, ...) of coefficients X (2H+1, ...)."""
        return np.tensordot(self.E, X, axes=1)

    def to_coefficients(self, x: np.ndarray) -> np.ndarray:
        """Coefficients (2H+1, ...) of samples x (m, ...)."""
        return np.tensordot(self.P, x, axes=1)

    def amplitudes(self, X: np.ndarray) -> np.ndarray:
        """|X_k| per harmonic k = 0..H, (H+1, ...): the mean's magnitude, then sqrt(X_ck^2 + X_sk^2)."""
        out = np.empty((self.harmonics + 1, *X.shape[1:]))
        out[0] = np.abs(X[0])
        out[1:] = np.hypot(X[1::2], X[2::2])
        return out

    def evaluate(self, X: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The series at any phases tau (n_tau, ...)."""
        tau = np.atleast_1d(np.asarray(tau, dtype=float))
        k = np.arange(1, self.harmonics + 1)
        B = np.empty((tau.size, self.size))
        B[:, 0] = 1.0
        B[:, 1::2] = np.cos(np.outer(tau, k))
        B[:, 2::2] = np.sin(np.outer(tau, k))
        return np.tensordot(B, X, axes=1)
