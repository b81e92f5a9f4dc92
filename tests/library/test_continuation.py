"""Continuation (issue 13): special points located, the cycle born at a Hopf point, the orbit a
transient settles on, and the boundary curves against the grid maps."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.analyses.continuation import agreement
from rotorub_model.analyses.continuation.boundary import trace_boundaries
from rotorub_model.analyses.continuation.branch import continue_static
from rotorub_model.analyses.continuation.equilibria import Equilibria
from rotorub_model.analyses.continuation.periodic import continue_orbits, continue_orbits_from_hopf, orbit_from_state
from rotorub_model.analyses.maps import run_stability_map
from rotorub_model.analyses.transient import run_transient
from rotorub_model.structure.model import build_model


@pytest.fixture(scope="module")
def model():
    return build_model()


@pytest.fixture(scope="module")
def w33(model):
    return 3.3 * model.params.normalisation.omega_ref


@pytest.fixture(scope="module")
def hopf_3d(model, w33):
    eq = Equilibria(model, "3D")
    b = continue_static(eq, "g0", w33, 0.36e-3, 0.32e-3)
    return eq, b


def settled(r, eq: Equilibria, record_dt: float) -> tuple[float, float]:
    """Over a transient's last 2 s: the fan disk's largest peak-to-peak [m] and the period [s] from
    the upward crossings of its mean."""
    last = r.q[-int(2.0 / record_dt):] @ eq._T2.T
    x = last[:, 0] - last[:, 0].mean()
    up = np.flatnonzero((x[1:] > 0) & (x[:-1] <= 0))
    return float(np.ptp(last, axis=0).max()), float(np.mean(np.diff(up)) * record_dt)


def settles_from_unstable(model, eq: Equilibria, omega: float, g0: float, amplitude: float, dt: float,
                          t_end: float) -> tuple[float, float, float]:
    """A transient started next to the unstable static solution at (omega, g0), along its critical
    eigenvector with the fan disk moved by ``amplitude`` [m], at step dt: (Re mu of the static
    solution, then the settled peak-to-peak and period as :func:`settled` gives them)."""
    qs = eq.solve(omega, g0)
    mu, _ = eq.critical(qs, omega, g0)
    q0, v0 = eq.unstable_start(qs, omega, g0, mu, amplitude)
    r = run_transient(model, eq.contact(g0), omega, t_end=t_end, t_ramp=0.0, q0=q0, v0=v0, record_dt=2 * dt, dt=dt)
    assert not r.penetration_limit_hit
    return (mu.real, *settled(r, eq, 2 * dt))


def test_hopf_point_is_located_to_1e_8(hopf_3d, w33):
    eq, b = hopf_3d
    assert b.complete
    hopf = b.of_kind("hopf")
    assert len(hopf) == 1
    h = hopf[0].point
    assert abs(h.mu.real) <= 1e-8
    # recomputed from scratch (full spectrum, then Newton): the same eigenvalue, on the axis
    q = eq.solve(w33, h.g0, h.q)
    mu, max_real = eq.critical(q, w33, h.g0)
    assert abs(mu.real) <= 1e-8 and abs(mu - h.mu) <= 1e-8 * abs(mu)
    # and it is a crossing: stable just above, unstable just below (g0 decreasing)
    d = 1e-8
    above = eq.critical(eq.solve(w33, h.g0 + d, q), w33, h.g0 + d)[0].real
    below = eq.critical(eq.solve(w33, h.g0 - d, q), w33, h.g0 - d)[0].real
    assert above < 0 < below
    assert hopf[0].detail["direction"] == "destabilising"


def test_cycle_born_at_the_hopf_point_has_its_frequency(hopf_3d, w33):
    eq, b = hopf_3d
    h = b.of_kind("hopf")[0].point
    br = continue_orbits_from_hopf(eq, w33, h.g0, h.mu, 0.0, max_orbits=3)
    first = br.orbits[0]
    assert first.residual < 1e-8
    assert first.disk_peak_to_peak < 1e-6  # a small cycle, near the Hopf point
    assert first.frequency == pytest.approx(abs(h.mu.imag), rel=1e-3)
    # supercritical: the cycles grow past the Hopf point (smaller g0; the scheme's own Hopf point sits
    # 2e-5 relative higher, the central-difference frequency shift) and are stable there
    g, amp = [o.g0 for o in br.orbits], [o.disk_peak_to_peak for o in br.orbits]
    assert g[-1] < h.g0 and np.all(np.diff(g) < 0) and np.all(np.diff(amp) > 0)
    assert abs(g[0] / h.g0 - 1) < 1e-4 and all(o.stable for o in br.orbits[1:])  # the first: neutral to 1e-5


def test_contact_events_and_the_2d_switch(model, w33):
    eq = Equilibria(model, "2D")
    b = continue_static(eq, "g0", w33, 1.2e-3, 0.0)
    assert b.complete
    events = b.of_kind("contact")
    assert len(events) >= 4
    for e in events:
        k = e.detail["point_index"]
        gap = eq.contact(e.point.g0).gaps(e.point.q).ravel()[k]
        assert abs(gap) <= 1e-9 * 1.2e-3  # the event is where the gap is zero
    sw = b.of_kind("switch")
    assert len(sw) == 1  # 2D: stability lost when the second blade touches (the point law's stiffness jumps)
    assert sw[0].detail["left_real_part"] < 0 < sw[0].detail["right_real_part"]
    assert not b.of_kind("hopf")  # at fixed speed the 2D spectrum is constant between events: no Hopf in g0


def test_fold_in_speed(model):
    """Through the hardening resonance at g0 = 2 mm (3D) the branch turns back: folds located where the
    parameter's tangent component vanishes and the static Jacobian is singular."""
    wr = model.params.normalisation.omega_ref
    eq = Equilibria(model, "3D")
    b = continue_static(eq, "omega", 2.0e-3, 3.45 * wr, 3.6 * wr, spectrum=False)
    folds = b.of_kind("fold")
    assert len(folds) >= 2 and b.complete
    f = folds[0].point
    J = eq.jacobian(f.q, f.omega, f.g0)
    s_fold = np.linalg.svd(J, compute_uv=False)
    p0 = b.points[0]
    s_start = np.linalg.svd(eq.jacobian(p0.q, p0.omega, p0.g0), compute_uv=False)
    assert s_fold[-1] / s_fold[0] < 1e-3 * s_start[-1] / s_start[0]
    w = b.values()
    k = int(np.argmin(np.abs(w - f.omega)))
    assert (w[k - 3] - w[k]) * (w[k + 3] - w[k]) > 0  # the same side before and after: it turned


