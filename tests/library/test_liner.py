"""The abradable liner (issue 19): the law against its closed forms, conservation, cases whose answer is
known, and the rigid casing left as it was."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model import kernel
from rotorub_model.analyses.transient import run_transient
from rotorub_model.contact import make_contact
from rotorub_model.contact.liner import Liner
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters

K, FY = 1.5e6, 100.0  # the reference's contact stiffness and the default yield force


# ------------------------------------------------------------------------------------------- the law
@pytest.mark.parametrize("steps", [1, 7, 1000])
def test_an_incursion_beyond_yield_removes_exactly_what_is_beyond(steps):
    """A tip pushed into a rigidly backed liner by delta, in any number of increments: the force saturates at
    F_y, the depth removed is delta - F_y / k, the work is F_y times it."""
    delta, depth, work = 0.4e-3, 0.0, 0.0
    for g in np.linspace(0.0, -delta, steps + 1)[1:]:
        f, depth, w = kernel.liner_law(g, K, FY, 0.0, 2e-3, depth)
        work += w
    assert f == pytest.approx(FY, rel=1e-12)
    assert depth == pytest.approx(delta - FY / K, rel=1e-12)
    assert work == pytest.approx(FY * depth, rel=1e-12)
    # below yield nothing is removed: the liner is elastic
    f, d, w = kernel.liner_law(-0.5 * FY / K, K, FY, 0.0, 2e-3)
    assert (f, d, w) == (pytest.approx(0.5 * FY), 0.0, 0.0)


@pytest.mark.parametrize("steps", [1, 50])
def test_hardening_follows_the_closed_form_force_incursion_curve(steps):
    """With linear hardening H: F(delta) = k delta up to F_y / k, then F_y + H (k delta - F_y) / (k + H); the
    depth (k delta - F_y) / (k + H); the work F_y w + H w^2 / 2."""
    H = 4.0e5
    depth = work = 0.0
    for delta in np.linspace(0.0, 0.5e-3, steps + 1)[1:]:
        f, depth, w = kernel.liner_law(-delta, K, FY, H, 2e-3, depth)
        work += w
        if delta <= FY / K:
            assert f == pytest.approx(K * delta) and depth == 0.0
        else:
            w_exact = (K * delta - FY) / (K + H)
            assert depth == pytest.approx(w_exact, rel=1e-12)
            assert f == pytest.approx(FY + H * w_exact, rel=1e-12)
    assert work == pytest.approx(FY * depth + 0.5 * H * depth**2, rel=1e-12)


def test_unloading_is_elastic_and_the_thickness_stops_the_wear():
    f, d, _ = kernel.liner_law(-0.3e-3, K, FY, 0.0, 2e-3)
    f2, d2, w2 = kernel.liner_law(-0.28e-3, K, FY, 0.0, 2e-3, d)  # backing off: elastic, nothing removed
    assert d2 == d and w2 == 0.0 and f2 == pytest.approx(K * (0.28e-3 - d))
    f3, d3, _ = kernel.liner_law(-5e-3, K, FY, 0.0, 2e-3)  # through the liner: stops at the substrate
    assert d3 == 2e-3 and f3 == pytest.approx(K * 3e-3)
    f4, d4, w4 = kernel.liner_law(-0.3e-3, K, FY, 0.0, 2e-3, wears=False)  # a fixed surface does not wear
    assert d4 == 0.0 and w4 == 0.0 and f4 == pytest.approx(K * 0.3e-3)


def test_bad_liner_parameters_are_refused_with_their_range():
    m = build_model()
    c = make_contact(m, "2D")
    for kw, text in (({"yield_force": 0.0}, "yield_force"), ({"thickness": -1.0}, "thickness"),
                     ({"n_sectors": 4}, r"n_sectors.*\[8, 100000\]"), ({"hardening": float("nan")}, "hardening")):
        with pytest.raises(ParameterError, match=text):
            Liner.for_model(m, c, **kw)
    with pytest.raises(ParameterError, match="abradable.yield_force"):
        reference_parameters().replace(abradable={"yield_force": -1.0})


# ------------------------------------------------------------------------------------------- in a run
@pytest.fixture(scope="module")
def model():
    return build_model()


def test_the_rigid_casing_is_left_as_it_was(model):
    """A surface that does not wear, with no closure and no offset, gives the rigid casing's run bit for bit,
    in 2D and 3D; and the parameter file's liner is off by default."""
    assert not model.params.abradable.enabled
    w = 3.3 * model.params.normalisation.omega_ref
    for f in ("2D", "3D"):
        c = make_contact(model, f, g0=0.335e-3)
        a = run_transient(model, c, w, t_end=2.0)
        b = run_transient(model, c, w, t_end=2.0, liner=Liner.for_model(model, c, wears=False))
        np.testing.assert_array_equal(a.q, b.q)
        assert b.wear["summary"]["depth_max"] == 0.0


