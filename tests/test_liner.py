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
    """The offset casing's wear with 360, 1440 and 2880 cells: volume and plastic work converge (measured:
    1.1 % from 360 to 2880 cells, 0.014 % from 1440), so the work is the liner's, not its discretisation's."""
    out = {}
    for ns in (360, 1440, 2880):
        c = make_contact(model, "2D", g0=0.2e-3)
        liner = Liner.for_model(model, c, wears=True, offset=(0.3e-3, 0.0), n_sectors=ns)
        run_transient(model, c, 0.5 * model.params.normalisation.omega_ref, t_end=1.0, me=0.0, t_ramp=0.0,
                      liner=liner)
        out[ns] = liner.summary()
    for key in ("volume", "plastic_work"):
        coarse, fine, finest = (out[ns][key] for ns in (360, 1440, 2880))
        assert abs(fine - finest) < 1e-3 * finest and abs(coarse - finest) < 2e-2 * finest
        assert abs(fine - finest) < 0.1 * abs(coarse - finest)


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