def test_transient_settles_on_the_predicted_orbit(model, w33):
    """2D, g0 = 0.33 mm (past the switch: the static solution is unstable, Re = +0.43 /s). The orbit is
    predicted by continuing the orbit found at 0.30 mm; a transient started next to the unstable static
    solution settles on it: amplitude within 2 %, period within 1 %."""
    eq = Equilibria(model, "2D")
    n = model.n_dofs
    # the orbit at 0.30 mm, from a transient there, then continued to 0.33 mm and shot at exactly 0.33 mm
    g_seed, g = 0.30e-3, 0.33e-3
    q = eq.solve(w33, g_seed)
    mu, _ = eq.critical(q, w33, g_seed)
    q0, v0 = eq.unstable_start(q, w33, g_seed, mu, 1e-5)
    tr = run_transient(model, eq.contact(g_seed), w33, t_end=30.0, t_ramp=0.0, q0=q0, v0=v0, record_dt=5e-4)
    seed = orbit_from_state(eq, w33, g_seed, tr.q[-1], (tr.q[-1] - tr.q[-2]) / (tr.t[1] - tr.t[0]),
                            2 * np.pi / abs(mu.imag))
    br = continue_orbits(eq, seed, g, max_orbits=30)
    near = min(br.orbits, key=lambda o: abs(o.g0 - g))
    pred = orbit_from_state(eq, w33, g, near.x0[:n], near.x0[n:], near.period)
    assert pred is not None and pred.g0 == g and pred.residual < 1e-8
    # the transient at 0.33 mm from the unstable static solution, at the orbit's own step
    re, ptp, period = settles_from_unstable(model, eq, w33, g, 1e-6, pred.period / 256, 35.0)
    assert re > 0.3
    assert ptp == pytest.approx(pred.disk_peak_to_peak, rel=0.02)
    assert period == pytest.approx(pred.period, rel=0.01)
    # and the amplitude it settles on is not the linear growth's: the static solution was 1 um away
    assert pred.disk_peak_to_peak > 1e-4