@pytest.fixture(scope="module")
def offset_run(model):
    """A casing moved 0.3 mm along +x over a centred rotor (no imbalance, 0.5 Omega_ref: the rotor stays
    put), g0 = 0.2 mm: the gap is g0 + 0.3 mm cos(theta), smallest at theta = pi."""
    c = make_contact(model, "2D", g0=0.2e-3)
    liner = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0))
    r = run_transient(model, c, 0.5 * model.params.normalisation.omega_ref, t_end=1.0, me=0.0, t_ramp=0.0,
                      liner=liner)
    return r, liner


def test_an_offset_casing_wears_where_the_gap_is_smallest_and_nowhere_else(offset_run):
    """The worn depth is the penetration beyond yield, -(g0 + e cos theta) - F_y / k_r, around theta = pi and
    zero elsewhere: the closed form of a rigid structure, which the flexible rotor meets within 2 % at its
    deepest point."""
    r, liner = offset_run
    th = liner.angles
    exact = np.maximum(-(0.2e-3 + 0.3e-3 * np.cos(th)) - FY / K, 0.0)
    prof = liner.profile
    assert prof.max() == pytest.approx(exact.max(), rel=0.05)
    assert abs(th[np.argmax(prof)] - np.pi) < np.radians(2.0)
    cell = 2 * np.pi / liner.n_sectors
    far = np.abs(np.angle(np.exp(1j * (th - np.pi)))) > np.arccos((0.2e-3 + FY / K) / 0.3e-3) + 2 * cell
    assert far.sum() > 0.8 * liner.n_sectors and prof[far].max() == 0.0, "wear away from the tightest gap"
    # the rotor gives way under the rub (its fan disk moves ~35 microns): never more wear than a rigid
    # structure would leave, the region 3 degrees narrower at each edge
    assert np.all(prof <= exact + 0.02 * exact.max())
    assert np.sum(prof > 0) >= 0.85 * np.sum(exact > 0)
    assert r.wear["summary"]["lobes"] == 1


def test_removed_volume_and_plastic_work_are_the_profiles(offset_run, model):
    """The volume is the integral of the worn profile over the casing (cell area x depth) to round-off, and the
    plastic work what the law says for a liner cut monotonically: sum of F_y w + H w^2 / 2 over the cells."""
    _, liner = offset_run
    s = liner.summary()
    assert s["volume"] == pytest.approx(np.sum(liner.profile) * liner.cell_area, rel=1e-12)
    # the law is a tip's: the work is the yield pressure F_y / A_tip times the volume
    assert s["plastic_work"] == pytest.approx(FY / liner.tip_area * s["volume"], rel=1e-9)
    assert s["depth_max"] == liner.depth.max()
    # 3D: two rows (LE, TE), each end carrying half the chord
    c = make_contact(model, "3D", g0=0.2e-3)
    l3 = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0), hardening=2e5)
    run_transient(model, c, 0.5 * model.params.normalisation.omega_ref, t_end=0.5, me=0.0, t_ramp=0.0, liner=l3)
    d = l3.depth
    assert d.max() > 0
    w = l3.cell_area / l3.tip_area
    assert l3.plastic_work == pytest.approx(0.5 * w * np.sum(FY * d + 0.5 * 2e5 * d**2), rel=1e-9)
    assert l3.summary()["volume"] == pytest.approx(d.mean(axis=0).sum() * l3.cell_area, rel=1e-12)


