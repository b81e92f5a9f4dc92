"""The blades' Ritz discretisation against the rotating-cantilever literature (issue 12, item 3).

Reference computed here: a uniform Euler–Bernoulli cantilever (hub radius 0) of 32 Hermite
elements, tension T(s) = rho A Omega^2 (l^2 - s^2) / 2 from the centrifugal field, flapwise
(K + Kg) and lagwise (K + Kg - Omega^2 M: spin softening), matrices by Gauss quadrature. It
matches the literature's first flapwise frequencies (Wright et al. 1982; Hodges & Rutkowski 1981)
to their 4 decimals for mu = 0..10; the model's blade block (clamped-free polynomials) is held to it.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy.linalg import eigh

from rotorub_model.analyses.discretisation import rotating_cantilever, run_blade_convergence
from rotorub_model.structure.params import reference_parameters

# first flapwise lambda = omega / sqrt(EI / (rho A l^4)) of the uniform rotating cantilever, hub radius 0
LITERATURE_FLAP = [3.5160, 3.6817, 4.1373, 4.7973, 5.5850, 6.4495, 7.3604, 8.2996, 9.2568, 10.2257, 11.2023]
MUS = np.arange(11.0)


@cache
def fe_cantilever(n_elements: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """(flap, lag) first lambda at MUS from the reference FE (l = EI = rho A = 1)."""
    xg, wg = legendre.leggauss(6)
    x = 0.5 * (xg + 1.0)
    h = 1.0 / n_elements
    nd = 2 * (n_elements + 1)
    K, M, Kg = np.zeros((nd, nd)), np.zeros((nd, nd)), np.zeros((nd, nd))
    for e in range(n_elements):
        z = (e + x) * h
        w = 0.5 * wg * h
        N = np.stack([1 - 3 * x**2 + 2 * x**3, h * (x - 2 * x**2 + x**3), 3 * x**2 - 2 * x**3, h * (x**3 - x**2)], -1)
        dN = np.stack([(-6 * x + 6 * x**2) / h, 1 - 4 * x + 3 * x**2, (6 * x - 6 * x**2) / h, 3 * x**2 - 2 * x], -1)
        ddN = np.stack([(-6 + 12 * x) / h**2, (-4 + 6 * x) / h, (6 - 12 * x) / h**2, (-2 + 6 * x) / h], -1)
        blk = slice(2 * e, 2 * e + 4)
        K[blk, blk] += (ddN.T * w) @ ddN
        M[blk, blk] += (N.T * w) @ N
        Kg[blk, blk] += (dN.T * (w * 0.5 * (1.0 - z**2))) @ dN
    free = slice(2, nd)  # clamped root: u = u' = 0
    K, M, Kg = K[free, free], M[free, free], Kg[free, free]
    flap = [np.sqrt(eigh(K + mu**2 * Kg, M, eigvals_only=True, subset_by_index=[0, 0])[0]) for mu in MUS]
    lag = [np.sqrt(eigh(K + mu**2 * (Kg - M), M, eigvals_only=True, subset_by_index=[0, 0])[0]) for mu in MUS]
    return np.array(flap), np.array(lag)


def test_reference_matches_the_literature_and_is_converged():
    flap, lag = fe_cantilever()
    np.testing.assert_allclose(flap, LITERATURE_FLAP, rtol=0, atol=0.6e-4)  # the table's last digit
    np.testing.assert_allclose(lag**2, flap**2 - MUS**2, rtol=1e-7)  # uniform beam: softening by exactly mu^2
    # converged: 24 elements agree to 1e-6 (flap) and 1e-5 (lag, whose lambda^2 = flap^2 - mu^2 magnifies
    # relative errors 5x at mu = 10), a hundredth of the tolerances below; more elements only add
    # round-off (the spectrum's top grows as h^-4)
    f2, l2 = fe_cantilever(24)
    assert np.abs(f2 / flap - 1).max() < 1e-6 and np.abs(l2 / lag - 1).max() < 1e-5


@pytest.mark.parametrize("n", [5, 6])
def test_flap_and_lag_within_a_tenth_of_a_percent(n):
    """n >= 5: first flap and lag frequencies within 0.1 % for mu = 0..10 (measured: 0.035 % at n = 5)."""
    flap, lag = fe_cantilever()
    p = reference_parameters()
    assert np.abs(rotating_cantilever(p, n, 90.0, MUS) / flap - 1).max() < 1e-3
    assert np.abs(rotating_cantilever(p, n, 0.0, MUS) / lag - 1).max() < 1e-3


def test_four_functions():
    """n = 4: flap within 0.1 % up to mu = 10; lag within 0.1 % up to mu = 7 and 0.37 % at mu = 10
    (the lag mode's root boundary layer at high spin is what four polynomials miss; the issue asked
    0.1 % from n = 4: not met for the lag mode above mu = 7, docs/THEORY.md)."""
    flap, lag = fe_cantilever()
    p = reference_parameters()
    ef = rotating_cantilever(p, 4, 90.0, MUS) / flap - 1
    el = rotating_cantilever(p, 4, 0.0, MUS) / lag - 1
    assert np.abs(ef).max() < 1e-3
    assert np.abs(el[MUS <= 7]).max() < 1e-3
    assert np.abs(el).max() < 4e-3
    assert np.all(ef >= -1e-6) and np.all(el >= -1e-6)  # Rayleigh–Ritz: from above


def test_errors_fall_with_every_function_and_the_papers_two_cost_what_the_report_says():
    """The convergence table of the theory notes: each added function lowers the worst error; the
    paper's two functions are 2.4 % high (flap) and 11.4 % high (lag) at mu = 10, and the reference
    blade's first frequency 3.7 % high at the top of the speed range."""
    r = run_blade_convergence(reference_parameters())
    flap, lag = fe_cantilever()
    for kind, ref in (("flap", flap), ("lag", lag)):
        worst = [np.abs(getattr(r, kind)[n] / ref - 1).max() for n in (2, 3, 4, 5, 6)]
        assert all(b < a for a, b in zip(worst, worst[1:])), (kind, worst)
    assert r.flap[2][-1] / flap[-1] - 1 == pytest.approx(0.0241, abs=5e-4)
    assert r.lag[2][-1] / lag[-1] - 1 == pytest.approx(0.1135, abs=5e-4)
    s = r.summary()
    assert s["model_blade_max_error"] == pytest.approx(0.037, abs=1e-3)
    assert s["model_blade_error_at_rest"] == pytest.approx(0.0048, abs=2e-4)


