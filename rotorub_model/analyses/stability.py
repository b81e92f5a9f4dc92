"""Stability of a balanced static solution (eq. 11).

The perturbation obeys M q'' + (D + G(Omega) - J_v) q' + (K(Omega) - J_q) q = 0, with J_q and
J_v the contact force's Jacobians in q and q' at the static solution (J_v: the damping of the
regularised friction, zero at tip speeds far above contact.slip_velocity).
The solution is unstable if an eigenvalue of the first-order system has a positive
real part. Indicators: the largest real part and the paper's "sum of positive real
parts" (each complex-conjugate pair counted once, i.e. the sum over modes), plus
the unstable modes with their rotating-frame frequency and dominant dofs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import ContactModel
from ..structure.model import Model
from .linear import first_order

# A real part below this (1/s) is round-off of a neutral mode, not an instability.
RE_TOL = 1e-6


@dataclass
class StabilityResult:
    eigenvalues: np.ndarray  # one per mode (Im >= 0), sorted by decreasing real part
    max_real: float
    sum_positive_real: float
    unstable_modes: list[dict]

    @property
    def stable(self) -> bool:
        return self.max_real <= RE_TOL

    def summary(self) -> dict:
        return {
            "max_real_part": self.max_real,
            "sum_positive_real_parts": self.sum_positive_real,
            "stable": self.stable,
            "unstable_modes": self.unstable_modes,
        }


def stability_indicators(model: Model, contact: ContactModel, omega: float, q0: np.ndarray) -> tuple[float, float]:
    """(largest real part, sum of positive real parts over modes) of the system linearised about q0: what
    a map cell needs, from the eigenvalues alone (a third of the cost of the eigenvectors too)."""
    J, Jv = contact.jacobians(q0, omega)
    lam = np.linalg.eigvals(first_order(model, omega, J, Jv))
    lam = lam[lam.imag >= -1e-9 * np.maximum(1.0, np.abs(lam))]  # a complex pair once, real ones once
    pos = lam.real > RE_TOL
    return float(lam.real.max()), float(lam.real[pos].sum())


def stability_of(
    model: Model, contact: ContactModel, omega: float, q0: np.ndarray, n_dominant: int = 3
) -> StabilityResult:
    """Eigen-analysis of the system linearised about the static solution q0."""
    J, Jv = contact.jacobians(q0, omega)
    A = first_order(model, omega, J, Jv)
    lam, vec = np.linalg.eig(A)
    keep = lam.imag >= -1e-9 * np.maximum(1.0, np.abs(lam))
    # real eigenvalues appear once; complex pairs once (Im >= 0)
    lam, vec = lam[keep], vec[: model.n_dofs, keep]
    order = np.argsort(-lam.real)
    lam, vec = lam[order], vec[:, order]
    pos = lam.real > RE_TOL
    unstable = []
    for i in np.flatnonzero(pos):
        e = np.abs(vec[:, i]) ** 2 * np.diag(model.M)
        top = np.argsort(-e)[:n_dominant]
        unstable.append(
            {
                "real_part": float(lam[i].real),
                "frequency_hz": float(abs(lam[i].imag) / (2 * np.pi)),
                "dominant_dofs": [model.dofs[k] for k in top],
            }
        )
    return StabilityResult(lam, float(lam.real.max()), float(lam.real[pos].sum()), unstable)
