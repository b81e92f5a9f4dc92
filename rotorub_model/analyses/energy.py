"""Energy balance of a transient: a check that the contact model creates no energy.

In the rotating frame at constant spin speed Omega, with the structure undamped, the
mechanical energy

    E = 1/2 q'^T M q' + 1/2 q^T K(Omega) q + V_c(q)

(K(Omega) symmetric: the gyroscopic matrix does no work; V_c the strain energy of the normal law,
the kernel's: for the penalty law (k_r / l_c) int 1/2 gap(c)^2 over the penetrated chord, 1/2 k_r gap^2 in 2D)
changes only by the friction's power. The drive that holds Omega constant feeds the power
P_drive = -Omega tau_z (tau_z: the contact torque on the rotor about the spin axis), and the
friction dissipates sum_p mu tanh(v_p / v_slip) w_p v_p >= 0, so

    d(E - W_drive)/dt = -dissipation <= 0.

:func:`energy_history` evaluates E and W_drive along a run recorded at every step (central
differences: velocities centred for E, the backward velocity the kernel's friction used for
P_drive); the tests hold E - W_drive to the integrator's own O(dt^2) oscillation.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..contact import ContactModel
from ..structure.model import Model


def contact_potential(contact: ContactModel, Q: np.ndarray) -> np.ndarray:
    """The normal law's strain energy of states Q (m, n) [J] (the kernel's, for every law): its gradient is
    -F_nl without friction."""
    return contact.potential(np.atleast_2d(Q))


def contact_potential_of_gaps(contact: ContactModel, g: np.ndarray) -> np.ndarray:
    """The same from the states' gaps (m, N, P): what a run against a worn liner records (its outputs' gaps
    are to the worn surface, which the model's own gaps(q) do not know)."""
    return contact.potential_of_gaps(g)


@dataclass
class EnergyHistory:
    t: np.ndarray  # [s] times of the states 1..m-2
    energy: np.ndarray  # [J] kinetic + strain (K(Omega)) + contact potential
    drive_work: np.ndarray  # [J] work fed by the drive since the first state
    kinetic: np.ndarray
    contact: np.ndarray

    @property
    def balance(self) -> np.ndarray:
        """E - W_drive: never rises (beyond the integrator's oscillation) if the model creates no energy."""
        return self.energy - self.drive_work

    def largest_rise(self) -> float:
        """The largest rise of E - W_drive over any earlier value [J] (0 when it never rises)."""
        b = self.balance
        return float(np.max(b - np.minimum.accumulate(b))) if b.size else 0.0

    def summary(self) -> dict:
        b = self.balance
        scale = float(np.max(np.abs(self.energy))) if self.energy.size else 0.0
        rise = self.largest_rise()
        return {"t_s": [float(self.t[0]), float(self.t[-1])] if self.t.size else None,
                "energy_start_J": float(self.energy[0]) if b.size else None,
                "energy_end_J": float(self.energy[-1]) if b.size else None,
                "drive_work_J": float(self.drive_work[-1]) if b.size else None,
                "dissipated_J": float(b[0] - b[-1]) if b.size else None,
                "largest_rise_of_balance_J": rise, "largest_rise_relative": rise / scale if scale > 0 else 0.0,
                "verdict": self.verdict()}

    def verdict(self) -> str:
        scale = float(np.max(np.abs(self.energy))) if self.energy.size else 0.0
        rise = self.largest_rise()
        return (f"E - W_drive never rises by more than {rise:.3g} J ({rise / scale:.2g} of the largest energy): "
                "no energy created" if scale > 0 else "no motion")

    def figure(self):
        """E, the drive's work and their difference (which friction can only lower), the verdict in the title."""
        from ..plotting import pyplot

        fig, axes = pyplot().subplots(2, 1, figsize=(8, 5.5), sharex=True, layout="constrained")
        axes[0].plot(self.t, self.energy, lw=1, label="E: kinetic + strain + contact potential")
        axes[0].plot(self.t, self.drive_work, lw=1, label="W_drive: work the drive fed in")
        axes[0].set_ylabel("energy [J]")
        axes[0].legend(fontsize=8)
        axes[1].plot(self.t, self.balance, lw=1, color="k", label="E − W_drive (friction lowers it)")
        axes[1].set_ylabel("E − W_drive [J]")
        axes[1].set_xlabel("time [s]")
        axes[1].legend(fontsize=8)
        for ax in axes:
            ax.grid(alpha=0.3)
        fig.suptitle(f"Energy balance: {self.verdict()}", fontsize=9)
        return fig

    def save(self, out: str | Path, stem: str = "energy") -> dict:
        from ..writing import save_result

        return save_result(self, out, stem)


def energy_history(model: Model, contact: ContactModel, q: np.ndarray, dt: float, omega: float) -> EnergyHistory:
    """Energy and drive work along consecutive states q (m, n) a step dt apart at spin omega."""
    q = np.asarray(q, dtype=float)
    v = (q[2:] - q[:-2]) / (2.0 * dt)
    qm = q[1:-1]
    K = model.K_omega(omega)
    Ks = 0.5 * (K + K.T)
    kinetic = 0.5 * np.einsum("ti,ij,tj->t", v, model.M, v)
    strain = 0.5 * np.einsum("ti,ij,tj->t", qm, Ks, qm)
    vc = contact_potential(contact, qm)
    # the friction the kernel applied at state n used the backward velocity (q_n - q_n-1) / dt
    back = (q[1:] - q[:-1]) / dt
    torque = contact.split_outputs(contact.outputs_array(q[1:], omega, back))["friction_torque"]
    p_drive = -omega * torque  # power the drive feeds to hold the speed, step n -> n+1
    work = np.concatenate([[0.0], np.cumsum(p_drive[:-1] * dt)])[: len(qm)]
    return EnergyHistory(np.arange(1, len(q) - 1) * dt, kinetic + strain + vc, work, kinetic, vc)