@pytest.fixture(scope="module")
def quick_maps(model):
    """The main job's quick stability maps (40 x 36 cells round the first critical), per formulation."""
    from rotorub_model.app.studies import default_grid

    speeds, g0s = default_grid(model, quick=True)
    cache = {}

    def get(formulation):
        if formulation not in cache:
            cache[formulation] = run_stability_map(model, formulation, speeds, g0s, executor="serial",
                                                   progress=False)
        return speeds, g0s, cache[formulation]

    return get


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_boundary_curves_agree_with_the_quick_grid_map(model, quick_maps, formulation):
    """Over the main job's quick map: every grid cell that contradicts the side of the traced curves
    lies within one cell of them (measured: 2D none at all, 3D 2 cells, each within one cell). The
    curves include the folds where the maps' branch jumps."""
    speeds, g0s, mp = quick_maps(formulation)
    assert mp.unstable.any() and (mp.contact & ~mp.unstable).any()
    curves, info = trace_boundaries(Equilibria(model, formulation), speeds, g0s)
    kinds = {k for c in curves for k in c.kinds}
    assert kinds >= ({"switch", "fold"} if formulation == "2D" else {"hopf", "fold"})
    a = agreement(curves, mp, tuple(info["cell"]))
    assert a["regions"] >= 2
    assert a["contradicting_beyond_one_cell"] == 0, a
    assert a["contradicting_fraction"] < 0.01


@pytest.mark.parametrize("formulation, lattice", [("2D", (13, 13)), ("3D", (13, 13)), ("3D", (21, 21))])
def test_boundary_curves_do_not_hang_on_the_seed_lattice(model, quick_maps, formulation, lattice):
    """Seeded from a coarser or a finer lattice than the default 17 x 17, the curves still leave no
    contradicting cell beyond one cell of them (at 9 x 9 the 3D pocket right of the critical is
    seeded by no lattice edge: measured 167 cells beyond, the reason for the default)."""
    speeds, g0s, mp = quick_maps(formulation)
    curves, info = trace_boundaries(Equilibria(model, formulation), speeds, g0s, lattice=lattice)
    a = agreement(curves, mp, tuple(info["cell"]))
    assert a["contradicting_beyond_one_cell"] == 0, a
    assert a["contradicting_fraction"] < 0.01


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_boundary_curves_agree_on_a_softer_contact(formulation):
    """Another configuration (the tip's contact stiffness halved): the curves still leave no grid cell
    contradicting them beyond one cell. 3D failed here before the tracer learnt to check a seed's or
    a corner's stable side by its whole spectrum and to re-start a lost regula falsi iterate from the
    stable end (152 cells beyond one cell; now 3, all within one)."""
    from rotorub_model.app.studies import default_grid
    from rotorub_model.structure.params import reference_parameters

    m = build_model(reference_parameters().replace(contact={"k_r": 0.75e6}))
    speeds, g0s = default_grid(m, quick=True)
    mp = run_stability_map(m, formulation, speeds, g0s, executor="serial", progress=False)
    curves, info = trace_boundaries(Equilibria(m, formulation), speeds, g0s)
    a = agreement(curves, mp, tuple(info["cell"]))
    assert a["regions"] >= 2
    assert a["contradicting_beyond_one_cell"] == 0, a
    assert a["contradicting_fraction"] < 0.01


