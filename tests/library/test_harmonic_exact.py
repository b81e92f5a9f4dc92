"""The harmonic balance against exact periodic solutions (rotorub_model/analyses/harmonic/piecewise.py,
oscillator.py): a gap oscillator integrated in closed form between contact events, and the reference's 2D law,
which is piecewise linear. The numbers are those of agreement.json (validation.py), quoted and re-measured."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from threadpoolctl import threadpool_limits

from rotorub_model.analyses.harmonic.continuation import continue_hb
from rotorub_model.analyses.harmonic.orbit import OrbitView
from rotorub_model.analyses.harmonic.oscillator import hb_problem
from rotorub_model.analyses.harmonic.piecewise import gap_oscillator, reference_2d
from rotorub_model.analyses.harmonic.problem import HBProblem, newton
from rotorub_model.analyses.harmonic.stability import monodromy_multipliers
from rotorub_model.analyses.harmonic.surface import CasingForcing
from rotorub_model.analyses.harmonic.validation import AGREEMENT_JSON, load_agreement, resized
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError

G0 = 0.5e-3
OVAL = CasingForcing.lobe(2, 0.15e-3)


@pytest.fixture(autouse=True)
def one_thread():
    with threadpool_limits(limits=1):
        yield


@pytest.fixture(scope="module")
def oscillator_orbit():
    osc = gap_oscillator()
    nu = float(osc.nu[0])
    T = 2 * math.pi / nu
    x = np.zeros(4)
    for _ in range(60):
        x = osc.flow(x, T, period=T)[0]
    return osc, osc.shoot_forced(nu, x)


def test_exact_flow_is_the_ode(oscillator_orbit):
    """The closed-form flow against a tight Runge-Kutta of the same vector field, and its monodromy against
    finite differences (no saltation: the spring enters at zero force)."""
    osc, orb = oscillator_orbit
    T = orb.period
    assert orb.converged and orb.events == 2 and orb.residual < 1e-12
    sol = solve_ivp(lambda t, x: osc.rhs(x, t), (0, T), orb.x0, method="DOP853", rtol=1e-12, atol=1e-15)
    assert np.abs(sol.y[:, -1] - orb.x0).max() <= 1e-9 * np.abs(orb.x0).max()
    h = 1e-8
    J = np.column_stack([(osc.flow(orb.x0 + h * e, T, period=T)[0] - osc.flow(orb.x0 - h * e, T, period=T)[0]) / (2 * h)
                         for e in np.eye(4)])
    assert np.abs(J - orb.monodromy).max() <= 1e-6 * np.abs(orb.monodromy).max()


def test_hb_of_the_gap_oscillator_converges_to_the_exact_orbit(oscillator_orbit):
    """Reached by continuation in the gap from no contact (no seed from the exact orbit); the orbit error falls
    as the harmonics grow (H^-2.5: the contact's kink), the multiplier agrees once the monodromy's steps do."""
    osc, orb = oscillator_orbit
    nu = float(osc.nu[0])
    tt = np.linspace(0.0, orb.period, 2048, endpoint=False)
    qex = osc.sample(orb.segments, tt)
    scale = np.ptp(qex, axis=0).max()
    br = continue_hb(hb_problem(gap_oscillator(gap=0.05), 16), "g0", 0.05, 1e-3, nu, stability=False)
    assert br.complete
    errs = {}
    for H in (16, 64):
        pb = hb_problem(osc, H)
        r = newton(pb, resized(br.points[-1].Y, pb), nu, nu, tol=1e-12)
        assert r.converged
        errs[H] = np.abs(pb.basis.evaluate(pb.full(r.Y, nu, nu), nu * tt) - qex).max() / scale
    rec = {row["H"]: row for row in load_agreement()["oscillator"]["rows"]}
    assert errs[16] < 2e-3 and errs[64] < 5e-5  # measured 8.7e-4, 2.4e-5
    assert errs[64] == pytest.approx(rec[64]["orbit"], rel=1e-3)
    fl = monodromy_multipliers(pb, r.Y, nu, nu, steps=16 * pb.basis.m)
    assert abs(fl.largest - np.abs(orb.multipliers()).max()) < 1e-4  # measured 7e-6


@pytest.fixture(scope="module")
def exact_2d(ref_model):
    """The 2D reference with the oval casing at 3.25 Omega_ref (a stable rub, 10 contact events a period)."""
    m = ref_model
    om = 3.25 * m.params.normalisation.omega_ref
    c = make_contact(m, "2D", g0=G0)
    sysm = reference_2d(m, c, om, OVAL)
    pb = HBProblem(m, c, 10, forcing=OVAL)
    Y = newton(pb, pb.linear_start(om, om), om, om).Y
    b = pb.basis
    Q = pb.full(Y, om, om)
    x0 = np.concatenate([b.evaluate(Q, np.array([0.0]))[0], om * b.evaluate(b.derivative() @ Q, np.array([0.0]))[0]])
    return m, c, om, sysm, sysm.shoot_forced(om, x0), Y


def test_piecewise_2d_law_is_the_kernels(ref_model):
    """The independent re-implementation of the 2D law (penalty on affine gaps, the surface's offset and lobes,
    saturated friction) equals the kernel's force at random states and frame angles."""
    m = ref_model
    om = 3.25 * m.params.normalisation.omega_ref
    c = make_contact(m, "2D", g0=G0)
    f = CasingForcing(offset=(0.05e-3, 0.02e-3), lobes={2: (0.15e-3, 0.3), 3: (0.05e-3, 1.0), 4: (0.02e-3, 2.0)})
    sysm = reference_2d(m, c, om, f)
    pb = HBProblem(m, c, 8, forcing=f)
    rng = np.random.default_rng(3)
    touched = 0
    for _ in range(6):
        q = rng.standard_normal(m.n_dofs) * 3e-4
        t = rng.uniform(0, 0.03)
        F = pb.kernel_batch((pb.P @ q)[None], None, om, np.array([om * t]), False)[0][0]
        g = sysm.gaps(np.concatenate([q, np.zeros(m.n_dofs)])[:, None], np.array([t]))[:, 0]
        touched += int((g < 0).sum())
        assert np.abs(pb.P @ ((np.maximum(-g, 0) * sysm.k) @ sysm.D) - F).max() <= 1e-13 * max(np.abs(F).max(), 1.0)
    assert touched > 0
    with pytest.raises(ParameterError, match="accepted: 2D, penalty"):
        reference_2d(m, make_contact(m, "3D", g0=G0), om)


def test_hb_of_the_2d_reference_equals_the_exact_orbit(exact_2d):
    """H = 10: amplitudes within 1e-3 of the exact (the map's setting); H = 40: the orbit within 1e-5 of its range;
    the leading multiplier within 1e-4 (default monodromy grid)."""
    m, c, om, sysm, ex, Y10 = exact_2d
    assert ex.converged and ex.events >= 4
    tt = np.linspace(0.0, ex.period, 4096, endpoint=False)
    qex = sysm.sample(ex.segments, tt)
    rho = np.abs(ex.multipliers()).max()
    for H, tol in ((10, 1e-3), (40, 1e-5)):
        pb = HBProblem(m, c, H, forcing=OVAL)
        r = newton(pb, resized(Y10, pb), om, om, tol=1e-12)
        view = OrbitView(pb, r.Y, om, om, samples=4096)
        err = np.abs(view.q - qex).max() / np.ptp(qex, axis=0).max()
        assert err < tol, (H, err)  # measured 4.1e-4, 4.5e-6
        assert abs(monodromy_multipliers(pb, r.Y, om, om).largest - rho) < 1e-4
    gaps = sysm.gaps(np.vstack([qex.T, np.zeros_like(qex.T)]), tt)
    f_exact = c.k_r * np.maximum(-gaps, 0).max()
    assert view.measures().max_force == pytest.approx(f_exact, rel=1e-5)


def test_agreement_json_is_within_its_bounds():
    """Every bounded row of the recorded agreement table holds (the docs quote these numbers)."""
    d = load_agreement()
    assert AGREEMENT_JSON.exists() and d["table"]
    for row in d["table"]:
        if row["bound"] is not None:
            assert abs(row["value"]) <= row["bound"], row


def test_hb_reaches_1e_6_of_the_exact_2d_orbit(exact_2d):
    """H = 160 (4096 samples): the orbit within 1e-6 of its range, the number agreement.json records."""
    m, c, om, sysm, ex, Y10 = exact_2d
    tt = np.linspace(0.0, ex.period, 4096, endpoint=False)
    qex = sysm.sample(ex.segments, tt)
    pb = HBProblem(m, c, 160, forcing=OVAL)
    r = newton(pb, resized(Y10, pb), om, om, tol=1e-12)
    err = np.abs(OrbitView(pb, r.Y, om, om, samples=4096).q - qex).max() / np.ptp(qex, axis=0).max()
    rec = {row["H"]: row for row in load_agreement()["forced_2d"]["rows"]}[160]["orbit"]
    assert err < 1e-6 and err == pytest.approx(rec, rel=1e-2)  # measured 3.4e-7
