"""facts.py and the main job's facts (issue 25.6): a failed fact names its failed condition, with our value, and
says when the condition is a number of the paper's rotor rather than a defect of the configuration."""

from __future__ import annotations

from rotorub_model.app.report import write_report
from rotorub_model.app.reproduce import fact1, fact6, main_job_verdict
from rotorub_model.facts import FINDING, ROTOR


def _section6(**over) -> dict:
    """A transient study's summary of the issue's 14-blade configuration: everything as the paper says, but four
    blades touch at 1 s where the paper's rotor has three."""
    tr = {"speed": 3.3, "g0_mm": 0.42, "diverged_2d": True, "settled_3d": True, "blades_in_contact_2d_at_1s": 4,
          "blades_in_contact_3d_at_1s": 4, "partial_chord_fraction_3d": 0.31, "max_force_at_1s_N": {"2D": 150.0,
                                                                                                     "3D": 170.0},
          "verdicts": {"2D": "diverged: envelope about the static solution ×3.1 over 10-20 s (+0.11 1/s)"}}
    return {**tr, **over}


def test_the_fourteen_blade_fact_6a_names_the_blade_count_as_the_papers_rotors():
    a, b = fact6(_section6())
    assert not a["holds"] and b["holds"]
    failed = [c for c in a["conditions"] if not c["holds"]]
    assert [c["condition"] for c in failed] == ["three blades touch at 1 s in 2D", "three blades touch at 1 s in 3D"]
    assert all(c["kind"] == ROTOR and c["ours"] == "4" for c in failed)
    assert "three blades touch at 1 s in 2D: ours 4" in a["why"] and "not a defect of this one" in a["why"]
    # the conditions that hold are not in the reason (the issue: its reason listed conditions that all read as met)
    assert "diverges" not in a["why"] and "settles" not in a["why"]


def test_a_finding_that_fails_is_not_called_the_rotors():
    a, _ = fact6(_section6(blades_in_contact_2d_at_1s=3, blades_in_contact_3d_at_1s=3, diverged_2d=False,
                           verdicts={"2D": "not diverging: envelope ×0.9"}))
    failed = [c for c in a["conditions"] if not c["holds"]]
    assert [c["kind"] for c in failed] == [FINDING] and "not diverging" in a["why"]
    assert "not a defect" not in a["why"]


def test_fact_1_on_another_rotor(tmp_path):
    f = fact1({"critical_speeds": [4.9, 9.1], "peak_amplitudes_m": [3e-3, 2e-4]})
    failed = [c["condition"] for c in f["conditions"] if not c["holds"]]
    assert failed == ["the first within 0.2 of 3.5", "the second within 0.5 of 8"]
    assert "ours 4.9" in f["why"] and "ours 9.1" in f["why"]


def test_the_report_and_the_verdict_list_the_failed_conditions(tmp_path):
    facts = [fact1({"critical_speeds": [3.49, 8.36], "peak_amplitudes_m": [5e-3, 2e-4]}), *fact6(_section6())]
    s = {"n_dofs": 46, "omega_ref_rad_s": 53.4, "paper_facts": facts}
    text = write_report(tmp_path, s).read_text()
    s["inputs"] = {"parameters": {"source": "fourteen.toml"}, "grid": {"mode": "quick"}}
    part = text.split("## What does not hold, and why")[1]
    assert "* Fact 6a: 2 of its 5 conditions fail:" in part
    assert "  * three blades touch at 1 s in 2D: ours 4 — a number of the paper's rotor" in part
    lines = main_job_verdict(s, tmp_path, ["FMU checks: ..."])
    assert lines[0] == "Main job on fourteen.toml (quick grids): 2 of 3 paper facts hold (1, 6b)."
    assert lines[1].startswith("  fact 6a does not hold: expected three blades touch at 1 s in 2D, ours 4")
    assert lines[1].endswith("numbers of the paper's rotor, not a defect of this configuration")
    assert lines[-1] == f"report: {tmp_path / 'report.md'}; summary: {tmp_path / 'summary.json'}; figures in " \
                        f"{tmp_path}/*/"


def test_the_verdict_carries_the_section_6_notes(tmp_path):
    """A bilinear law's knee that the 2D run never reached, and a picked point whose instability the run may not
    show, were in transient/summary.json and on stderr only: the main job's verdict now says them."""
    facts = [fact1({"critical_speeds": [3.49, 8.36], "peak_amplitudes_m": [5e-3, 2e-4]})]
    s = {"paper_facts": facts, "inputs": {"parameters": {"source": "a.toml"}, "grid": {"mode": "quick"}},
         "transient": {"verdict_note": "2D: the bilinear law's knee (0.2 mm) was never reached",
                       "point": {"note": "no qualifying point of this configuration has a 2D instability fast enough"}}}
    lines = main_job_verdict(s, tmp_path, [])
    assert "  section-6 transients: 2D: the bilinear law's knee (0.2 mm) was never reached" in lines
    assert any(ln.startswith("  section-6 transients: no qualifying point") for ln in lines)
    s["transient"] = {"verdict_note": "", "point": {"source": "given"}}
    assert not any("section-6" in ln for ln in main_job_verdict(s, tmp_path, []))
