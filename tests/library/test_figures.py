"""What the figures show (issue 18, points 5 and 7): 3D drawn over 2D, sweep curves told apart, stable vs
unstable cells by colour with a scale, legends outside the data; and what the stability maps call a cell
without a solution (solved from a contact-set start, proven absent, or the solver's failure)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from rotorub_model.analyses import discretisation, maps
from rotorub_model.analyses.detection import run_detection
from rotorub_model.analyses.maps import NO_EQUILIBRIUM, NOT_CONVERGED, ContactSetStarts, run_stability_map
from rotorub_model.analyses.transient import run_transient
from rotorub_model.app import studies
from rotorub_model.app.studies import default_grid
from rotorub_model.contact import make_contact
from rotorub_model.plotting import pyplot
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters


@pytest.fixture(scope="module")
def det(ref_model):
    return run_detection(ref_model, n_speeds=80, n_g0=30, progress=False)


@pytest.fixture
def captured():
    """Figures the tests draw through the result objects' figure(), laid out, drawn, closed at the end."""
    figs = []
    yield figs
    for f in figs:
        pyplot().close(f)


def _drawn(figs: list, fig):
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    fig.canvas.draw()
    figs.append(fig)
    return fig


def _legends(fig) -> list:
    return [*fig.legends, *(a.get_legend() for a in fig.axes if a.get_legend() is not None)]


