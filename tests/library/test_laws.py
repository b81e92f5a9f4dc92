"""The normal contact laws in one place (contact/laws.py, the kernel's rr_laws.c): the second law (bilinear) against
its closed forms, its potential against its force, and the law going through every place the law reaches (the
model's forces, the explicit step, static solutions, the time loop, the liner's return map, the parameter file)."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model import kernel
from rotorub_model.analyses.energy import energy_history
from rotorub_model.analyses.static import solve_static
from rotorub_model.analyses.transient import critical_time_step, run_transient
from rotorub_model.contact import make_contact
from rotorub_model.contact.laws import LAWS, knee_note, law_params, max_slope
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import load_parameters, reference_parameters

K, L = 1.5e6, 0.2
KNEE, RATIO = 0.3e-3, 4.0
BILINEAR = kernel.make_law("bilinear", (KNEE, RATIO))


def shape(delta, knee=KNEE, ratio=RATIO):
    """The bilinear law's force per unit k_r at penetration delta (the closed form)."""
    delta = np.maximum(delta, 0.0)
    return delta + (ratio - 1.0) * np.maximum(delta - knee, 0.0)


def strain(delta, knee=KNEE, ratio=RATIO):
    """Its integral: the potential per unit k_r."""
    delta = np.maximum(delta, 0.0)
    return 0.5 * delta**2 + 0.5 * (ratio - 1.0) * np.maximum(delta - knee, 0.0) ** 2


# ----------------------------------------------------------------------------------------------- the point law
@pytest.mark.parametrize("delta", [0.0, 0.1e-3, KNEE, 0.5e-3, 2e-3])
def test_point_law_is_the_closed_form(delta):
    out = kernel.blade_law(-delta, 0.0, K, 1.0, BILINEAR, 1)
    assert out[0] == pytest.approx(K * shape(delta), rel=1e-14, abs=1e-9)
    slope = 0.0 if delta == 0 else (1.0 if delta <= KNEE else RATIO)
    assert out[2] == pytest.approx(-K * slope, rel=1e-14)
    assert out[7] == pytest.approx(K * strain(delta), rel=1e-14, abs=1e-15)


def test_penalty_is_the_bilinear_law_with_ratio_one():
    one = kernel.make_law("bilinear", (KNEE, 1.0))
    for g in np.linspace(-2e-3, 1e-3, 31):
        for gte in (-1e-3, 0.2e-3):
            a = kernel.blade_law(g, gte, K, L, one, 2)
            b = kernel.blade_law(g, gte, K, L, kernel.PENALTY, 2)
            assert a == pytest.approx(b, rel=1e-14, abs=1e-12)


# ----------------------------------------------------------------------------------------------- the chord law
def quadrature(g_le, g_te, n=200001):
    """F_N, M_N and the potential by the trapezoidal rule on a fine grid along the chord (independent of the
    kernel's closed form): pressure (k / l) shape(-gap(c))."""
    c = np.linspace(-L / 2, L / 2, n)
    gap = g_le + (g_te - g_le) * (c + L / 2) / L
    p = K / L * shape(-gap)
    v = K / L * strain(-gap)
    return np.trapezoid(p, c), np.trapezoid(c * p, c), np.trapezoid(v, c)


@pytest.mark.parametrize("g_le,g_te", [(-0.1e-3, -0.2e-3), (-0.6e-3, 0.2e-3), (0.3e-3, -0.9e-3),
                                       (-0.5e-3, -0.7e-3), (-0.2e-3, -1.1e-3), (0.1e-3, 0.2e-3)])
def test_chord_law_is_the_integral_of_the_pressure(g_le, g_te):
    """Force, moment and potential of the bilinear chord law against a direct quadrature of the pressure along
    the chord: before the knee, across it, wholly beyond it, partly in contact, and open."""
    out = kernel.blade_law(g_le, g_te, K, L, BILINEAR, 2)
    F, M, V = quadrature(g_le, g_te)
    scale = K * 1e-3
    assert out[0] == pytest.approx(F, abs=1e-7 * scale)
    assert out[1] == pytest.approx(M, abs=1e-7 * scale * L)
    assert out[7] == pytest.approx(V, abs=1e-7 * scale * 1e-3)