# ------------------------------------------------------------------------------------------ the reduced basis
def test_reduced_basis_is_a_projection_of_the_polynomial_one():
    """n_modes < n_ritz: the blade block is Phi^T (block of the n_ritz polynomials) Phi, Phi the kept
    functions' coefficients (tip deflection 1): the same physics on a smaller subspace, nothing else."""
    from rotorub_model.analyses.discretisation import blade_block
    from rotorub_model.structure.blades import blade_basis

    p = reference_parameters().replace(blades={"n_ritz": 5, "n_modes": 3})
    phi = blade_basis(p)
    assert phi.shape == (5, 3)
    K5, M5, S5 = blade_block(p.replace(blades={"n_modes": 5}))
    K3, M3, S3 = blade_block(p)
    for A, B in ((K3, phi.T @ K5 @ phi), (M3, phi.T @ M5 @ phi), (S3, phi.T @ S5 @ phi)):
        np.testing.assert_allclose(A, B, rtol=1e-10, atol=1e-10 * np.abs(B).max())
    assert blade_basis(reference_parameters()) is None  # n_modes >= n_ritz: the polynomials as they are


def test_five_functions_reduced_to_two_keep_the_accuracy_and_the_time_step():
    """The user's n_ritz = 5 with the default n_modes = 2: the first flap frequency of the reference blade
    within 0.15 % over the whole speed range (the paper's two polynomials: 3.7 %; five kept: 0.13 %), with
    the highest blade frequency and the explicit step of the two-function model (five kept: 13x the steps)."""
    from rotorub_model.analyses.discretisation import run_blade_convergence
    from rotorub_model.analyses.transient import critical_time_step
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model

    p = reference_parameters()
    r = run_blade_convergence(p.replace(blades={"n_ritz": 5}), n_values=(2, 5), n_speeds=13)
    e_first, _, top = r.reduced_errors((5, 2))
    assert e_first < 1.5e-3 and r.reduced_errors((2, 2))[0] > 0.03
    assert top < 1.2 * r.reduced_errors((2, 2))[2] and r.reduced_errors((5, 5))[2] > 8 * top
    w = 3.3 * p.normalisation.omega_ref
    dt = {}
    for key, q in (("ref", p), ("5/2", p.replace(blades={"n_ritz": 5})),
                   ("5/5", p.replace(blades={"n_ritz": 5, "n_modes": 5}))):
        m = build_model(q)
        dt[key] = critical_time_step(m, make_contact(m, "3D", g0=0.8e-3), w)
        assert m.n_dofs == (68 if key == "5/5" else 38)
    assert dt["5/2"] > 0.8 * dt["ref"] and dt["5/5"] < dt["ref"] / 8


