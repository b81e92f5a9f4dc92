"""The engine scenario with a manoeuvre (fmu_src/systems/manoeuvre_scenario.py): the four-component SSP package and its
level-flight reference, the rub the ovalized casing makes and the two lobes it wears, the three masters."""

from __future__ import annotations

import json
import zipfile

import pytest

fmpy = pytest.importorskip("fmpy", reason="the engine tests drive the FMUs with fmpy (pip install -e '.[fmu]')")

from fmu_src.systems.manoeuvre_scenario import (  # noqa: E402
    build_manoeuvre_fmus,
    run_manoeuvre_scenario,
    scenario_settings,
    tight_points,
    write_manoeuvre_ssp,
)
from fmu_src.systems.ssp import run_ssp_fmpy, ssp_contents, validate_ssp, write_ssp  # noqa: E402
from fmu_src.systems.system import EngineError  # noqa: E402

CASING = ("casing_lobe2.amplitude", "casing_lobe2.phase", "casing_offset.x", "casing_offset.y")


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    return build_manoeuvre_fmus(tmp_path_factory.mktemp("manoeuvre_fmus"), platforms=("linux64",))


@pytest.fixture(scope="module")
def scenario(fmus, tmp_path_factory):
    out = tmp_path_factory.mktemp("manoeuvre_scenario")
    r = run_manoeuvre_scenario(out, quick=True, fmus=fmus)
    r["out"] = out
    return r


def test_the_four_component_packages_validate(scenario):
    """Both packages against the SSP 1.0 schemas and their FMUs; four components, the casing load wired to the
    contact's four casing inputs; the reference differs from the manoeuvre in casing_load.ssv alone."""
    s = scenario["summary"]
    ssp, level = s["ssp"], s["ssp_level_flight"]
    for p in (ssp, level):
        assert validate_ssp(p) == []
        c = ssp_contents(p)
        assert set(c["components"]) == {"contact", "spool", "clearance", "casing_load"}
        assert c["components"]["casing_load"] == "resources/CasingLoad.fmu"
        for v in CASING:
            assert ("casing_load", v, "contact", v) in c["connections"]
        assert ("clearance", "closure", "contact", "clearance_closure") in c["connections"]
        assert len(c["connections"]) == 8
    with zipfile.ZipFile(ssp) as a, zipfile.ZipFile(level) as b:
        assert set(a.namelist()) == set(b.namelist())
        differ = [n for n in a.namelist() if n != "SystemStructure.ssd" and a.read(n) != b.read(n)]
        assert differ == ["resources/casing_load.ssv"]
        assert b'name="load_factor_peak"' in b.read("resources/casing_load.ssv")


def test_parts_are_named_and_given_once(fmus, tmp_path):
    with pytest.raises(EngineError, match="no part named 'gearbox'; known: clearance, casing_load"):
        write_ssp(tmp_path / "x.ssp", fmus["contact"], fmus["spool"], parts={"gearbox": (fmus["clearance"], None)})
    with pytest.raises(EngineError, match="the clearance part given twice"):
        write_ssp(tmp_path / "x.ssp", fmus["contact"], fmus["spool"], clearance_fmu=fmus["clearance"],
                  parts={"clearance": (fmus["clearance"], None)})
    with pytest.raises(EngineError, match="casing_load parameter 'g_peak' unknown"):
        write_ssp(tmp_path / "x.ssp", fmus["contact"], fmus["spool"],
                  parts={"casing_load": (fmus["casing_load"], {"g_peak": 2.0})})
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_the_manoeuvre_makes_the_rub_and_wears_two_lobes(scenario):
    """Level flight: the blades keep a quarter of a millimetre and never touch. The pull-up's oval closes the two
    sides 90 degrees from its widest (vertical) axis past the liner's elastic limit: the blades rub there, during
    the rise, and cut two lobes (the kernel's rule: harmonic 2 at least twice every harmonic not its multiple)."""
    s = scenario["summary"]
    assert s["level_flight_contact_time_s"] == 0.0 and s["level_flight_wear_depth_max_mm"] == 0.0
    assert s["level_flight_wear_lobes"] == 0 and s["gap_min_level_flight_before_manoeuvre_mm"] > 0.2
    assert s["casing_load_vs_closed_form_max_rel_diff"] <= 1e-15
    # the oval's tight sides: 90 degrees off its widest axis (the offset, along that axis, moves them 2.4 deg down)
    angles = sorted(p["angle_deg"] for p in s["tight_points_at_peak"])
    assert len(angles) == 2 and abs(angles[0] - 180.0) < 5.0 and abs(angles[1] - 360.0) < 5.0
    reach = s["g0_mm"] - s["closure_mm"] - s["gap_min_level_flight_before_manoeuvre_mm"]  # the blades' excursion
    assert all(p["gap_to_centred_rotor_mm"] < reach - s["liner_elastic_limit_mm"]
               for p in s["tight_points_at_peak"])  # deep enough to cut
    t0, t1 = s["manoeuvre_s"]
    p = scenario_settings(True)["casing_params"]
    assert t0 < s["t_first_contact_s"] < t0 + 0.5 + 0.05  # during the rise (0.5 s)
    assert s["wear_depth_max_mm"] > 0.02 and s["wear_volume_mm3"] > 0.0
    assert s["wear_lobes"] == 2
    h = s["wear_harmonics_mm"]
    assert all(h[1] >= 2.0 * h[k] for k in (0, 2, 4, 6))
    assert s["max_contact_force_N"] == pytest.approx(s["liner_yield_force_N"], rel=0.05)  # the liner yields
    assert s["spool_speed_dip_rad_s"] > 0.0 and p["t_start"] == t0