def test_volume_and_work_converge_with_the_cells(model):
    """The offset casing's wear with 360, 1440 and 2880 cells: volume and plastic work converge, so the work is
    the liner's, not its discretisation's. The offset is there at t = 0, with every blade's cell in its way cut at
    once (the exact return map, before the rotor is pushed away): one cell per blade deeper than the rest of the
    arc, a volume of order 1 / cells, so the convergence is first order (measured: 0.86 % from 360 to 2880 cells,
    0.113 % from 1440; the ratio 0.132 against first order's 0.143)."""
    out = {}
    for ns in (360, 1440, 2880):
        c = make_contact(model, "2D", g0=0.2e-3)
        liner = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0), n_sectors=ns)
        run_transient(model, c, 0.5 * model.params.normalisation.omega_ref, t_end=1.0, me=0.0, t_ramp=0.0,
                      liner=liner)
        out[ns] = liner.summary()
    first_order = (1 / 1440 - 1 / 2880) / (1 / 360 - 1 / 2880)
    for key in ("volume", "plastic_work"):
        coarse, fine, finest = (out[ns][key] for ns in (360, 1440, 2880))
        assert abs(coarse - finest) < 2e-2 * finest and abs(fine - finest) < 2e-3 * finest
        assert abs(fine - finest) == pytest.approx(first_order * abs(coarse - finest), rel=0.15)


def _stationary_backward_wave(model, h):
    """The speed where the blades' backward travelling wave of nodal diameter h stands still in the fixed
    frame (its rotating-frame frequency equals h Omega: engine order h), and its mode there. The blade-alone
    waves of every nodal diameter >= 2 share one frequency to 1e-12: the mode is chosen by its label (index
    -h, the wave that stands still in the fixed frame), never by its frequency alone."""
    from scipy.optimize import brentq

    from rotorub_model.analyses.linear import _free_modes, _labels

    wref = model.params.normalisation.omega_ref

    def standing(s):
        lam, phi = _free_modes(model, np.array([s * wref]))[0]
        _, harm = _labels(model, lam, phi, s * wref)
        i = np.flatnonzero((harm == -h) & (np.abs(lam.imag) > 1.0))
        k = i[np.argmin(np.abs(lam[i].imag - h * s * wref))]
        return lam[k], phi[:, k]

    s = brentq(lambda s: standing(s)[0].imag - h * s * wref, 0.3, 6.0, xtol=1e-12)
    lam, phi = standing(s)
    return s, lam, phi


@pytest.mark.parametrize("h", [2, 3])
def test_a_vibration_locked_to_engine_order_h_leaves_h_lobes(model, h):
    """The literature's criterion (a blade vibration whose pattern stands still in the casing's frame, its
    frequency an engine order h of the spin, wears the liner in h lobes): started on the blades' backward
    wave of nodal diameter h at the speed where it stands still, the worn profile's dominant harmonic is h
    (3D: the blades' bending reaches the gap through the cone and the chord's tilt)."""
    s, lam, phi = _stationary_backward_wave(model, h)
    c = make_contact(model, "3D", g0=0.1e-3)  # 2D: the blades' bending does not move the tip radially
    tip = np.abs(c.G @ phi).max()
    q0 = np.real(phi) * (0.25e-3 / tip)
    v0 = np.real(lam * phi) * (0.25e-3 / tip)
    liner = Liner.for_model(model, c, wears=True)
    r = run_transient(model, c, s * model.params.normalisation.omega_ref, t_end=0.3, me=0.0, t_ramp=0.0, q0=q0,
                      v0=v0, liner=liner)
    sm = r.wear["summary"]
    assert sm["depth_max"] > 20e-6, "the vibration must reach the liner"
    amps = [sm[f"harmonic_{k}"] for k in range(1, 9)]
    assert sm["lobes"] == h, amps
    # a pattern of h-fold symmetry holds only multiples of h; the run's drift (the contact detunes the
    # vibration) leaves the others small (measured: 0 for h = 2, 0.02 a_h for h = 3)
    assert amps[h - 1] > 10 * max(a for k, a in enumerate(amps, 1) if k % h)