# ------------------------------------------------------------------------------ the basis as it grows (to 12)
def _blade_frequencies(n: int, omega: float) -> np.ndarray:
    from rotorub_model.analyses.discretisation import frequencies, full

    return frequencies(full(reference_parameters(), n), omega)


def test_frequencies_fall_monotonically_to_twelve_functions_and_the_mass_stays_conditioned():
    """Rayleigh-Ritz on nested spaces: every frequency can only fall as functions are added, at rest and at the
    top speed, up to the 12 the parameters accept. The paper's monomials broke this from 9 on (their mass
    matrix's condition number 8e13 at 9, 3e15 at 10: the first frequency moved in its 6th digit, NaN at 11);
    the conditioned form of the same space keeps it below 1e7 and the frequencies monotone to 1e-8 (their own
    round-off: eps x cond(M) ~ 1e-16 x 3.6e6 at 12, through the eigen-solve)."""
    from rotorub_model.analyses.discretisation import blade_block, full

    p = reference_parameters()
    top = p.normalisation.speed_max * p.normalisation.omega_ref
    for omega in (0.0, top):
        prev = None
        for n in range(2, 13):
            f = _blade_frequencies(n, omega)[:3]
            assert np.all(np.isfinite(f))
            if prev is not None:
                k = min(f.size, prev.size)
                assert np.all(f[:k] <= prev[:k] * (1 + 1e-8)), (n, omega, f, prev)
            prev = f
        # converged: the last two functions move the first two frequencies by less than 1e-7
        assert np.allclose(_blade_frequencies(11, omega)[:2], _blade_frequencies(12, omega)[:2], rtol=1e-7)
    for n in range(2, 13):
        assert np.linalg.cond(blade_block(full(p, n))[1]) < 1e7


def test_the_conditioned_form_is_the_same_physics_as_the_monomials(monkeypatch):
    """Five functions as the paper's monomials (forced here) and in the conditioned form span one space: the same
    frequencies to 1e-10 and the same transient (a blade tip's deflection at 3.3 omega_ref, 0.2 s, no contact)
    to 2e-6 of its amplitude, which is the monomials' own round-off (the model's mass matrix: condition number
    4.4e9 with them, 1.7e6 conditioned; eps x 4.4e9 ~ 5e-7); only the meaning of the coefficients differs."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure import ritz
    from rotorub_model.structure.blades import blade_functions
    from rotorub_model.structure.model import build_model

    p = reference_parameters().replace(blades={"n_ritz": 5, "n_modes": 5})
    w = 3.3 * p.normalisation.omega_ref

    def tip_history():
        m = build_model(p)
        r = run_transient(m, make_contact(m, "2D", g0=5e-3), w, t_end=0.2, t_ramp=0.1)
        ns = 2 * p.shaft.n_ritz
        return r.q[:, ns:ns + 5] @ blade_functions(p, p.blades.length)[0], _blade_frequencies(5, w)

    tip_c, f_c = tip_history()
    monkeypatch.setattr(ritz, "RAW_MAX", 5)
    tip_m, f_m = tip_history()
    np.testing.assert_allclose(f_c, f_m, rtol=1e-10)
    assert np.abs(tip_c - tip_m).max() <= 2e-6 * np.abs(tip_m).max()
    assert np.abs(tip_m).max() > 1e-5  # the blade does move


def test_twelve_functions_all_kept_run_a_transient_that_agrees_with_eight():
    """n_ritz = n_modes = 12 (the largest accepted): the transient without contact stays finite and its blade tip
    deflection matches eight functions' to 1e-3 (the monomials diverged within 0.1 s at 8 already)."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.blades import blade_functions
    from rotorub_model.structure.model import build_model

    tips = []
    for n in (8, 12):
        p = reference_parameters().replace(blades={"n_ritz": n, "n_modes": n})
        m = build_model(p)
        r = run_transient(m, make_contact(m, "2D", g0=5e-3), 3.3 * p.normalisation.omega_ref, t_end=0.2, t_ramp=0.1)
        assert np.all(np.isfinite(r.q)) and not r.diverged
        ns = 2 * p.shaft.n_ritz
        tips.append(r.q[:, ns:ns + n] @ blade_functions(p, p.blades.length)[0])
    assert np.abs(tips[1] - tips[0]).max() <= 1e-3 * np.abs(tips[0]).max()