def test_an_offset_across_the_oval_wears_one_side(scenario):
    """The same pull-up with the casing centre moved horizontally (across the oval, as a gyroscopic yaw would) closes
    one tight side by a2 + e and opens the other to a2 - e: the blades cut one side only, deeper, and the wear has
    one lobe (harmonic 1 the largest). Would fail if the offset's direction or the lobe rule were wrong."""
    s = scenario["summary"]
    assert s["offset_across_oval_wear_lobes"] == 1
    h = s["offset_across_oval_wear_harmonics_mm"]
    assert h[0] == max(h) and s["offset_across_oval_wear_depth_max_mm"] > 1.5 * s["wear_depth_max_mm"]


def test_how_long_the_peak_is_held_changes_no_wear(scenario, fmus, tmp_path):
    """The liner's law is rate-independent: once the tight sides are cut, the blades pass at the yield force. A
    pull-up held 0.5 s instead of 2 s wears the same depth (to 1e-6: the rise and the peak are the same)."""
    s = scenario["summary"]
    cfg = scenario_settings(True)
    cfg["t_end"] = 4.0
    ssp = write_manoeuvre_ssp(tmp_path / "short.ssp", fmus, cfg, {"t_hold": 0.5})
    run = run_ssp_fmpy(ssp, cfg["t_end"], cfg["h"], (("contact", "wear.depth_max"), ("contact", "wear.lobes")))
    assert run["contact.wear.depth_max"][-1] * 1e3 == pytest.approx(s["wear_depth_max_mm"], rel=1e-6)
    assert run["contact.wear.lobes"][-1] == 2


def test_the_packages_run_the_same_in_every_master(scenario):
    """fmpy (the reference master), the C master with no Python (bit for bit) and libcosim (its own engine). In
    level flight libcosim agrees to 1e-12; in the manoeuvre its time points (integer nanoseconds) move the casing
    load by an ulp (1e-15), which the impacts of the rub carry to a few 1e-10 of the blade forces."""
    s = scenario["summary"]
    for key in ("masters", "masters_level_flight"):
        nat = s[key]["native_host"]
        if nat["largest"] is None:
            pytest.skip(nat["note"])
        assert nat["largest"] == 0.0, nat
    lc = s["masters"]["libcosim"]
    if lc["largest"] is None:
        pytest.skip(lc["note"])
    assert s["masters_level_flight"]["libcosim"]["largest"] < 1e-11
    assert max(v for k, v in lc["max_rel_diff"].items() if k.startswith("casing_load.")) < 1e-14
    assert lc["max_rel_diff"]["contact.wear.depth_max"] < 1e-9 and lc["largest"] < 2e-9, lc


def test_the_figure_summary_and_report_section(scenario):
    out = scenario["out"]
    assert (out / "manoeuvre_engine.png").stat().st_size > 50_000
    assert json.loads((out / "summary.json").read_text())["wear_lobes"] == 2
    md = scenario["markdown"]
    assert md.startswith("\n## Engine manoeuvre") and "**2 lobes**" in md and "C master (0.0e+00" in md
    assert scenario["figures"][0][1] == "manoeuvre_engine.png"


def test_tight_points_of_a_round_casing_offset_are_one():
    """The closed form the figure and the summary use: an oval alone has its two tight sides 90 degrees off its
    widest axis; an offset larger than four times the oval leaves one (the side it moves away from)."""
    two = tight_points(1e-3, 0.0, 2e-4, 0.0, 0.0, 0.0)
    assert sorted(round(a) for a, _ in two) == [90, 270] and all(g == pytest.approx(8e-4) for _, g in two)
    one = tight_points(1e-3, 0.0, 1e-5, 0.0, 1e-4, 0.0)
    assert len(one) == 1 and round(one[0][0]) == 180 and one[0][1] == pytest.approx(1e-3 - 1e-4 + 1e-5)