def assert_legends_hide_nothing(fig) -> None:
    """Every legend lies outside every data axes (colourbars aside): it cannot cover a curve or a cell."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    data_axes = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    assert _legends(fig), "no legend at all"
    for leg in _legends(fig):
        box = leg.get_window_extent(r)
        for ax in data_axes:
            assert not box.overlaps(ax.get_window_extent(r)), (leg.get_texts()[0].get_text(), ax.get_title())


# ----------------------------------------------------------------------------- point 1, 2: detection


def test_detection_draws_3d_above_2d_and_lets_2d_show_through(det):
    fig = det.figure("2d_3d")
    try:
        for ax in fig.axes:
            z = {k: [a.get_zorder() for a in ax.get_children() if a.get_gid() == k] for k in ("2D", "3D")}
            assert len(z["2D"]) == len(z["3D"]) == 2, z  # fill and closure line each
            assert min(z["3D"]) > max(z["2D"]), z
            fill_3d = next(a for a in ax.collections if a.get_gid() == "3D")
            assert fill_3d.get_hatch() and not np.any(fill_3d.get_facecolor()[:, 3] > 0)  # a hatch, no face
        assert_legends_hide_nothing(fig)
    finally:
        pyplot().close(fig)


@pytest.mark.parametrize("study", ["theta", "chord"])
def test_sweep_curves_differ_in_colour_style_and_marker(det, study):
    fig = det.figure(study)
    try:
        for ax in fig.axes:
            lines = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2]
            looks = {(to_rgb(ln.get_color()), str(ln.get_linestyle()), ln.get_marker()) for ln in lines}
            assert len(lines) >= 5 and len(looks) == len(lines)
            colours = [np.array(to_rgb(ln.get_color())) for ln in lines]
            gaps = [np.linalg.norm(a - b) for i, a in enumerate(colours) for b in colours[i + 1:]]
            assert min(gaps) > 0.15, min(gaps)
            assert ax.get_xlabel().endswith("[-]") and "[mm]" in ax.get_ylabel()
        assert_legends_hide_nothing(fig)
    finally:
        pyplot().close(fig)


# ----------------------------------------------------------------------------- point 4: cells without a solution


@pytest.fixture(scope="module")
def stiff():
    """A ten times stiffer contact: the quick map's flank past the first critical, where the branch continued in
    g0 folds (measured before the contact-set starts: 62 2D and 66 3D cells "no equilibrium")."""
    m = build_model(reference_parameters().replace(contact={"k_r": 1.5e7}))
    speeds, g0s = default_grid(m, quick=True)
    return m, speeds, g0s


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_stiff_flank_cells_are_solved_from_contact_sets(stiff, formulation, monkeypatch):
    m, speeds, g0s = stiff
    speeds = speeds[[20, 22, 27]]  # 3.51, 3.59, 3.80: 24 of those cells
    mp = run_stability_map(m, formulation, speeds, g0s, executor="serial", progress=False)
    s = mp.summary()
    assert s["no_equilibrium_points"] == 0 and s["not_converged_points"] == 0
    assert s["found_from_contact_set_points"] >= 3
    assert mp.converged.all() and np.isfinite(mp.max_real).all()
    # without the contact-set starts the same cells fail, and are counted as the solver's failures, not as a
    # proven absence
    monkeypatch.setattr(ContactSetStarts, "find", lambda self, g0, near: (None, False))
    bare = run_stability_map(m, formulation, speeds, g0s, executor="serial", progress=False).summary()
    assert bare["not_converged_points"] >= 8 and bare["no_equilibrium_points"] == 0


def test_a_contact_set_solution_is_an_equilibrium(stiff):
    """The affine law of a contact set, built from the kernel's law blade by blade, is the kernel's law: a set
    consistent with its gaps solves the full residual (what makes the 2D enumeration a proof)."""
    m, speeds, _ = stiff
    omega = float(speeds[22]) * m.params.normalisation.omega_ref
    base = make_contact(m, "2D")
    cs = ContactSetStarts(m, base, omega)
    g0 = 1.3e-3
    qs, ok, viol, regular = cs.solve(cs.every_set(), g0)
    assert regular and ok.sum() >= 1 and np.all(viol[ok] == 0.0)
    c = base.with_clearance(g0)
    for q in qs[ok]:
        r = m.K_omega(omega) @ q - c.forces(q, omega) - m.force(omega)
        assert np.linalg.norm(r) <= 1e-10 * np.linalg.norm(m.force(omega))


def test_proven_absence_and_failure_are_told_apart(stiff, monkeypatch, captured):
    """Bookkeeping of the two kinds: a 2D cell whose every contact set is inconsistent is NO_EQUILIBRIUM, a 3D
    one the solver could not solve NOT_CONVERGED; the summary counts each, the figure's legend names each."""
    m, speeds, g0s = stiff
    monkeypatch.setattr(maps, "solve_static", _failing_at(maps.solve_static, g0s[20]))
    monkeypatch.setattr(ContactSetStarts, "find", lambda self, g0, near: (None, self.base.formulation == "2D"))
    # at the lowest speed every cell converges by itself: only the one made to fail has no solution
    got = {f: run_stability_map(m, f, speeds[:2], g0s, executor="serial", progress=False) for f in ("2D", "3D")}
    assert got["2D"].n_contact[0, 20] == NO_EQUILIBRIUM and got["3D"].n_contact[0, 20] == NOT_CONVERGED
    s2, s3 = got["2D"].summary(), got["3D"].summary()
    assert (s2["no_equilibrium_points"], s2["not_converged_points"]) == (2, 0)
    assert (s3["no_equilibrium_points"], s3["not_converged_points"]) == (0, 2)
    fig = _drawn(captured, maps.maps_figure(got))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(lab.startswith("no equilibrium") for lab in labels)
    assert any(lab.startswith("solver did not converge") for lab in labels)


def _failing_at(solve, g0_bad: float):
    def solve_static(model, contact, omega, **kw):
        st = solve(model, contact, omega, **kw)
        if contact.g0 == g0_bad:
            st.converged = False
        return st

    return solve_static


# ----------------------------------------------------------------------------- point 3: stability colours


def test_stable_and_unstable_cells_cannot_be_confused(stiff, captured):
    m, speeds, g0s = stiff
    mp = run_stability_map(m, "3D", speeds[[20, 22, 27]], g0s, executor="serial", progress=False)
    assert mp.unstable.any() and (mp.contact & ~mp.unstable).any()
    fig = _drawn(captured, mp.figure())
    stable = np.array(to_rgb(maps.STABLE_COLOUR))
    scale = maps.unstable_cmap()(np.linspace(0.0, 1.0, 256))[:, :3]
    assert np.min(np.linalg.norm(scale - stable, axis=1)) > 0.5  # not one shade of the scale is near it
    bars = [a for a in fig.axes if a.get_label() == "<colorbar>"]
    assert len(bars) == 2
    assert any("[1/s]" in b.get_ylabel() for b in bars) and any("blades in contact" in b.get_ylabel() for b in bars)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(lab.startswith("stable") for lab in labels)
    assert_legends_hide_nothing(fig)