def test_transient_settles_on_the_orbit_born_at_the_hopf_point(hopf_3d, model, w33):
    """3D: the orbit predicted from the Hopf point alone (continued to g0 = 0.3323 mm, 1.5 um below
    it: 2.8 um peak-to-peak of the disk, stable) is where a transient started next to the unstable
    static solution ends: amplitude within 2 %, period within 1 % (measured: 1.0 % at 100 s, the
    approach being slow so near the Hopf point: the static Re is 0.036 /s)."""
    eq, b = hopf_3d
    h = b.of_kind("hopf")[0].point
    br = continue_orbits_from_hopf(eq, w33, h.g0, h.mu, 0.3323e-3, max_orbits=30)
    pred = min(br.orbits, key=lambda o: abs(o.g0 - 0.3323e-3))
    assert pred.stable and abs(pred.g0 - 0.3323e-3) < 0.2e-6
    re, ptp, period = settles_from_unstable(model, eq, w33, pred.g0, 0.25 * pred.disk_peak_to_peak,
                                            pred.period / 128, 100.0)
    assert re > 0.02
    assert ptp == pytest.approx(pred.disk_peak_to_peak, rel=0.02)
    assert period == pytest.approx(pred.period, rel=0.01)


def test_the_trivial_multiplier_is_the_one_along_the_orbit():
    """Near a Hopf point the amplitude's multiplier comes within the differences' error of the trivial one (1,
    eigenvector along the flow). Measured on a newcomer's configuration: the trivial one read 1.0000061, the other
    0.999996; removing the one nearest 1 left 1.0000061 and called a stable orbit unstable. Removed by its
    eigenvector instead, the orbit is stable; without a direction the old rule stays."""
    from rotorub_model.analyses.continuation.periodic import MULTIPLIER_TOL, _multipliers

    rng = np.random.default_rng(3)
    V = rng.standard_normal((6, 6))
    rho = np.array([1.0000061, 0.999996, 0.8, 0.5, 0.3, 0.1])
    D = V @ np.diag(rho) @ np.linalg.inv(V)
    kept = _multipliers(D, along=V[:, 0] * 2.5)
    assert np.abs(kept).max() == pytest.approx(0.999996, abs=1e-9) and np.abs(kept).max() < 1 + MULTIPLIER_TOL
    assert np.abs(_multipliers(D)).max() == pytest.approx(1.0000061, abs=1e-9)  # the nearest-to-1 rule


def test_continuation_solves_on_one_blas_thread_and_a_large_problem_keeps_its_threads(monkeypatch, ref_model):
    """Continuation's many small static solutions and eigenproblems run on one BLAS thread (rotorub_model/threads.py:
    an 18-blade configuration at load 5.5 took 2 min 57 s with OpenBLAS's thread per core, 44 s on one); a problem of
    BLAS_THREADS_FROM unknowns or more keeps the caller's threads."""
    from threadpoolctl import threadpool_info, threadpool_limits

    import rotorub_model.analyses.continuation.study as study
    from rotorub_model.threads import BLAS_THREADS_FROM, blas_threads

    def blas():
        return {i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}

    seen = []

    def spy(*args, **kwargs):
        seen.append(blas())
        raise RuntimeError("stop here")

    monkeypatch.setattr(study, "_run_continuation", spy)
    with threadpool_limits(limits=2):  # a user's process: a thread per core (the suite's conftest pins one)
        with pytest.raises(RuntimeError, match="stop here"):
            study.run_continuation(ref_model, speeds=np.array([3.0, 3.5]), g0s=np.array([0.0, 1e-3]))
        with blas_threads(BLAS_THREADS_FROM):
            seen.append(blas())
        after = blas()
    assert seen[0] <= {1}, seen
    assert seen[1] == after, (seen, after)  # the caller's limit, unchanged
