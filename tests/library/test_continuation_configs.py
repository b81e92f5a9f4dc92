"""The continuation study on configurations other than the reference (issue 18.4): contact switches
located whatever the step and never taken for Hopf points, no crash where a branch has no special
point, orbit or contact, the study speed from the configuration, and the boundary curves against the
quick grid maps on a matrix of configurations.

The matrix runs the whole study (quick maps, branches, orbits, curves) on five configurations: the
file takes 2 min 20 s on two shared cores (measured), half of it the 18-blade rotor."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.analyses.continuation import PAPER_SPEED, ContinuationResult, agreement, off_branch, run_continuation
from rotorub_model.analyses.continuation import branch as branch_mod
from rotorub_model.analyses.continuation.boundary import trace_boundaries
from rotorub_model.analyses.continuation.branch import HOPF_TOL, Branch, continue_static
from rotorub_model.analyses.continuation.equilibria import Equilibria
from rotorub_model.analyses.linear import run_response
from rotorub_model.analyses.maps import StabilityMap, run_stability_map
from rotorub_model.app.cli import build_parser
from rotorub_model.app.studies import default_grid
from rotorub_model.structure.model import Model, build_model
from rotorub_model.structure.params import Parameters, from_dict, reference_parameters, to_dict

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def configuration(name: str) -> Parameters:
    p = reference_parameters()
    if name == "reference":
        return p
    if name == "mu0.3":
        return p.replace(contact={"mu": 0.3})
    if name == "k_r x10":
        return p.replace(contact={"k_r": 10 * p.contact.k_r})
    if name == "18 blades":
        return p.replace(blades={"count": 18})
    if name == "disk moved":  # the fan disk at z = 0.15 m: its first critical moves from 3.49 to 4.86
        d = to_dict(p)
        d["disks"][0]["z"] = 0.15
        return from_dict(d)
    raise KeyError(name)


CONFIGURATIONS = ("reference", "mu0.3", "k_r x10", "18 blades", "disk moved")


# ---------------------------------------------------------------------------------------- unit tests

@pytest.fixture(scope="module")
def friction_model() -> Model:
    return build_model(configuration("mu0.3"))


@pytest.mark.parametrize("h_max", [0.01, 0.05, 0.2, 0.5])
def test_first_contact_switch_is_located_whatever_the_step(friction_model, h_max):
    """Friction 0.3, 2D at the paper's speed: the first blade's contact (g0 = 0.675 mm) makes the
    solution unstable (the point law's stiffness jumps). With steps of 1 % to 50 % of the 8.3 mm range
    it is located as a switch where the blade's gap vanishes, at the same clearance, and no Hopf point
    is reported: before the step's own planes replaced the chord's, the corrector cycled across the
    kink at the event and its switch was reported as a Hopf point with Re mu = -0.796 /s."""
    m = friction_model
    eq = Equilibria(m, "2D")
    w = PAPER_SPEED * m.params.normalisation.omega_ref
    b = continue_static(eq, "g0", w, 8.28e-3, 0.0, h_max=h_max)
    assert b.complete
    assert not b.of_kind("hopf") and not b.of_kind("unlocated")
    first = b.of_kind("contact")[0]
    sw = b.of_kind("switch")[0]
    assert sw.point is first.point  # the switch is the first contact event
    assert sw.point.g0 == pytest.approx(0.675085e-3, rel=1e-6)
    k = first.detail["point_index"]
    assert abs(eq.gaps(sw.point.q, sw.point.g0).ravel()[k]) <= 1e-9 * 8.28e-3
    assert sw.detail["left_real_part"] < 0 < sw.detail["right_real_part"]
    assert sw.detail["direction"] == "destabilising"


def test_a_change_of_stability_that_cannot_be_placed_is_not_a_hopf_point(friction_model, monkeypatch):
    """Where the corrector fails inside every step (simulated), the first contact's change of
    stability cannot be located: it is reported as "unlocated" with its reason, never as a Hopf point."""
    m = friction_model
    eq = Equilibria(m, "2D")
    w = PAPER_SPEED * m.params.normalisation.omega_ref
    original = branch_mod._Step.at

    def failing(self, s):
        return original(self, s) if s in (0.0, 1.0) else None

    monkeypatch.setattr(branch_mod._Step, "at", failing)
    b = continue_static(eq, "g0", w, 1.0e-3, 0.5e-3)
    assert b.complete and not b.of_kind("hopf")
    un = b.of_kind("unlocated")
    assert len(un) == 1 and "not located" in un[0].detail["reason"]


def test_stability_changes_at_a_fold_belong_to_the_fold():
    """3D, the moved disk at g0 = 1.8 mm in speed: past three Hopf points the branch turns back twice;
    at the second fold a real eigenvalue crosses zero with the static Jacobian singular. That change of
    stability is the fold's (noted on it), not an unlocated point, and every Hopf point is on the axis."""
    m = build_model(configuration("disk moved"))
    wr = m.params.normalisation.omega_ref
    eq = Equilibria(m, "3D")
    b = continue_static(eq, "omega", 1.8e-3, 4.85 * wr, 4.97 * wr)
    assert b.complete
    assert len(b.of_kind("hopf")) == 3 and len(b.of_kind("fold")) == 2
    assert not b.of_kind("unlocated")
    assert any(f.detail.get("stability_change") for f in b.of_kind("fold"))
    for h in b.of_kind("hopf"):
        assert abs(eq.critical(h.point.q, h.point.omega, h.point.g0)[0].real) <= HOPF_TOL


def test_no_crash_without_contact_special_points_or_orbits(tmp_path):
    """No imbalance, 2D: the disk stays on the axis, no blade ever touches (g0 >= 0), the branch has no
    special point and there is no orbit; the study still plots and writes its summary. (The branch
    reached g0 = 0 only once the corrector's residual had a scale without an imbalance load: 1e-10 of
    a zero load asked |R| <= 1e-40 N.)"""
    m = build_model(reference_parameters().replace(imbalance={"me": 0.0}))
    speeds, g0s = np.linspace(3.0, 3.6, 6), np.linspace(0.0, 2e-3, 6)
    r = run_continuation(m, speeds=speeds, g0s=g0s, formulations=("2D",))
    s = r.save(tmp_path)
    b = r.branches["2D"]
    assert b.complete and abs(b.points[-1].g0) < 1e-15 and all(p.n_contact == 0 for p in b.points)
    assert s["2D"]["specials"] == [] and s["2D"]["orbit_branches"] == [] and s["2D"]["boundary"]["curves"] == 0
    assert json.loads((tmp_path / "summary.json").read_text())["speed"] == PAPER_SPEED
    assert (tmp_path / "continuation.png").read_bytes()[:8] == PNG_MAGIC


def test_no_crash_on_an_empty_branch(tmp_path):
    """A branch without a single balanced solution (its start not found) still plots and is summarised."""
    empty = Branch("2D", "g0", 176.0, [], [], False, "no balanced solution at the start")
    r = ContinuationResult(3.3, {"2D": empty}, {"2D": []}, {}, {}, {})
    s = r.save(tmp_path)
    assert s["2D"]["branch"] == {"points": 0, "complete": False, "message": "no balanced solution at the start"}
    assert s["2D"]["special_counts"] == {"hopf": 0, "switch": 0, "fold": 0, "unlocated": 0}
    assert (tmp_path / "continuation.png").read_bytes()[:8] == PNG_MAGIC


def test_the_cli_leaves_the_speed_to_the_configuration():
    assert build_parser().parse_args(["continuation", "--quick"]).speed is None
    assert build_parser().parse_args(["continuation", "--speed", "3.1"]).speed == 3.1


# ------------------------------------------------------------------------------- the configuration matrix

@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """study(name) -> (model, ContinuationResult, summary read back from summary.json), run once each:
    the quick maps of both formulations, then the continuation study at the configuration's own speed."""
    cache: dict[str, tuple] = {}

    def run(name: str):
        if name not in cache:
            m = build_model(configuration(name))
            speeds, g0s = default_grid(m, quick=True)
            maps = {f: run_stability_map(m, f, speeds, g0s, executor="serial", progress=False) for f in ("2D", "3D")}
            r = run_continuation(m, maps=maps, quick=True)
            out = tmp_path_factory.mktemp("continuation")
            r.save(out)
            cache[name] = (m, r, json.loads((out / "summary.json").read_text()), out)
        return cache[name]

    return run


@pytest.mark.slow  # the first test of a configuration runs its whole study (maps, branches, curves): 20-60 s each
@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_summary_is_written_at_the_configurations_speed(study, name):
    m, r, s, out = study(name)
    for f in ("2D", "3D"):
        assert s[f]["branch"]["complete"], s[f]["branch"]
        assert set(s[f]["special_counts"]) == {"hopf", "switch", "fold", "unlocated"}
    for png in ("continuation.png", "boundaries.png"):
        assert (out / png).read_bytes()[:8] == PNG_MAGIC
    speeds = r.maps["2D"].speeds
    if speeds[0] <= PAPER_SPEED <= speeds[-1]:
        assert s["speed"] == PAPER_SPEED
    else:  # the moved disk: its grid is 4.06-5.66, and the branches are taken at its own first critical
        assert name == "disk moved"
        c1 = run_response(m, float(speeds[0]), float(speeds[-1]), 400).critical_speeds[0]
        assert s["speed"] == pytest.approx(c1, rel=1e-9) and abs(s["speed"] - 4.86) < 0.05


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_every_reported_hopf_point_is_on_the_axis(study, name):
    """(a) Every Hopf point of the summary has |Re mu| <= 1e-8 /s, recomputed from scratch (whole
    spectrum, then Newton) at its solution, and the stability changes across it; none is unlocated."""
    m, r, s, _ = study(name)
    for f, b in r.branches.items():
        assert s[f]["special_counts"]["unlocated"] == 0, s[f]["specials"]
        assert len(b.of_kind("hopf")) == s[f]["special_counts"]["hopf"]
        eq = Equilibria(m, f)
        for h in b.of_kind("hopf"):
            p = h.point
            mu, _ = eq.critical(p.q, p.omega, p.g0)
            assert abs(mu.real) <= HOPF_TOL, (f, p.g0, mu)
            assert abs(mu - p.mu) <= 1e-6 * abs(mu)
        for x in s[f]["specials"]:
            if x["kind"] == "hopf":
                assert abs(x["critical_eigenvalue"][0]) <= HOPF_TOL


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_every_change_of_stability_along_the_branch_is_located(study, name):
    """(b) Between any two neighbouring branch points whose verdicts differ lies a located switch, Hopf
    point or fold of that stability change; in 2D (at fixed speed the spectrum is constant between
    contact events) only switches; and a branch stepped 20 times coarser locates the same switches."""
    m, r, _, _ = study(name)
    for f, b in r.branches.items():
        st = b.stable()
        changes = np.flatnonzero(st[1:] != st[:-1])
        located = [x for x in b.specials if x.kind in ("switch", "hopf")
                   or (x.kind == "fold" and x.detail.get("stability_change"))]
        for i in changes:
            hi, lo = b.points[i].g0, b.points[i + 1].g0
            assert any(lo <= x.point.g0 <= hi for x in located), (f, lo, hi)
        assert len(located) >= len(changes)
        if f == "2D":
            assert not b.of_kind("hopf")
            assert len(b.of_kind("switch")) == len(changes) > 0
            coarse = continue_static(Equilibria(m, f), "g0", b.fixed, b.points[0].g0, 0.0, h_max=0.2)
            np.testing.assert_allclose([x.point.g0 for x in coarse.of_kind("switch")],
                                       [x.point.g0 for x in b.of_kind("switch")], rtol=1e-8)


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_boundary_curves_agree_with_the_grid_within_one_cell(study, name):
    """(c) No grid cell on the branch the map follows contradicts the side of the boundary curves it lies
    on beyond one cell of them (before: friction 0.3 3D 227 cells, the moved disk 294 (2D) and 319
    (3D)). Cells the map did not continue from that branch (past a cell solved from a contact-set start
    or left unsolved) are another equilibrium's, which the curves do not bound: those beyond one cell
    are counted in the summary with the reason (measured: k_r x 10, 3D, 5 cells, all of this kind)."""
    _, _, s, _ = study(name)
    for f in ("2D", "3D"):
        a = s[f]["boundary"]
        assert a["grid_cells"] > 1000 and a["curves"] >= 1
        assert a["contradicting_beyond_one_cell"] - a["contradicting_beyond_one_cell_off_branch"] == 0, (f, a)
        assert ("reason" in a) == (a["contradicting_beyond_one_cell"] > 0), (f, a)
        print(f"\n{name} {f}: speed {s['speed']:.4f}, contradicting {a['contradicting_cells']} of {a['grid_cells']} "
              f"({a['contradicting_off_branch']} off the followed branch), beyond one cell "
              f"{a['contradicting_beyond_one_cell']} ({a['contradicting_beyond_one_cell_off_branch']} off it); "
              f"specials {s[f]['special_counts']}, Hopf max |Re| {s[f]['hopf_max_abs_real_part']}; "
              f"timings {s['timings_s']}")


def test_off_branch_cells_are_those_past_a_rescued_or_unsolved_cell():
    """The map sweeps each speed down in g0; a cell solved from a contact-set start, or left unsolved, and
    every cell below it at that speed, are not continued from the followed branch."""
    g0s = np.linspace(0.0, 1e-3, 6)
    shape = (3, 6)
    n_contact = np.ones(shape)
    n_contact[1, 3] = -1  # unsolved at speed 1, the fourth clearance
    rescued = np.zeros(shape)
    rescued[2, 4] = 1.0  # from a contact-set start at speed 2, the fifth clearance
    z = np.zeros(shape)
    mp = StabilityMap("3D", np.arange(3.0), g0s, n_contact, z, z, z, np.ones(shape), rescued)
    off = off_branch(mp)
    assert not off[0].any()
    np.testing.assert_array_equal(off[1], g0s <= g0s[3])
    np.testing.assert_array_equal(off[2], g0s <= g0s[4])


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_orbits_are_drawn_on_their_static_branch(study, name):
    """(4) continuation.png plots one quantity for both, the fan-disk centre's distance from the axis:
    an orbit born at a Hopf point starts on its static branch (its largest and smallest distance over
    the period within 0.5 % of the static one at the Hopf point), an orbit from a transient encloses its
    static solution (smallest <= static <= largest), and no orbit is the static solution itself (what
    shooting from a transient that had not settled converged on, 1e-15 m peak-to-peak, before)."""
    _, r, _, _ = study(name)
    checked = 0
    for f, b in r.branches.items():
        for ob in r.orbits[f]:
            assert all(not o.trivial for o in ob.orbits), (f, ob.message)
            if not ob.orbits:
                continue
            if ob.notes["start"] == "hopf":
                h = next(x for x in b.of_kind("hopf") if x.point.g0 == ob.hopf_g0).point.disk_amplitude
                first = ob.orbits[0]
                assert abs(first.disk_max_radius - h) <= 5e-3 * h and abs(first.disk_min_radius - h) <= 5e-3 * h
            else:
                g = np.array([p.g0 for p in b.points])
                a = np.array([p.disk_amplitude for p in b.points])
                for o in ob.orbits:
                    static = float(np.interp(o.g0, g[::-1], a[::-1]))
                    assert o.disk_min_radius <= static <= o.disk_max_radius, (f, o.g0)
            checked += 1
    assert checked >= 1  # every configuration has a 3D Hopf point with its orbits


@pytest.mark.slow  # a 30-blade rotor's 2D quick map and boundary curves: about 20 s on 2 cores
def test_thirty_blades_2d_boundaries_meet_at_their_corners():
    """A second newcomer's 30 blades (3 polynomials reduced to 2 modes, 78 dofs). The 2D first-contact switch stops
    being a stability boundary where the contact solution turns stable, and the boundary goes on as a curve shorter
    than a seed-lattice cell; the curves also stopped short of the corner where they meet. One gap flooded the map:
    one region, 362 cells 'contradicting' (202 beyond one cell). Now: the free ends' local lattices seed the
    missing curve, ends within a cell of another curve meet it, and no followed-branch cell beyond one cell
    contradicts the curves (measured: 4 contradicting, all within one cell)."""
    m = build_model(reference_parameters().replace(blades={"count": 30, "n_ritz": 3, "n_modes": 2}))
    speeds, g0s = default_grid(m, quick=True)
    mp = run_stability_map(m, "2D", speeds, g0s, executor="serial", progress=False)
    curves, info = trace_boundaries(Equilibria(m, "2D"), speeds, g0s)
    a = agreement(curves, mp, tuple(info["cell"]))
    assert a["regions"] >= 2 and a["contradicting_cells"] < 20, a
    assert a["contradicting_beyond_one_cell"] - a["contradicting_beyond_one_cell_off_branch"] == 0, a


@pytest.mark.slow  # the imported fan blade (158 dofs): a 6 x 8 corner of its quick 3D map and its curves, twice:
# 22 s on two shared cores, up to 5 min when they are loaded (measured); the whole example's map and curves take 12 min
def test_boundaries_the_lattice_misses_are_seeded_from_the_maps_verdicts():
    """The imported fan blade (examples/fan_blade), 3D: by the left edge of the quick map, below g0 = 0.1 mm, two
    modes' Hopf curves (258 and 291 rad/s, Re within 0.05 /s of zero) bound a thin stable sliver; the quick grid's
    clearances are quadratic (7 um between its lowest rows) and the seed lattice's rows 0.5 mm apart, so no lattice
    edge crosses the sliver's lower boundary, the curve along its upper one stops at the corner, and the unstable
    cells connect round its end to the stable ones: one region, every unstable cell 'contradicting' (the whole map:
    342 of 1440, 201 beyond one cell). Reproduced on the map's corner (its first 6 speeds and 8 clearances) with a
    lattice whose second row lies above the sliver, as the default's does on the whole range: the map's own verdict
    changes that no curve passes seed the missing curves."""
    from pathlib import Path

    from rotorub_model.structure.params import load_parameters

    m = build_model(load_parameters(Path(__file__).parents[2] / "examples" / "fan_blade" / "example.toml"))
    speeds, g0s = default_grid(m, quick=True)
    speeds, g0s = speeds[:6], g0s[:8]
    mp = run_stability_map(m, "3D", speeds, g0s, executor="serial", progress=False)
    verdicts = np.where(mp.no_solution | off_branch(mp), -1, mp.unstable.astype(int))
    curves, info = trace_boundaries(Equilibria(m, "3D"), speeds, g0s, lattice=(6, 2))
    before = agreement(curves, mp, tuple(info["cell"]))
    assert before["regions"] == 1 and before["contradicting_beyond_one_cell"] > 0, before  # the lattice alone
    curves, info = trace_boundaries(Equilibria(m, "3D"), speeds, g0s, lattice=(6, 2), verdicts=verdicts)
    a = agreement(curves, mp, tuple(info["cell"]))
    assert info["curves_from_map_edges"] >= 1 and info["map_edges_other_solution"] == 0, info
    assert a["regions"] >= 3, a  # the sliver and the unstable cells either side are separated from the rest
    assert a["contradicting_cells"] == 0, a  # measured: 24 before (4 beyond one cell), 0 after
