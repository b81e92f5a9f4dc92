"""An out-of-round casing through the harmonic balance (rotorub_model/analyses/harmonic/surface.py, problem.py):
lobe counts 2-4 in the linear limit against the linear solver with the equivalent harmonic load, the rub's
harmonic content at multiples of n Omega in the rotating frame, and bad input."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from rotorub_model.analyses.harmonic.problem import HarmonicsWarning, HBProblem, check_truncation, newton
from rotorub_model.analyses.harmonic.surface import CasingForcing, ForcingWarning
from rotorub_model.app.forced_response import forcing_from_args
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError


@pytest.fixture(autouse=True)
def one_thread():
    with threadpool_limits(limits=1):
        yield


def _complex(Q: np.ndarray, k: int) -> np.ndarray:
    """Harmonic k of real coefficients (cos, sin) as the complex amplitude of e^{i k tau}."""
    return Q[2 * k - 1] - 1j * Q[2 * k]


@pytest.mark.parametrize("n", [2, 3, 4])
def test_linear_limit_equals_the_linear_solver(ref_model, n):
    """2D, every blade pressed (g0 = -0.2 mm) and a lobe of 1 um: the contact never opens, so the response is
    linear: harmonic 0 solves (K(Omega) + K_c) q = F_imb - k_r g0 sum D_j and harmonic n solves Z(n Omega) Q_n =
    -k_r a sum_j n_r D_j e^{i n (alpha_j - psi)} (the lobe's gap seen by blade j at alpha_j + Omega t; D_j = A_j -
    mu S_j, saturated friction), with K_c = k_r sum D_j^T G_j; every other harmonic vanishes. Written from the
    documented formula, not from the kernel: a wrong phase, sign or lobe count in the surface fails it."""
    m = ref_model
    om = 2.0 * m.params.normalisation.omega_ref
    g0, a, psi = -0.2e-3, 1e-6, 0.4
    c = make_contact(m, "2D", g0=g0)
    pb = HBProblem(m, c, n + 2, forcing=CasingForcing.lobe(n, a, psi))
    r = newton(pb, pb.linear_start(om, om), om, om, tol=1e-13)
    assert r.converged and r.evaluation.touching == pb.basis.m
    Q = pb.full(r.Y, om, om)
    pts = c.geometry.points.reshape(-1, 3)
    alpha = np.arctan2(pts[:, 1], pts[:, 0])
    nr = (c.geometry.normals.reshape(-1, 3)[:, :2] * np.c_[np.cos(alpha), np.sin(alpha)]).sum(axis=1)
    D = c.A - c.mu * c.S
    Kc = c.k_r * D.T @ c.G
    K = m.K_omega(om) + Kc
    q0 = np.linalg.solve(K, m.force(om) - c.k_r * g0 * D.sum(axis=0))
    assert np.abs(Q[0] - q0).max() <= 1e-10 * np.abs(q0).max()
    Fn = -c.k_r * a * (D * (nr * np.exp(1j * n * (alpha - psi)))[:, None]).sum(axis=0)
    Z = K - (n * om) ** 2 * m.M + 1j * n * om * (m.D + m.G(om))
    Qn = np.linalg.solve(Z, Fn)
    # (n = 4: 10 blades leave no load on the 2D dofs, 1 to 3 nodal diameters: 4 +- k is never a multiple of 10;
    # both sides are then round-off, held to 1e-9 of the lobe)
    assert np.abs(_complex(Q, n) - Qn).max() <= 1e-8 * np.abs(Qn).max() + 1e-9 * a
    if n < 4:
        assert np.abs(Qn).max() > 1e-3 * a
    others = [k for k in range(1, pb.H + 1) if k != n]
    assert max(np.abs(_complex(Q, k)).max() for k in others) <= 1e-9 * np.abs(Qn).max() + 1e-9 * a


def test_linear_limit_3d_against_the_kernels_load(ref_model):
    """3D (chord law, both edges pressed): the same, the equivalent load and closed stiffness read from the kernel
    at q = 0 over the frame angle (its harmonic 2), the response from the linear solver."""
    m = ref_model
    om = 2.0 * m.params.normalisation.omega_ref
    f = CasingForcing.lobe(2, 1e-6, 1.1)
    c = make_contact(m, "3D", g0=-0.2e-3)
    pb = HBProblem(m, c, 4, forcing=f)
    r = newton(pb, pb.linear_start(om, om), om, om, tol=1e-13)
    Q = pb.full(r.Y, om, om)
    phi = 2 * math.pi * np.arange(64) / 64
    F = np.stack([pb.P.T @ pb.kernel_batch(np.zeros((1, pb.r)), None, om, np.array([p]), False)[0][0] for p in phi])
    F2 = 2 * (np.exp(-2j * phi) @ F) / 64  # the load's harmonic 2 (F ~ Re(F2 e^{2 i phi}))
    J = pb.P.T @ pb.kernel_batch(np.zeros((1, pb.r)), None, om, np.array([0.0]), True)[1][0] @ pb.P
    Z = m.K_omega(om) - J - (2 * om) ** 2 * m.M + 2j * om * (m.D + m.G(om))
    Q2 = np.linalg.solve(Z, F2)
    assert np.abs(_complex(Q, 2) - Q2).max() <= 1e-7 * np.abs(Q2).max()


@pytest.mark.parametrize("formulation", ["2D", "3D"])
@pytest.mark.parametrize("n", [2, 3, 4])
def test_oval_rub_is_forced_at_multiples_of_n_omega(ref_model, formulation, n):
    """A rub on an n-lobed casing (0.15 mm, g0 = 0.5 mm, 3.25 Omega_ref): in the rotating frame the contact force
    holds harmonics n, 2n, ... of the spin, harmonic n the largest; the others (the rotor's own whirl) below 1e-3
    of it (measured: round-off for n = 2, 4; 1e-4 for n = 3, whose 3-fold pattern the 10 blades do not share)."""
    m = ref_model
    om = 3.25 * m.params.normalisation.omega_ref
    pb = HBProblem(m, make_contact(m, formulation, g0=0.5e-3), 6 * n, forcing=CasingForcing.lobe(n, 0.15e-3, 0.4))
    r = newton(pb, pb.linear_start(om, om), om, om)
    assert r.converged and r.evaluation.touching > 0
    a = np.linalg.norm(pb.basis.amplitudes(r.evaluation.f_hat), axis=1)
    assert int(np.argmax(a[1:])) + 1 == n
    assert max(a[k] for k in range(1, pb.H + 1) if k % n) <= 1e-3 * a[n]


def test_bad_input():
    for n, match in ((0, "lobes: 0 is a uniform closure"), (1, "lobes: 1 is the casing's rigid offset"),
                     (9, "accepted lobe counts 2..8")):
        with pytest.raises(ParameterError, match=match):
            CasingForcing(lobes={n: (1e-4, 0.0)})
    with pytest.raises(ParameterError, match=r"lobes\[2\]"):
        CasingForcing(lobes={2: (-1e-4, 0.0)})
    with pytest.raises(ParameterError, match=r"lobes\[3\]"):
        CasingForcing(lobes={3: (1e-4,)})
    with pytest.raises(ParameterError, match="clearances"):
        CasingForcing.lobe(2, 6e-3).check(0.5e-3)  # 6 mm on a 0.5 mm clearance: metres taken for millimetres
    with pytest.warns(ForcingWarning, match="exceeds the clearance"):
        CasingForcing.lobe(3, 0.6e-3).check(0.5e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert CasingForcing.lobe(4, 0.2e-3).check(0.5e-3) == []
    with pytest.raises(ParameterError, match="--amplitude"):
        forcing_from_args(0.5e-3, 2, None, 0.0, None)


def test_harmonics_against_the_lobe_count(ref_model):
    """Fewer harmonics than the lobe count: refused (the forcing is not represented); as many: the stated warning
    for a rub (its harmonic n is then the highest kept and the largest); 6 n: none."""
    m = ref_model
    c = make_contact(m, "2D", g0=0.5e-3)
    om = 3.25 * m.params.normalisation.omega_ref
    for n in (2, 3, 4):
        f = CasingForcing.lobe(n, 0.15e-3)
        with pytest.raises(ParameterError, match=f"fewer than the casing's lobe count {n}"):
            HBProblem(m, c, n - 1, forcing=f)
        few = HBProblem(m, c, n, forcing=f)
        with pytest.warns(HarmonicsWarning, match="too few"):
            check_truncation(few, newton(few, few.linear_start(om, om), om, om).Y)
        many = HBProblem(m, c, 6 * n, forcing=f)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert check_truncation(many, newton(many, many.linear_start(om, om), om, om).Y) is None
