"""Friction from the sliding velocity of each contact point (issue 12).

The friction force on the blade at point p is -mu tanh(v_p / v_slip) w_p e_t with
v_p = Omega rho_p + S_p q'. Checked here: the direction against the sliding, the exact
Coulomb limit at tip speeds, both Jacobians against finite differences where the tanh is not
saturated, and energy: a free vibration at Omega = 0 never gains energy, and with a drive the
energy minus the drive's work never rises (beyond the integrator's own O(dt^2) oscillation).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rotorub_model.analyses.energy import contact_potential, energy_history
from rotorub_model.analyses.linear import linear_response
from rotorub_model.analyses.transient import run_transient
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model


@pytest.fixture(scope="module")
def model():
    return build_model()


def touching_state(model, form, frac=0.5):
    """A state at the first critical's linear response with about half the points in contact."""
    wref = model.params.normalisation.omega_ref
    q = linear_response(model, 3.4 * wref)
    c = make_contact(model, form)
    g0 = float(np.quantile(-(c.G @ q), frac))
    return c.with_clearance(g0), q


def slow_velocity(model, c, rng, scale):
    """A velocity whose sliding speeds at the points are of order ``scale`` [m/s], both signs."""
    qd = rng.standard_normal(model.n_dofs)
    return qd * scale / np.abs(c.S @ qd).max()


# ------------------------------------------------------------------ direction and limits


@pytest.mark.parametrize("form", ["2D", "3D"])
def test_friction_opposes_the_sliding(model, form):
    c, q = touching_state(model, form)
    rng = np.random.default_rng(3)
    qd = slow_velocity(model, c, rng, 1.0)  # 10 v_slip: tanh = 0.99999...
    fr = c.friction_factors(q, 0.0, qd)
    v = c.sliding_velocity(0.0, qd)
    touching = c.laws(q)[:, 0] > 0
    assert touching.any() and (~touching).any()
    assert np.all(fr[~touching] == 0.0)
    # the force on the blade is -fr w e_t: against the sliding at every point in contact
    assert np.all(np.sign(fr[touching]) == np.sign(v[touching]))
    np.testing.assert_allclose(np.abs(fr[touching]), c.mu * np.tanh(np.abs(v[touching]) / c.v_slip), rtol=1e-14)
    # and both signs occur (the test is not one-sided)
    assert (v[touching] > 0).any() and (v[touching] < 0).any()
    # its power on the generalised velocities is a dissipation
    normal_only = dataclasses.replace(c, mu=0.0)
    p_friction = (c.forces(q, 0.0, qd) - normal_only.forces(q, 0.0, qd)) @ qd
    assert p_friction < 0


@pytest.mark.parametrize("form", ["2D", "3D"])
def test_coulomb_at_tip_speeds_and_none_at_rest(model, form):
    c, q = touching_state(model, form)
    w = 3.4 * model.params.normalisation.omega_ref  # tip speed ~50 m/s = 500 v_slip
    bf = c.blade_forces(q, w)
    np.testing.assert_array_equal(c.friction_factors(q, w)[bf["F_N"] > 0], c.mu)  # tanh saturates to exactly 1
    np.testing.assert_allclose(bf["F_T"], c.mu * bf["F_N"], rtol=1e-14)
    assert c.friction_torque_on_rotor(q, w) < 0
    # a static state at rest in the rotating frame with no spin does not slide: no friction
    at_rest = c.blade_forces(q, 0.0)
    assert np.all(at_rest["F_T"] == 0.0) and at_rest["F_N"].max() > 0
    # spinning backwards (a windmilling rotor turning the wrong way) reverses it
    np.testing.assert_allclose(c.blade_forces(q, -w)["F_T"], -c.mu * bf["F_N"], rtol=1e-14)


# ------------------------------------------------------------------ Jacobians


def fd_jacobians(c, q, omega, qd):
    """Central differences in q (steps that cross no kink of the law) and in q' (smooth)."""
    n = q.size
    g = c.gaps(q).ravel()
    J, Jv = np.zeros((n, n)), np.zeros((n, n))
    for i in range(n):
        gi = np.abs(c.G[:, i])
        e = np.zeros(n)
        if gi.max() > 0.0:
            h = min(1e-8 / gi.max(), 0.01 * np.min(np.abs(g) / np.maximum(gi, 1e-300)))
            e[i] = h
            J[:, i] = (c.forces(q + e, omega, qd) - c.forces(q - e, omega, qd)) / (2 * h)
        si = np.abs(c.S[:, i]).max()
        if si > 0.0:
            h = 1e-4 * c.v_slip / si
            e[:] = 0.0
            e[i] = h
            Jv[:, i] = (c.forces(q, omega, qd + e) - c.forces(q, omega, qd - e)) / (2 * h)
    return J, Jv