def test_a_wearing_run_creates_no_energy(undamped):
    """Undamped, frictionless, at constant spin: the energy (kinetic, strain, penalty energy against the worn
    surface) of a rub into a liner never rises, and the cuts take energy out: below the rigid casing's run."""
    from rotorub_model.analyses.energy import contact_potential_of_gaps

    T, _ = undamped.disk_maps
    v0 = np.linalg.pinv(T[:2]) @ np.array([0.3, 0.1])
    omega, dt = 1.0, 5e-5
    energies = {}
    for wears in (False, True):
        c = make_contact(undamped, "2D", g0=0.2e-3, mu=0.0)
        liner = Liner.for_model(undamped, c, wears=wears, yield_force=30.0)
        r = run_transient(undamped, c, omega, t_end=0.3, me=0.0, q0=np.zeros(undamped.n_dofs), v0=v0,
                          record_dt=1e-12, t_ramp=0.0, dt=dt, max_penetration=0.01, liner=liner)
        q = np.vstack([np.zeros(undamped.n_dofs), r.q])
        v = (q[2:] - q[:-2]) / (2 * dt)
        qm = q[1:-1]
        Ks = undamped.K_omega(omega)
        Ks = 0.5 * (Ks + Ks.T)
        e = 0.5 * np.einsum("ti,ij,tj->t", v, undamped.M, v) + 0.5 * np.einsum("ti,ij,tj->t", qm, Ks, qm)
        e = e + contact_potential_of_gaps(c, r.outputs["gap"][:-1])
        energies[wears] = (e, r)
    e0, r0 = energies[False]
    e1, r1 = energies[True]
    assert r1.wear["summary"]["depth_max"] > 10e-6 and r1.outputs["F_N"].max() > 20.0
    rise0 = float(np.max(e0 - np.minimum.accumulate(e0)) / e0[0])
    rise1 = float(np.max(e1 - np.minimum.accumulate(e1)) / e1[0])
    assert rise1 <= max(2 * rise0, 1e-6), (rise1, rise0)
    assert e1[-1] < e0[-1] - 0.01 * e0[0]  # the liner took energy out


def test_the_kernels_constants_are_the_librarys_and_the_interfaces():
    from pathlib import Path

    from fmu_src.models.contact import variables as interface

    header = (Path(kernel.__file__).parent / "rotorub_kernel.h").read_text()
    assert f"#define RR_WEAR_HARMONICS {kernel.WEAR_HARMONICS} " in header
    assert interface.WEAR_HARMONICS == kernel.WEAR_HARMONICS
    assert f"#define RR_ABI_VERSION {kernel.ABI_VERSION}" in header


