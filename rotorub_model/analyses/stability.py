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
from pathlib import Path

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
            "verdict": self.verdict(),
            "unstable_modes": self.unstable_modes,
        }

    def verdict(self) -> str:
        if self.stable:
            return f"stable: every Re λ ≤ {RE_TOL:g} 1/s (largest {self.max_real:+.3g} 1/s)"
        n = len(self.unstable_modes)
        return (f"unstable: {n} mode{'s' if n != 1 else ''} with Re λ > 0, largest {self.max_real:+.3g} 1/s, "
                f"sum {self.sum_positive_real:.3g} 1/s")

    def draw(self, ax) -> None:
        """The eigenvalues on ``ax``: rotating-frame frequency against the real part on a symmetric log axis (the
        least damped, near Re λ = 0, spread out; its linear band ±1e-3 1/s marked), the unstable ones red."""
        lam = np.asarray(self.eigenvalues)
        bad = lam.real > RE_TOL
        ax.scatter(lam.real[~bad], np.abs(lam.imag[~bad]) / (2 * np.pi), s=14, color="C0", label="Re λ ≤ 0 (damped)")
        if bad.any():
            ax.scatter(lam.real[bad], np.abs(lam.imag[bad]) / (2 * np.pi), s=30, color="C3", marker="D",
                       label="Re λ > 0 (unstable)")
        ax.set_xscale("symlog", linthresh=1e-3)
        # every other decade, labelled at an angle (a symlog axis labels every decade, and they overlap)
        lo, hi = float(lam.real.min()), float(lam.real.max())
        neg = [-(10.0 ** k) for k in range(int(np.ceil(np.log10(-lo))), -4, -2)] if lo < -1e-3 else []
        pos = [10.0 ** k for k in range(-3, int(np.ceil(np.log10(hi))) + 1, 2)] if hi > 1e-3 else []
        ticks = [*neg, 0.0, *pos]
        ax.set_xticks(ticks, [("0" if t == 0 else f"{t:.0e}".replace("e+0", "e").replace("e-0", "e-")) for t in ticks],
                      rotation=40, fontsize=7.5)
        ax.axvspan(-1e-3, 1e-3, color="0.92", zorder=0, label="linear axis within ±1e-3 1/s")
        ax.axvline(0, color="k", lw=0.8)
        ax.set_xlabel("real part Re λ [1/s] (symmetric log axis)")
        ax.set_ylabel("rotating-frame frequency [Hz]")
        ax.set_title(self.verdict(), fontsize=8)
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(alpha=0.3)

    def figure(self):
        from ..plotting import pyplot

        fig, ax = pyplot().subplots(figsize=(6.5, 4), layout="constrained")
        self.draw(ax)
        return fig

    def save(self, out: str | Path, stem: str = "stability") -> dict:
        """``<stem>.png`` and ``<stem>.json`` in ``out``; returns the summary."""
        from ..writing import save_result

        return save_result(self, out, stem)


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