# ----------------------------------------------------------------------------- point 5: legends


def test_transient_legends_are_outside_the_data(ref_model, captured):
    runs = {f: run_transient(ref_model, make_contact(ref_model, f, g0=0.2e-3), 3.3 * 53.4, t_end=1.2)
            for f in ("2D", "3D")}
    _drawn(captured, runs["2D"].figure())
    _drawn(captured, studies.TransientStudy(3.3, 0.2e-3, runs, {}).figure())
    assert len(captured) == 2
    for fig in captured:
        assert_legends_hide_nothing(fig)
        for ax in fig.axes:
            assert ax.get_xlabel() in ("", "time [s]") and "[" in ax.get_ylabel()
    blades = [t.get_text() for t in captured[1].legends[0].get_texts() if t.get_text().startswith("blade")]
    assert len(blades) == len(set(blades)) >= 2  # one legend for both panels, each blade once


def test_discretisation_legends_are_outside_the_data(captured):
    res = discretisation.run_blade_convergence(reference_parameters(), n_values=(2, 3), n_speeds=3)
    assert_legends_hide_nothing(_drawn(captured, res.figure()))


# ----------------------------------------------------------------------------- issue 25.4: figures show their data
def _synthetic_maps():
    """Two small maps whose contact region stops at half the grid's clearances, with different growth rates."""
    speeds, g0s = np.linspace(3.0, 4.0, 6), np.linspace(0.0, 8e-3, 9)
    out = {}
    for f, rate in (("2D", 1.0), ("3D", 0.01)):
        n = np.zeros((6, 9), dtype=int)
        n[:, :4] = 3  # contact up to g0 = 3 mm of 8
        unstable = np.zeros((6, 9))
        unstable[2:4, :3] = rate
        out[f] = maps.StabilityMap(f, speeds, g0s, n, np.zeros((6, 9)), np.where(unstable > 0, unstable, -1.0),
                                   unstable, np.ones((6, 9)))
    return out


def test_a_maps_clearance_axis_ends_where_its_contact_does_and_2d_3d_share_one_scale(captured):
    """The issue: the maps' g0 axis ran to 8.5 mm for data that stopped at 3-5 mm, and 2D and 3D had their own
    colour scales (the same colour, different growth rates)."""
    got = _synthetic_maps()
    fig = _drawn(captured, maps.maps_figure(got))
    data_axes = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    top = data_axes[0].get_ylim()[1]
    assert 3.0 < top < 4.5, top  # the grid goes to 8 mm
    assert "cut at" in fig._suptitle.get_text() and "8 mm" in fig._suptitle.get_text()
    meshes = [c for a in data_axes for c in a.collections if getattr(c, "norm", None) is not None
              and type(c.norm).__name__ == "LogNorm"]
    assert len(meshes) == 2 and meshes[0].norm is meshes[1].norm  # one scale for the 2D and the 3D panel
    assert meshes[0].norm.vmin == pytest.approx(0.01) and meshes[0].norm.vmax == pytest.approx(1.0)
    bars = [a for a in fig.axes if a.get_label() == "<colorbar>"]
    assert len(bars) == 2  # one per column, not one per panel


def test_the_modes_figure_is_in_the_fixed_frame(ref_model, captured):
    """README and --help promise fixed-frame frequencies; the figure plotted the rotating-frame ones against Re,
    twelve eigenvalues on top of each other near Re = 0. Now: fixed-frame frequency against the damping ratio
    (log), each mode labelled with its nodal diameter."""
    from rotorub_model.analyses.linear import run_modes

    r = run_modes(ref_model, 3.49)
    fig = _drawn(captured, r.figure())
    ax = fig.axes[0]
    assert "fixed-frame frequency" in ax.get_xlabel() and ax.get_yscale() == "log"
    xy = ax.collections[0].get_offsets()
    np.testing.assert_allclose(np.sort(xy[:, 0]), np.sort(r.fixed_frame_hz))
    assert len(ax.texts) == len(r.fixed_frame_hz)
    assert "fixed frame" in ax.get_title() and "all damped" in ax.get_title()


