"""Autonomous harmonic balance (rotorub_model/analyses/harmonic/autonomous.py): the orbits past the Hopf point
(3D) and past the switch (2D), whose frequency is an unknown, against references that share no code with the
balance (a DOP853 shooting at rtol 1e-12; the exact piecewise-linear 2D orbit), and the central-difference
shooting of analyses/continuation/periodic.py converging to them as dt^2. The references' states are those of
agreement.json (validation.py), re-checked here as fixed points of their own flows."""

from __future__ import annotations

import math

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from rotorub_model.analyses.continuation.branch import continue_static
from rotorub_model.analyses.continuation.equilibria import Equilibria
from rotorub_model.analyses.harmonic.autonomous import (
    hopf_start,
    is_trivial,
    newton_autonomous,
    section_phase,
    seed_from_samples,
)
from rotorub_model.analyses.harmonic.continuation import continue_hb
from rotorub_model.analyses.harmonic.piecewise import reference_2d
from rotorub_model.analyses.harmonic.problem import HBProblem
from rotorub_model.analyses.harmonic.reference import TightFlow
from rotorub_model.analyses.harmonic.stability import monodromy_multipliers
from rotorub_model.analyses.harmonic.surface import CasingForcing
from rotorub_model.analyses.harmonic.validation import cd_shoot, load_agreement, resized
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError


@pytest.fixture(autouse=True)
def one_thread():
    with threadpool_limits(limits=1):
        yield


@pytest.fixture(scope="module")
def hopf(ref_model):
    """The 3D Hopf point at 3.3 Omega_ref and the record of its orbit at g0 = 0.3323 mm."""
    om = 3.3 * ref_model.params.normalisation.omega_ref
    eq = Equilibria(ref_model, "3D")
    h = continue_static(eq, "g0", om, 0.36e-3, 0.32e-3).of_kind("hopf")[0].point
    return eq, om, h, load_agreement()["autonomous_3d"]


def test_hb_from_the_hopf_point_meets_the_tight_reference(ref_model, hopf):
    """The HB branch continued from the Hopf point alone (no shooting seed) reaches g0 = 0.3323 mm; at H = 24 its
    period is the DOP853 reference's to 1e-9 and its orbit to 1e-6 of the orbit's range (measured 4e-11,
    2.1e-7); the recorded reference is still a fixed point of the tight flow."""
    m = ref_model
    eq, om, h, rec = hopf
    g0 = rec["g0_m"]
    pb = HBProblem(m, eq.contact(h.g0), 8)
    q = eq.solve(om, h.g0)
    mu, v = eq.refine(q, om, h.g0, h.mu)
    Y0, w0, tangent = hopf_start(pb, q, om, mu, v)
    br = continue_hb(pb, "g0", h.g0, g0, om, Y0=Y0, autonomous=True, w0=w0, start_tangent=tangent, stability=False)
    assert br.complete and abs(br.points[-1].g0 - g0) < 1e-12
    pb24 = HBProblem(m, eq.contact(g0), 24)
    r = newton_autonomous(pb24, resized(br.points[-1].Y, pb24), br.points[-1].w, om, tol=1e-12)
    assert r.converged
    ref = rec["reference"]
    x0, T = np.array(ref["x0"]), ref["period_s"]
    flow = TightFlow(m, eq.contact(g0), om)
    assert np.abs(flow.flow(x0, T) - x0).max() <= 1e-9 * np.abs(x0).max()
    assert abs(2 * math.pi / r.w / T - 1) < 1e-9
    dof = m.dofs.index(rec["section_dof"])
    Q = pb24.full(r.Y, om, r.w)
    tau0 = section_phase(pb24, Q, dof)
    tt = np.linspace(0.0, T, 64, endpoint=False)
    from rotorub_model.analyses.harmonic.reference import TightOrbit

    qref = TightOrbit(x0, T, True, 0.0, 0, 0).sample(flow, tt)
    qhb = pb24.basis.evaluate(Q, tau0 + r.w * tt)
    assert np.abs(qhb - qref).max() <= 1e-6 * np.ptp(qref, axis=0).max()
    # the trivial multiplier removed, the orbit is stable, as the shooting branch says (0.99934)
    fl = monodromy_multipliers(pb24, r.Y, om, r.w, autonomous=True)
    assert fl.stable and fl.largest == pytest.approx(rec["shooting_branch_256"]["largest_multiplier"], abs=1e-4)