def test_the_wear_command_writes_its_figures_and_refuses_bad_inputs(tmp_path, capsys):
    import json

    from rotorub_model.app.cli import main

    out = tmp_path / "wear"
    assert main(["wear", "--speed", "3.3", "--g0", "0.335e-3", "--t-end", "3", "--offset-x", "0.2e-3",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    for f in ("2D", "3D"):
        s = json.loads((out / f / "wear.json").read_text())
        assert s["casing_offset_mm"] == [0.2, 0.0] and s["depth_max_mm"] > 0
        for png in ("wear_map.png", "wear_profile.png", "forces.png"):
            assert (out / f / png).stat().st_size > 10_000
    assert main(["wear", "--closure", "0.5", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "--closure" in err and "[-0.01, 0.01] m" in err


# --------------------------------------------------------------------------- the engine's inputs changing mid-run
@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_a_jump_while_cutting_keeps_the_force_and_cuts_exactly_the_jump(formulation):
    """A blade cutting the liner at rest (Omega = 0) while the engine pushes the casing into it (the offset grows
    by 2 um a millisecond), and the same run with the offset jumping 10 um more at one communication point: the
    exact return map cuts the jump away before the first force, so the force stays at the yield bound and the
    structure does not move differently (below 1e-9 m), and the blade's cell is cut deeper by exactly the jump
    seen along the normal (within 0.1 %). Three blades, so that the blade that cuts is the only one touching (the
    others, 120 deg away, stay open). Before the map saw the new surface, the first step's force was the uncapped
    elastic one: 1.8 um of motion, a cut 10.11 um deep for a 10 um jump."""
    m = build_model(reference_parameters().replace(blades={"count": 3}))
    c = make_contact(m, formulation, g0=0.1e-3)
    jump = 10e-6
    runs = []
    for with_jump in (False, True):
        liner = Liner.for_model(m, c, wears=True, thickness=5e-3)
        state, q = None, []
        for k in range(60):
            e = 0.16e-3 + 2e-6 * k + (jump if with_jump and k >= 40 else 0.0)
            liner.set_inputs(offset=(-e, 0.0))  # towards -x: closes the gap of the blade at alpha = 0
            if k == 40:
                before = liner.depth.copy()
            r = run_transient(m, c, 0.0, t_end=1e-3, me=0.0, t_ramp=0.0, liner=liner, start=state)
            state = r.final_state
            if k == 40:
                after = liner.depth.copy()
            if k >= 40:
                q.append(r.q)
        runs.append((np.vstack(q), before, after, liner, r))
    (q0, b0, a0, _, r0), (q1, b1, a1, liner, r1) = runs
    assert np.array_equal(b0, b1) and 0.99 * FY < r0.outputs["F_N"][-1, 0] <= FY * (1 + 1e-12), "cutting"
    assert (r0.outputs["F_N"][-1, 1:] == 0).all(), "the other blades stay open"
    assert np.abs(q1 - q0).max() < 1e-9
    extra = (a1 - b1) - (a0 - b0)  # what the jump cut, on top of the ramp's own increment
    cut = extra > 0
    nr = np.hypot(*c.geometry.normals[0, :, :2].T)  # the cutting points' normals' radial parts
    expected = jump * nr[:, None] * np.cos(liner.angles)[None, :]
    assert cut.sum() == c.n_points  # one cell per point of the one blade
    np.testing.assert_allclose(extra[cut], expected[cut], rtol=1e-3)
    np.testing.assert_allclose(r1.outputs["F_N"][:, 0], r0.outputs["F_N"][:, 0], rtol=1e-9)


def test_a_continued_run_meets_the_liner_where_it_left_it(model):
    """Two runs of 0.5 s, the second going on from the first's final state (frame angle, both states, the worn
    profile), are one run of 1 s, to round-off (the frame angle is summed in two parts): the rotor meets the worn
    liner at the angle it left it. (A second run that restarted the angle at 0 met cells cut by another blade: 12
    cells cut up to 13.7 um deeper in two steps.)"""
    w = 1.0 * model.params.normalisation.omega_ref
    c = make_contact(model, "2D", g0=0.2e-3)
    one = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0))
    r1 = run_transient(model, c, w, t_end=1.0, me=0.0, t_ramp=0.0, liner=one)
    two = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0))
    a = run_transient(model, c, w, t_end=0.5, me=0.0, t_ramp=0.0, liner=two)
    b = run_transient(model, c, w, t_end=0.5, me=0.0, t_ramp=0.0, liner=two, start=a.final_state)
    assert b.final_state.phi == pytest.approx(w * 1.0, rel=1e-12) and b.t[0] > 0.5
    np.testing.assert_allclose(np.vstack([a.q, b.q]), r1.q, rtol=0, atol=1e-10 * np.abs(r1.q).max())
    np.testing.assert_allclose(two.depth, one.depth, rtol=0, atol=1e-10 * one.depth.max())
    assert one.depth.max() > 0
    with pytest.raises(ParameterError, match="start: the previous run had a liner"):
        run_transient(model, c, w, t_end=0.1, start=a.final_state)