def test_the_campbell_legend_names_the_dots(ref_model, captured):
    from rotorub_model.analyses.linear import run_campbell

    fig = _drawn(captured, run_campbell(ref_model, 10.0, 40).figure())
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("one mode at one speed" in lab for lab in labels) and any("1X" in lab for lab in labels)


def test_the_detection_variants_read_fact_3(det, captured):
    """detection_variants.png drew the differences on an unmarked symlog axis, fact 3's 0.0785 mm inside an
    unreadable block at the first critical: now |difference| on a log axis, the largest of each curve marked and
    named in the legend, fact 3's 0.1 mm bound drawn, a zoom on the first critical."""
    fig = _drawn(captured, det.figure("variants"))
    lower = [a for a in fig.axes[1:3]]
    assert all(a.get_yscale() == "log" for a in lower)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    geo = float(np.max(np.abs(det.closures["3D geometry only"] - det.closures["2D"]))) * 1e3
    assert any(lab.startswith("|3D geometry only − 2D| (largest") and f"{geo:.3g} mm" in lab for lab in labels)
    assert any("0.1 mm" in lab for lab in labels)
    lo, hi = lower[1].get_xlim()
    assert hi - lo < 0.2 * (det.speeds[-1] - det.speeds[0])  # the zoom


def _continuation():
    from rotorub_model.analyses.continuation.boundary import Curve
    from rotorub_model.analyses.continuation.branch import Branch, Special
    from rotorub_model.analyses.continuation.equilibria import Point
    from rotorub_model.analyses.continuation.periodic import Orbit, OrbitBranch
    from rotorub_model.analyses.continuation.study import ContinuationResult

    def pt(g0, stable):
        return Point(176.2, g0, np.zeros(2), (), 2, 100.0, 1e-4 + g0, None, -0.1 if stable else 0.1)

    pts = [pt(g, g > 0.5e-3) for g in np.linspace(0.7e-3, 0.0, 15)]
    b = Branch("2D", "g0", 176.2, pts, [Special("switch", pt(0.531e-3, False))], True, "reached g0 = 0")
    orbits = [Orbit(176.2, g, np.zeros(4), 0.02, np.array([0.5]), 1e-4, 4e-4, 150.0, 1e-10, 5e-4, 3e-4)
              for g in np.linspace(0.30e-3, 0.38e-3, 12)]
    ob = OrbitBranch("2D", 176.2, orbits, "stopped after 12 orbits", notes={"start": "transient",
                                                                             "seed_g0_m": 0.337e-3,
                                                                             "seed_transient_s": 40.0})
    curve = Curve([3.0, 3.2, 3.4, 3.5], [0.2e-3, 0.3e-3, 0.5e-3, 1e-3], ["switch", "switch", "fold", "fold"])
    return ContinuationResult(3.3, {"2D": b}, {"2D": [ob]}, {"2D": [curve]}, {"2D": {}}, {})


def test_the_continuation_figure_says_where_its_orbit_family_stops(captured):
    """The 2D orbit family stopped at 0.38 mm, cut off from its switch at 0.531 mm, without a word."""
    r = _continuation()
    fig = _drawn(captured, r.figure("branches"))
    text = " ".join(t.get_text() for t in fig.axes[0].texts).replace("\n", " ")
    assert "truncated: stopped after 12 orbits" in text and "not followed to the switch at 0.531 mm" in text
    assert r.summary()["2D"]["orbit_note"] == r.orbit_note("2D")


def test_the_boundaries_legend_matches_what_is_drawn(captured):
    """boundaries.png had a black legend line for coloured curves: each segment is now drawn in its kind's colour,
    and the legend has exactly the kinds drawn, as lines of those colours."""
    fig = _drawn(captured, _continuation().figure("boundaries"))
    ax = fig.axes[0]
    leg = {t.get_text(): h for t, h in zip(ax.get_legend().get_texts(), ax.get_legend().legend_handles)}
    assert set(leg) == {"boundary: contact-induced switch", "boundary: fold"}
    drawn = {to_rgb(ln.get_color()) for ln in ax.get_lines()}
    assert {to_rgb(h.get_color()) for h in leg.values()} == drawn