@pytest.mark.parametrize("g_le,g_te", [(-0.6e-3, 0.2e-3), (-0.5e-3, -0.7e-3), (-0.2e-3, -1.1e-3)])
def test_chord_law_derivatives_and_potential_gradient(g_le, g_te):
    """dF/deta, dF/dzeta, dM/deta, dM/dzeta against central differences, and the potential's gradient:
    dV/deta = -F_N, dV/dzeta = -M_N (what makes the energy checks hold for every law)."""

    def law(eta, zeta):
        return np.array(kernel.blade_law(eta - zeta * L / 2, eta + zeta * L / 2, K, L, BILINEAR, 2))

    eta, zeta = 0.5 * (g_le + g_te), (g_te - g_le) / L
    h_e, h_z = 1e-9, 1e-9 / L
    d_eta = (law(eta + h_e, zeta) - law(eta - h_e, zeta)) / (2 * h_e)
    d_zeta = (law(eta, zeta + h_z) - law(eta, zeta - h_z)) / (2 * h_z)
    out = law(eta, zeta)
    assert out[2] == pytest.approx(d_eta[0], rel=1e-6)
    assert out[3] == pytest.approx(d_zeta[0], rel=1e-6)
    assert out[4] == pytest.approx(d_eta[1], rel=1e-6)
    assert out[5] == pytest.approx(d_zeta[1], rel=1e-6)
    assert d_eta[7] == pytest.approx(-out[0], rel=1e-6)
    assert d_zeta[7] == pytest.approx(-out[1], rel=1e-6)


def test_a_chord_pressed_evenly_carries_the_tips_force_in_both_formulations():
    """k_r is a whole tip's stiffness in both formulations, whatever the law."""
    for delta in (0.1e-3, 0.8e-3):
        f3 = kernel.blade_law(-delta, -delta, K, L, BILINEAR, 2)[0]
        f2 = kernel.blade_law(-delta, 0.0, K, 1.0, BILINEAR, 1)[0]
        assert f3 == pytest.approx(f2, rel=1e-13) == K * shape(delta)


# ----------------------------------------------------------------------------------------------- through the model
@pytest.fixture(scope="module")
def bilinear_model():
    return build_model(reference_parameters().replace(contact={"law": "bilinear", "knee": KNEE,
                                                                "stiffness_ratio": RATIO}))


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_model_forces_are_minus_the_potential_gradient(bilinear_model, formulation):
    """Without friction the generalised contact force is -grad V(q), V the kernel's potential (finite
    differences over every dof), at a state where blades are before, across and beyond the knee."""
    m = bilinear_model
    c = make_contact(m, formulation, g0=-0.4e-3, mu=0.0)
    rng = np.random.default_rng(3)
    q = 2e-5 * rng.standard_normal(m.n_dofs)
    f = c.forces(q, 0.0)
    grad = np.zeros(m.n_dofs)
    for i in range(m.n_dofs):
        e = np.zeros(m.n_dofs)
        e[i] = 1e-9
        grad[i] = (c.potential(q + e)[0] - c.potential(q - e)[0]) / 2e-9
    pen = -c.gaps(q)
    assert (pen > KNEE).any() and ((pen > 0) & (pen < KNEE)).any(), "both pieces of the law in play"
    np.testing.assert_allclose(f, -grad, atol=1e-6 * np.abs(f).max())


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_model_jacobian_against_finite_differences(bilinear_model, formulation):
    m = bilinear_model
    c = make_contact(m, formulation, g0=-0.4e-3)
    w = 3.3 * m.params.normalisation.omega_ref
    rng = np.random.default_rng(4)
    q = 2e-5 * rng.standard_normal(m.n_dofs)
    J = c.jacobian(q, w)
    fd = np.column_stack([(c.forces(q + e, w) - c.forces(q - e, w)) / 2e-10 for e in 1e-10 * np.eye(m.n_dofs)])
    np.testing.assert_allclose(J, fd, atol=1e-5 * np.abs(J).max())