# --------------------------------------------------------------------------- the casing out of round
def test_an_oval_casing_opens_and_closes_the_gaps_where_its_lobes_are(model):
    """A rigid surface with lobes n = 2 and 3: every point's gap is the round casing's plus n_r sum_n a_n
    cos(n (alpha + phi - psi_n)), at any frame angle (the kernel's tables against the closed form)."""
    import ctypes

    for formulation in ("2D", "3D"):
        c = make_contact(model, formulation, g0=1e-3)
        liner = Liner.for_model(model, c, wears=False, distortion={2: (0.2e-3, 0.3), 3: (-0.05e-3, 1.1)})
        seen = liner.attach(c.kernel)
        q = 1e-5 * np.random.default_rng(2).standard_normal(model.n_dofs)
        g = c.geometry
        alpha = np.arctan2(g.points[..., 1], g.points[..., 0])
        nr = np.hypot(g.normals[..., 0], g.normals[..., 1])
        for phi in (0.0, 0.7, 5.9, 40.1):
            liner.struct.phi = phi
            out = np.empty((c.n_blades, c.n_points))
            c.lib.rr_gaps_batch(ctypes.byref(seen), 1, kernel.ptr(np.ascontiguousarray(q)), kernel.ptr(out))
            exact = c.gaps(q) + nr * (0.2e-3 * np.cos(2 * (alpha + phi - 0.3))
                                      - 0.05e-3 * np.cos(3 * (alpha + phi - 1.1)))
            np.testing.assert_allclose(out, exact, atol=1e-15)
    for bad in ({1: (1e-4, 0.0)}, {9: (1e-4, 0.0)}, {2: (np.nan, 0.0)}, {2: 1e-4}):
        with pytest.raises(ParameterError, match="casing distortion"):
            Liner.for_model(model, c, wears=False, distortion=bad)


@pytest.mark.parametrize("speed", [0.5, 2.0])
def test_an_oval_casing_wears_two_lobes(model, speed):
    """A rotor spinning centred in an oval casing that closes the clearance at psi +- pi/2: the liner wears at
    the two tight places and nowhere else, to the rigid closed form -(g0 + a cos 2(theta - psi)) - F_y / k_r where
    positive, and the lobe rule reads 2. (At 0.5 and 2 Omega_ref: 2 % and 1e-15 over the closed form. At 1
    Omega_ref the blade passing, 10 Omega = 85 Hz, rings the ring's n = 2 mode, 74 Hz: 9 % over it, and a few
    cells worn within 0.6 deg outside the arc.)"""
    c = make_contact(model, "2D", g0=0.1e-3)
    psi, a = 0.4, 0.2e-3  # a > 0 opens the gap at psi: the tight places are psi +- pi/2
    liner = Liner.for_model(model, c, wears=True, distortion={2: (a, psi)})
    run_transient(model, c, speed * model.params.normalisation.omega_ref, t_end=1.0, me=0.0, t_ramp=0.0,
                  liner=liner)
    th = liner.angles
    exact = np.clip(-(0.1e-3 + a * np.cos(2 * (th - psi))) - FY / K, 0.0, None)
    prof = liner.profile
    assert prof.max() == pytest.approx(exact.max(), rel=0.03)
    assert np.all(prof[exact == 0] == 0.0)
    assert np.all(prof <= exact + 0.03 * exact.max())
    s = liner.summary()
    assert s["lobes"] == 2 and s["harmonic_2"] > 5 * max(s["harmonic_1"], s["harmonic_3"])