@pytest.mark.parametrize("form", ["2D", "3D"])
@pytest.mark.parametrize("omega", [0.0, 0.05, 150.0])
def test_jacobians_match_finite_differences(model, form, omega):
    """dF/dq and dF/dq' at sliding speeds of the order of v_slip (where the tanh bends) and at
    tip speed (where the velocity Jacobian vanishes)."""
    c, q = touching_state(model, form)
    rng = np.random.default_rng(11)
    qd = slow_velocity(model, c, rng, 2.0 * c.v_slip)
    J, Jv = c.jacobians(q, omega, qd)
    np.testing.assert_array_equal(J, c.jacobian(q, omega, qd))
    Jfd, Jvfd = fd_jacobians(c, q, omega, qd)
    scale, vscale = np.abs(J).max(), np.abs(Jv).max()
    assert np.abs(J - Jfd).max() <= 1e-6 * scale
    if omega > 1.0:
        # tip speed >> v_slip: exact Coulomb, no damping, and the stiffness is not symmetric
        assert vscale == 0.0 and np.abs(Jvfd).max() <= 1e-12 * scale
        assert np.abs(J - J.T).max() > 0.01 * scale
    else:
        assert vscale > 0.0
        assert np.abs(Jv - Jvfd).max() <= 1e-6 * vscale
        np.testing.assert_allclose(Jv, Jv.T, rtol=0, atol=1e-12 * vscale)
        assert np.linalg.eigvalsh(Jv).max() <= 1e-12 * vscale  # a damping: negative semi-definite


def test_contact_potential_is_the_normal_force_potential(model):
    """-grad V_c = F_nl without friction (the energy test's bookkeeping is right)."""
    for form in ("2D", "3D"):
        c, q = touching_state(model, form)
        c = dataclasses.replace(c, mu=0.0)
        f = c.forces(q, 0.0)
        rng = np.random.default_rng(2)
        for _ in range(5):
            dq = rng.standard_normal(model.n_dofs)
            dq *= 1e-9 / np.abs(c.G @ dq).max()
            dv = (contact_potential(c, q + dq) - contact_potential(c, q - dq))[0] / 2
            assert dv == pytest.approx(-f @ dq, rel=1e-6)


# ------------------------------------------------------------------ energy


def free_vibration(model, form, omega, mu, dt, t_end=0.3, v_slip=None):
    """A rub from a whirl of the fan disk (0.3 m/s) with the blades' flexure excited, no imbalance."""
    T, _ = model.disk_maps
    rng = np.random.default_rng(1)
    v0 = np.linalg.pinv(T[:2]) @ np.array([0.3, 0.1])
    b = model.slices["blades"]
    v0[b] += 0.05 * rng.standard_normal(b.stop - b.start)
    c = make_contact(model, form, g0=0.2e-3, mu=mu)
    if v_slip is not None:
        c = dataclasses.replace(c, v_slip=v_slip)
    # the energy check needs the whole rub, deeper than a liner (max_penetration 3 mm): the penalty law
    # conserves energy at any depth
    r = run_transient(model, c, omega, t_end=t_end, me=0.0, q0=np.zeros(model.n_dofs), v0=v0, record_dt=1e-12,
                      t_ramp=0.0, dt=dt, max_penetration=0.01)
    assert not r.penetration_limit_hit and r.outputs["F_N"].max() > 100.0  # a real rub
    q = np.vstack([np.zeros(model.n_dofs), r.q])
    e = energy_history(model, c, q, r.dt, omega)
    b = e.balance
    rise = float(np.max(b - np.minimum.accumulate(b)) / b[0])  # largest rise above the running minimum
    return e, rise


@pytest.mark.parametrize("form", ["2D", "3D"])
@pytest.mark.parametrize("omega", [0.0, 1.0])
def test_friction_never_creates_energy(undamped, form, omega):
    """Omega = 0: the energy of a free vibration with contact never rises; Omega = 1 rad/s (tip
    speed ~1 m/s, of the order of the vibration's: the sliding reverses): energy minus the
    drive's work never rises. 'Never' up to the integrator's own oscillation, measured on the
    same run without friction, which shrinks as dt^2."""
    dt = 5e-5
    _, rise0 = free_vibration(undamped, form, omega, 0.0, dt)
    e, rise = free_vibration(undamped, form, omega, 0.3, dt)
    b = e.balance
    assert rise <= rise0, (rise, rise0)
    assert rise0 < 2e-4  # the oscillation is small at this step...
    _, rise0_half = free_vibration(undamped, form, omega, 0.0, dt / 2)
    assert rise0_half == pytest.approx(rise0 / 4, rel=0.15)  # ...and it is the scheme's O(dt^2)
    assert b[-1] < 0.9 * b[0]  # friction did dissipate (2D at rest: 20 %, 3D: 92 % in 0.3 s)
    if omega:
        assert e.drive_work[-1] > b[0]  # and the drive did feed it


def test_energy_test_catches_a_friction_that_pushes(undamped):
    """The same check on a law whose friction pushes along the sliding (v_slip < 0 flips the tanh)
    fails by far: the energy test can see energy being created."""
    _, rise0 = free_vibration(undamped, "3D", 0.0, 0.0, 5e-5)
    _, rise = free_vibration(undamped, "3D", 0.0, 0.3, 5e-5, t_end=0.05, v_slip=-0.1)
    assert rise > 100 * rise0


# ------------------------------------------------------------------ parameter


def test_slip_velocity_parameter(model):
    c = make_contact(model, "2D", slip_velocity=0.5)
    assert c.v_slip == 0.5
    assert make_contact(model, "2D").v_slip == model.params.contact.slip_velocity == 0.1
    with pytest.raises(ParameterError, match=r"contact\.slip_velocity.*\[0.0001, 10\]"):
        model.params.replace(contact={"slip_velocity": 0.0})