def test_the_explicit_step_sees_the_stiffest_slope(bilinear_model, ref_model):
    """The closed-contact stiffness is the penalty's times the law's largest slope (friction's part too: it
    follows the normal force's slope), and the step shrinks accordingly; a softening law keeps the penalty's."""
    model = ref_model
    w = 3.3 * model.params.normalisation.omega_ref
    pen = make_contact(model, "3D")
    bil = make_contact(bilinear_model, "3D")
    np.testing.assert_allclose(bil.closed_stiffness(w), RATIO * pen.closed_stiffness(w), rtol=1e-13, atol=1e-6)
    assert max_slope("bilinear", (KNEE, RATIO)) == RATIO and max_slope("bilinear", (KNEE, 0.5)) == 1.0
    assert max_slope("penalty", ()) == 1.0
    # the step is 2 / w_max of the system closed at the largest slope (numpy's eigenvalues as the reference);
    # with the reference's soft contact a blade mode sets it, with a stiff one (1e9 N/m) the contact does
    for k_r in (model.params.contact.k_r, 1e9):
        steps = {}
        for name, m in (("penalty", model), ("bilinear", bilinear_model)):
            m = build_model(m.params.replace(contact={"k_r": k_r}))
            c = make_contact(m, "3D")
            lam = np.linalg.eigvals(np.linalg.solve(m.M, m.K_omega(w) + c.closed_stiffness(w)))
            steps[name] = critical_time_step(m, c, w)
            assert steps[name] == pytest.approx(2 / np.sqrt(np.abs(lam).max()), rel=1e-9)
        if k_r == 1e9:
            assert steps["bilinear"] == pytest.approx(steps["penalty"] / np.sqrt(RATIO), rel=0.05)


def test_static_solution_with_the_bilinear_law(bilinear_model):
    """A balanced solution past the knee: its residual is the model's own (K q - F_nl - F), and it differs
    from the penalty law's (the stiffer layer carries the blades)."""
    m = bilinear_model
    w = 3.3 * m.params.normalisation.omega_ref
    c = make_contact(m, "2D", g0=-0.5e-3)
    st = solve_static(m, c, w)
    assert st.converged
    r = m.K_omega(w) @ st.q - c.forces(st.q, w) - m.force(w)
    assert np.linalg.norm(r) <= 1e-8 * np.linalg.norm(m.force(w))
    assert (-c.gaps(st.q) > KNEE).any()
    pen = solve_static(build_model(reference_parameters()), make_contact(build_model(), "2D", g0=-0.5e-3), w)
    assert np.abs(st.q - pen.q).max() > 1e-6


def test_energy_is_conserved_with_the_bilinear_law(undamped):
    """Undamped, frictionless, at rest: kinetic + strain + the kernel's contact potential stays constant to the
    integrator's O(dt^2) while blades cross the knee back and forth (measured 3.8e-4 and 9.6e-5 of the energy at
    0.2 and 0.1 of the step limit: the penalty law's O(dt^2) too)."""
    m = build_model(undamped.params.replace(contact={"law": "bilinear", "knee": 0.1e-3, "stiffness_ratio": 3.0}))
    c = make_contact(m, "3D", g0=-0.25e-3, mu=0.0)
    limit = critical_time_step(m, c, 0.0)
    devs = []
    for frac in (0.2, 0.1):
        dt = frac * limit
        r = run_transient(m, c, 0.0, t_end=0.2, t_ramp=0.0, me=0.0, dt=dt, record_dt=dt)
        e = energy_history(m, c, np.vstack([np.zeros(m.n_dofs), r.q]), r.dt, 0.0)
        pen = -c.gaps_batch(r.q)
        assert (pen > 0.1e-3).any() and ((pen > 0) & (pen < 0.1e-3)).any(), "both pieces of the law in play"
        devs.append(np.ptp(e.energy) / e.energy.max())
    assert devs[0] < 1e-3 and devs[1] < devs[0] / 3.5, devs


