"""Issue 4 cross-checks: static vs linear, transient vs static and stability,
energy conservation of central differences, the time-step guard."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.analyses.linear import linear_response
from rotorub_model.analyses.stability import stability_of
from rotorub_model.analyses.static import solve_static
from rotorub_model.analyses.transient import (
    CentralDifference,
    all_closed_stiffness,
    critical_time_step,
    run_transient,
)
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model


@pytest.fixture(scope="module")
def model():
    return build_model()


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_static_equals_linear_response_below_contact(model, formulation):
    omega = 2.0 * model.params.normalisation.omega_ref
    q_lin = linear_response(model, omega)
    c = make_contact(model, formulation, g0=0.0)
    g0 = float(-c.gaps(q_lin).min()) + 1e-4  # just above the clearance closure
    st = solve_static(model, c.with_clearance(g0), omega)
    assert st.converged and st.n_contact == 0
    np.testing.assert_allclose(st.q, q_lin, rtol=0, atol=1e-12 * np.abs(q_lin).max())
    # ... and just below it, contact appears and the solution moves
    st2 = solve_static(model, c.with_clearance(g0 - 2e-4), omega)
    assert st2.converged and st2.n_contact >= 1
    assert np.abs(st2.q - q_lin).max() > 1e-3 * np.abs(q_lin).max()


def test_static_residual_is_honest(model):
    omega = 3.4 * model.params.normalisation.omega_ref
    c = make_contact(model, "3D", g0=0.8e-3)
    st = solve_static(model, c, omega)
    r = model.K_omega(omega) @ st.q - c.forces(st.q, omega) - model.force(omega)
    assert st.converged
    assert np.linalg.norm(r) <= 1e-9 * np.linalg.norm(model.force(omega))
    assert st.residual == pytest.approx(np.linalg.norm(r) / np.linalg.norm(model.force(omega)), rel=1e-3, abs=1e-14)


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_an_interference_at_rest_converges(model, formulation):
    """At rest (no imbalance force) with every blade 1 mm into the casing: the forces balance among the blades
    (k_r x 1 mm = 1500 N each in 2D, a generalised force of ~1e-12 N). The residual was measured against the
    stiffness' 1e-12 floor, which round-off cannot reach: 'not converged' after 135 iterations on exact forces
    (a newcomer's run). Measured against the blades' forces it converges at once, and the residual is honest."""
    c = make_contact(model, formulation, g0=-1e-3)
    st = solve_static(model, c, 0.0)
    assert st.converged and st.n_contact == 10 and st.iterations <= 2
    F_N = c.blade_forces(st.q, 0.0)["F_N"]
    if formulation == "2D":
        np.testing.assert_allclose(F_N, model.params.contact.k_r * 1e-3, rtol=1e-9)
    r = model.K_omega(0.0) @ st.q - c.forces(st.q, 0.0)
    assert np.linalg.norm(r) <= 1e-10 * F_N.sum()


def _modal_amplitude(model, omega, K_extra, C_extra, lam, q, v):
    """Projection of the state (q, v) on the eigenvector of lam (left eigenvector)."""
    from rotorub_model.analyses.linear import first_order

    A = first_order(model, omega, K_extra, C_extra)
    w, vl = np.linalg.eig(A.T)
    k = np.argmin(np.abs(w - lam))
    return vl[:, k] @ np.concatenate([q, v], axis=-1).T


def _unstable_2d_point(model):
    """The most unstable 2D static point of a small grid around the first critical."""
    best = None
    for speed in (3.3, 3.4, 3.45):
        for g0 in (0.05e-3, 0.2e-3, 0.4e-3, 0.8e-3):
            omega = speed * model.params.normalisation.omega_ref
            c = make_contact(model, "2D", g0=g0)
            st = solve_static(model, c, omega)
            if st.converged and st.n_contact > 0 and np.min(np.abs(c.gaps(st.q))) > 1e-7:
                sb = stability_of(model, c, omega, st.q)
                if not sb.stable and (best is None or sb.max_real > best[3].max_real):
                    best = (omega, c, st, sb)
    if best is None:
        pytest.skip("no unstable 2D static point among the candidates")
    return best


def test_unstable_2d_transient_grows_at_eigenvalue_rate(model):
    omega, c, st, sb = _unstable_2d_point(model)
    from rotorub_model.analyses.linear import first_order

    Kx, Cx = c.jacobians(st.q, omega)
    lam_all, vec = np.linalg.eig(first_order(model, omega, Kx, Cx))
    k = np.argmax(lam_all.real)
    lam, v = lam_all[k], vec[:, k]
    assert lam.real == pytest.approx(sb.max_real)
    n = model.n_dofs
    g_static = c.gaps(st.q)
    dq = np.real(v[:n])
    # perturb small enough that no blade changes state while the mode grows 20-fold
    eps = 0.005 * np.min(np.abs(g_static)) / np.max(np.abs(c.G @ v[:n]))
    assert np.min(np.abs(g_static)) > 1e-7, "a blade sits exactly on the casing: pick another point"
    t_end = np.log(20.0) / lam.real
    res = run_transient(model, c, omega, t_end=t_end, t_ramp=0.0, q0=st.q + eps * dq,
                        v0=eps * np.real(lam * v[:n]), record_dt=1e-9)
    assert not res.penetration_limit_hit
    for qi in res.q[:: max(1, len(res.q) // 200)]:
        assert np.all((c.gaps(qi) < 0) == (g_static < 0)), "contact set changed: not a linear test"
    qd = res.q - st.q
    vel = np.gradient(qd, res.t, axis=0)
    a = np.abs(_modal_amplitude(model, omega, Kx, Cx, lam, qd, vel))
    i0, i1 = len(res.t) // 4, len(res.t) - 2
    rate = np.log(a[i1] / a[i0]) / (res.t[i1] - res.t[i0])
    assert rate == pytest.approx(lam.real, rel=0.2), f"growth {rate:.4g} 1/s vs eigenvalue {lam.real:.4g} 1/s"


def test_central_differences_conserve_energy(undamped):
    m = undamped
    c = make_contact(m, "2D", g0=1.0)  # never touches
    K = m.K
    rng = np.random.default_rng(1)
    q0 = 1e-4 * rng.normal(size=m.n_dofs)
    devs = []
    for frac in (0.2, 0.1):
        cd = CentralDifference(m, c, dt=None)
        dt = frac * cd.dt_limit
        cd = CentralDifference(m, c, dt=dt, t_ramp=1.0)
        cd.q[:] = q0
        cd.q_prev[:] = q0
        n = int(round(0.05 / dt))
        rec = np.zeros((n, m.n_dofs))
        cd.advance(n, 0.0, 0.0, rec_every=1, rec_q=rec)
        qs = np.vstack([q0, rec])
        v = (qs[2:] - qs[:-2]) / (2 * dt)
        qm = qs[1:-1]
        E = 0.5 * np.einsum("ti,ij,tj->t", v, m.M, v) + 0.5 * np.einsum("ti,ij,tj->t", qm, K, qm)
        # the scheme's exact invariant (Stormer-Verlet on a linear system)
        vh = (qs[1:] - qs[:-1]) / dt
        qb = 0.5 * (qs[1:] + qs[:-1])
        Mt = m.M - 0.25 * dt**2 * K
        Ex = 0.5 * np.einsum("ti,ij,tj->t", vh, Mt, vh) + 0.5 * np.einsum("ti,ij,tj->t", qb, K, qb)
        assert np.ptp(Ex) <= 1e-9 * Ex.max()
        devs.append(np.ptp(E) / E.max())
    assert devs[0] < 0.2 and devs[1] < devs[0] / 3.0, devs  # O(dt^2): halving dt divides it by ~4


def test_time_step_guard(undamped):
    m = undamped
    c = make_contact(m, "3D", g0=0.5e-3, mu=0.0)  # friction would make the closed system flutter
    limit = critical_time_step(m, c, 0.0)
    with pytest.raises(ParameterError, match=r"dt: .* exceeds the central-difference stability limit"):
        CentralDifference(m, c, dt=1.02 * limit)
    with pytest.raises(ParameterError, match="dt"):
        CentralDifference(m, c, dt=-1.0)
    # the guard is right: with every contact closed, just below the limit stays bounded, just above blows up
    K = m.K + all_closed_stiffness(c, 0.0)
    q0 = np.random.default_rng(2).normal(size=m.n_dofs) * 1e-6
    growth = []
    for f in (0.99, 1.01):
        dt = f * limit
        Ainv = np.linalg.inv(m.M / dt**2)
        q, qp = q0.copy(), q0.copy()
        K2, Cm1 = 2 * m.M / dt**2 - K, m.M / dt**2
        with np.errstate(over="ignore", invalid="ignore"):  # above the limit it is meant to blow up
            for _ in range(20000):  # the bare linear scheme (no contact force: K holds the closed contacts)
                q, qp = Ainv @ (K2 @ q - Cm1 @ qp), q
        growth.append(np.abs(q).max() / np.abs(q0).max())
    assert growth[0] < 1e3, growth
    assert not np.isfinite(growth[1]) or growth[1] > 1e6, growth


def test_transient_records_outputs(model):
    c = make_contact(model, "3D", g0=0.8e-3)
    res = run_transient(model, c, 3.0 * model.params.normalisation.omega_ref, t_end=0.2, record_dt=1e-2)
    assert res.t.shape[0] == res.q.shape[0] == 20
    np.testing.assert_allclose(res.t, 0.01 * np.arange(1, 21), rtol=1e-12)  # records on the requested grid
    for key in ("F_N", "F_T", "fraction", "gap", "disk_fixed", "casing_fixed", "casing_force_fixed", "friction_torque"):
        assert key in res.outputs
    with pytest.raises(ParameterError, match="t_end"):
        run_transient(model, c, 100.0, t_end=-1)
    with pytest.raises(ParameterError, match="omega"):
        run_transient(model, c, float("nan"))


def test_map_cell_indicators_equal_the_full_stability_analysis(model):
    """The maps' eigenvalue-only path (stability_indicators) gives the same largest real part and
    sum of positive real parts as stability_of, stable and unstable, 2D and 3D."""
    from rotorub_model.analyses.stability import stability_indicators

    seen = set()
    for form in ("2D", "3D"):
        for speed, g0 in ((3.3, 0.2e-3), (3.45, 0.8e-3), (3.4, 0.05e-3)):
            omega = speed * model.params.normalisation.omega_ref
            c = make_contact(model, form, g0=g0)
            st = solve_static(model, c, omega)
            assert st.converged
            sb = stability_of(model, c, omega, st.q)
            mx, sp = stability_indicators(model, c, omega, st.q)
            assert mx == pytest.approx(sb.max_real, rel=1e-9, abs=1e-9)
            assert sp == pytest.approx(sb.sum_positive_real, rel=1e-9, abs=1e-9)
            seen.add(sb.stable)
    assert seen == {True, False}, "the points must cover stable and unstable cells"


def test_transient_divergence_depth_is_the_parameter_files():
    """contact.max_penetration from the parameter file sets the library transient's divergence
    depth (it was a fixed 10 mm): the same interference diverges with a 0.02 mm liner and runs
    with the reference's 3 mm."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.structure.params import reference_parameters

    runs = {}
    for depth in (2e-5, None):
        p = reference_parameters()
        p = p if depth is None else p.replace(contact={"max_penetration": depth})
        m = build_model(p)
        c = make_contact(m, "2D", g0=-5e-5)
        runs[depth] = run_transient(m, c, 0.5 * p.normalisation.omega_ref, t_end=0.01, t_ramp=0.0, me=0.0)
    assert runs[2e-5].penetration_limit_hit and "0.02 mm" in runs[2e-5].message, runs[2e-5].message
    assert not runs[None].penetration_limit_hit, runs[None].message
