"""A small structure with unilateral springs for the harmonic balance: the independent check's other half.

:class:`LinearStructure` holds M, C, K (speed-independent) in the attributes the harmonic balance reads from a
rotor model; :class:`UnilateralSprings` is the nonlinearity F = sum_j k_j (-g_j)_+ D_j, g = g0 + W q, in numpy
(its own implementation, not the kernel's), with the contact coordinates P spanning W's and D's rows. Together
with :func:`.piecewise.gap_oscillator` (the same oscillator integrated exactly) they check the AFT, the Newton,
the condensation and the monodromy on a system whose periodic solution is known to round-off.

Examples
--------
>>> from .piecewise import gap_oscillator
>>> pb = hb_problem(gap_oscillator(), harmonics=8)
>>> pb.r, pb.N
(1, 17)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from .piecewise import PiecewiseLinear
from .problem import HBProblem


@dataclass
class LinearStructure:
    """M q'' + C q' + K q = f0, independent of the spin (the harmonic balance's ``model`` interface)."""

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    f0: np.ndarray

    def __post_init__(self) -> None:
        self.params = SimpleNamespace(imbalance=SimpleNamespace(me=0.0))
        self.D = self.C

    @property
    def n_dofs(self) -> int:
        return self.M.shape[0]

    def G(self, omega: float) -> np.ndarray:
        return np.zeros_like(self.M)

    def K_omega(self, omega: float) -> np.ndarray:
        return self.K

    def force(self, omega: float, me: float | None = None) -> np.ndarray:
        return self.f0

    @property
    def M_inv(self) -> np.ndarray:
        return np.linalg.inv(self.M)


class UnilateralSprings:
    """F = sum_j k_j (-g_j)_+ D_j^T, g = g0 + W q, in contact coordinates y = P q (no friction, no surface)."""

    def __init__(self, W: np.ndarray, D: np.ndarray, g0: np.ndarray, k: np.ndarray):
        self.W, self.D = np.atleast_2d(W).astype(float), np.atleast_2d(D).astype(float)
        self.g0_rows, self.k = np.atleast_1d(g0).astype(float), np.atleast_1d(k).astype(float)
        _, s, Vt = np.linalg.svd(np.vstack([self.W, self.D]), full_matrices=False)
        self.P = np.ascontiguousarray(Vt[: int(np.sum(s > 1e-12 * s[0]))])
        self.Wy, self.Dy = self.W @ self.P.T, self.D @ self.P.T  # (s, r): the rows in contact coordinates
        self.g0 = float(self.g0_rows[0])

    def set_clearance(self, g0: float) -> None:
        """Shift every gap by the change of the first one's clearance."""
        self.g0_rows = self.g0_rows + (float(g0) - self.g0)
        self.g0 = float(g0)

    def batch(self, y, yd, omega, phi, jacobians=True):
        g = self.g0_rows[None] + y @ self.Wy.T  # (m, s)
        pen = np.maximum(-g, 0.0)
        F = (pen * self.k) @ self.Dy  # (m, r)
        J = Jv = None
        if jacobians:
            on = (g < 0).astype(float) * self.k  # dF_j/dg_j = -k_j where touching
            J = -np.einsum("ms,su,sv->muv", on, self.Dy, self.Wy)
            Jv = np.zeros_like(J)
        return F, J, Jv, int(np.count_nonzero((g < 0).any(axis=1)))


def hb_problem(system: PiecewiseLinear, harmonics: int, samples: int | None = None) -> HBProblem:
    """The harmonic balance of a piecewise-linear system forced at its single frequency (no surface terms): its
    force harmonics become the balance's external load, its springs a :class:`UnilateralSprings`."""
    if system.nu.size != 1 or np.any(system.c):
        raise ValueError("hb_problem: one forcing frequency and no gap harmonics; accepted: a gap oscillator")
    st = LinearStructure(system.M, system.C, system.K, system.f0)
    ext = np.zeros((2 * harmonics + 1, system.n))
    ext[1] = system.F[:, 0].real  # Re(F e^{i nu t}) = F_r cos - F_i sin
    ext[2] = -system.F[:, 0].imag
    nl = UnilateralSprings(system.W, system.D, system.g0, system.k)
    return HBProblem(st, None, harmonics, samples, me=0.0, external=ext, nonlinearity=nl)


def period_of(system: PiecewiseLinear) -> float:
    return 2 * math.pi / float(system.nu[0])