# ----------------------------------------------------------------------------------------------- the liner
@pytest.mark.parametrize("fy", [100.0, 800.0])
def test_liner_return_map_with_the_bilinear_law(fy):
    """A tip pushed by delta into a liner under the bilinear law: the force saturates at F_y; what is left of the
    penetration is the law's inverse at F_y (before the knee for F_y = 100 N, beyond it for 800 N)."""
    delta = 1.2e-3
    f, depth, work = kernel.liner_law(-delta, K, fy, 0.0, 5e-3, law=BILINEAR)
    left = fy / K if fy <= K * KNEE else KNEE + (fy - K * KNEE) / (RATIO * K)
    assert f == pytest.approx(fy, rel=1e-12)
    assert depth == pytest.approx(delta - left, rel=1e-12)
    assert work == pytest.approx(fy * depth, rel=1e-12)
    # with hardening: the bound F_y + H w is met exactly on the piece the root lies on
    H = 2e5
    f, depth, _ = kernel.liner_law(-delta, K, fy, H, 5e-3, law=BILINEAR)
    assert f == pytest.approx(fy + H * depth, rel=1e-12)
    assert K * shape(delta - depth) == pytest.approx(f, rel=1e-12)


# ----------------------------------------------------------------------------------------------- the parameter file
def test_parameter_file_selects_the_law(tmp_path):
    text = (load_parameters.__globals__["REFERENCE_FILE"]).read_text()
    f = tmp_path / "bil.toml"
    f.write_text(text.replace("[contact]", '[contact]\nlaw = "bilinear"\nknee = 4e-4\nstiffness_ratio = 2.5', 1))
    p = load_parameters(f)
    assert p.contact.law == "bilinear" and law_params(p.contact) == (4e-4, 2.5)
    c = make_contact(build_model(p), "3D")
    assert (c.law, c.law_params) == ("bilinear", (4e-4, 2.5))
    assert c.with_clearance(1e-3).law_params == (4e-4, 2.5)
    for bad, word in (({"law": "hertz"}, "contact.law: 'hertz' unknown; accepted: penalty, bilinear"),
                      ({"knee": 0.0}, "contact.knee"), ({"stiffness_ratio": 1e3}, "contact.stiffness_ratio")):
        with pytest.raises(ParameterError, match=word):
            reference_parameters().replace(contact=bad)
    assert set(LAWS) == {"penalty", "bilinear"}


@pytest.mark.parametrize("knee, noted", [(5e-3, True), (1e-6, False)])
def test_the_static_verdict_says_when_the_knee_was_never_reached(write_params, tmp_path, capsys, knee, noted):
    """A bilinear law whose knee the solution never reaches gives the penalty law's numbers: the verdict says so (a
    reader would otherwise take them for the law's effect), and says nothing once the knee is passed."""
    from rotorub_model.app.cli import main
    from rotorub_model.structure.params import to_dict

    p = reference_parameters().replace(contact={"law": "bilinear", "knee": knee, "stiffness_ratio": 4.0})
    path = write_params(to_dict(p))
    rc = main(["static", "--params", str(path), "--speed", "3.3", "--g0", "0.3mm", "--formulation", "2D",
               "--out", str(tmp_path / "st")])
    out = capsys.readouterr().out
    assert rc == 0
    assert ("the bilinear law's knee (5 mm) was never reached" in out) is noted, out


def test_knee_note_without_contact_says_no_blade_touched():
    """A static solution clear of the casing gives deepest penetration -0.0 (the CLI's gaps.min(initial=0)): the note
    said "deepest penetration -0 mm ... these are the penalty law's results", a number that looks wrong and a claim
    that the contact acted. It must say no blade touched; a real shallow penetration keeps its depth."""
    c = reference_parameters().replace(contact={"law": "bilinear", "knee": 2e-4}).contact
    for clear in (-0.0, 0.0, -1e-4):
        note = knee_note(c, clear)
        assert "no blade touched the casing" in note and "-0" not in note and "penalty law's results" not in note
    shallow = knee_note(c, 5e-5)
    assert "deepest penetration 0.05 mm" in shallow and "penalty law's results" in shallow
    assert knee_note(c, 3e-4) == ""
    assert knee_note(reference_parameters().contact, -0.0) == ""  # the penalty law has no knee
