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