def test_cd_shooting_converges_to_the_reference_as_dt_squared(hopf):
    """periodic.py's shooting (its CD flow and section) at 256 and 512 steps: the period's error falls by 4."""
    eq, om, h, rec = hopf
    ref = rec["reference"]
    dof = eq.model.dofs.index(rec["section_dof"])
    errs = [cd_shoot(eq, om, rec["g0_m"], np.array(ref["x0"]), ref["period_s"], dof, N)[0] / ref["period_s"] - 1
            for N in (256, 512)]
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.05)  # measured 4.00
    assert abs(errs[0]) == pytest.approx(abs({r["steps"]: r for r in rec["cd_rows"]}[256]["period"]), rel=1e-2)


def test_2d_autonomous_hb_equals_the_exact_orbit(ref_model):
    """2D past the switch (g0 = 0.33 mm, 3.3 Omega_ref): the HB seeded from the CD shooting orbit (256 steps) lands
    on the exact piecewise-linear orbit: period to 1e-7, orbit to 3e-6 at H = 40 (measured 1.8e-8, 1.4e-6)."""
    m = ref_model
    rec = load_agreement()["autonomous_2d"]
    om = rec["speed"] * m.params.normalisation.omega_ref
    g0 = rec["g0_m"]
    eq = Equilibria(m, "2D")
    c = eq.contact(g0)
    sysm = reference_2d(m, c, om)
    dof = m.dofs.index(rec["section_dof"])
    ex = sysm.shoot_autonomous(np.array(rec["exact"]["x0"]), rec["exact"]["period_s"], dof)
    assert ex.converged and ex.iterations <= 2 and ex.events >= 2
    T_cd, x_cd, q_cd, _ = cd_shoot(eq, om, g0, ex.x0, ex.period, dof, 256)
    pb = HBProblem(m, c, 40)
    Y0 = seed_from_samples(pb, np.vstack([x_cd[: m.n_dofs], q_cd[:-1]]))
    r = newton_autonomous(pb, Y0, 2 * math.pi / T_cd, om, tol=1e-12)
    assert r.converged
    assert abs(2 * math.pi / r.w / ex.period - 1) < 1e-7
    Q = pb.full(r.Y, om, r.w)
    tt = np.linspace(0.0, ex.period, 512, endpoint=False)
    qex = sysm.sample(ex.segments, tt)
    qhb = pb.basis.evaluate(Q, section_phase(pb, Q, dof) + r.w * tt)
    assert np.abs(qhb - qex).max() <= 3e-6 * np.ptp(qex, axis=0).max()
    assert monodromy_multipliers(pb, r.Y, om, r.w, autonomous=True).largest == pytest.approx(
        np.abs(ex.multipliers(autonomous=True)).max(), abs=1e-5)


def test_autonomous_bad_input_and_the_trivial_solution(ref_model):
    m = ref_model
    om = 3.3 * m.params.normalisation.omega_ref
    forced = HBProblem(m, make_contact(m, "2D", g0=0.5e-3), 6, forcing=CasingForcing.lobe(2, 1e-4))
    with pytest.raises(ParameterError, match="round casing"):
        newton_autonomous(forced, forced.linear_start(om, om), 300.0, om)
    pb = HBProblem(m, make_contact(m, "2D", g0=0.33e-3), 6)
    with pytest.raises(ParameterError, match="autonomous: needs"):
        continue_hb(pb, "g0", 0.33e-3, 0.3e-3, om, autonomous=True)
    # the static solution solves the autonomous balance for any w: Newton from a speck of an orbit that lands
    # there is not called converged
    Y = pb.linear_start(om, om).reshape(pb.basis.size, pb.r)
    assert is_trivial(pb, Y.ravel())
    Y[1] += 1e-18
    r = newton_autonomous(pb, Y.ravel(), 300.0, om)
    assert not r.converged or not is_trivial(pb, r.Y)
