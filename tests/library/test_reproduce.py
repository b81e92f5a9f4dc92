"""The main job end to end (quick grids): summary, report and every figure it references."""

from __future__ import annotations

import json
import re

import pytest

from rotorub_model.app.reproduce import run_reproduce
from rotorub_model.structure.model import build_model


# the main job (quick) once for the file: its fixture takes about 55 s on 2 cores, each test then reads its output
@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    summary = run_reproduce(build_model(), out, quick=True)
    return out, summary


def test_summary_and_facts(run):
    out, summary = run
    on_disk = json.loads((out / "summary.json").read_text())
    assert on_disk["n_dofs"] == 38
    ids = [f["id"] for f in on_disk["paper_facts"]]
    assert ids == [1, 2, 3, 4, 5, "6a", "6b"]
    for f in on_disk["paper_facts"]:
        assert isinstance(f["holds"], bool)
        assert f["holds"] or f.get("why"), f"fact {f['id']} fails without saying why"
    # facts 1-5 are reproduced by the reference configuration
    failing = [f["id"] for f in on_disk["paper_facts"][:5] if not f["holds"]]
    assert not failing, failing


def test_report_references_existing_figures(run):
    out, summary = run
    text = (out / "report.md").read_text()
    figs = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    assert len(figs) >= 8
    for rel in figs:
        p = out / rel
        assert p.exists() and p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", rel
    for f in summary["paper_facts"]:
        if not f["holds"]:
            assert f"Fact {f['id']}" in text


def test_report_and_summary_record_their_inputs(run):
    """Issue 18.7: the parameter source and its hash, the grid and the package version, in both."""
    import hashlib

    import rotorub_model
    from rotorub_model.structure.params import REFERENCE_FILE

    out, _ = run
    inp = json.loads((out / "summary.json").read_text())["inputs"]
    ref_hash = hashlib.sha256(REFERENCE_FILE.read_bytes()).hexdigest()
    assert inp["parameters"]["source"] == "embedded reference" and inp["parameters"]["sha256"] == ref_hash
    assert inp["grid"]["mode"] == "quick"
    assert (inp["grid"]["stability_maps"]["n_speeds"], inp["grid"]["stability_maps"]["n_g0"]) == (40, 36)
    assert inp["package_version"] == rotorub_model.__version__
    text = (out / "report.md").read_text()
    assert ref_hash in text and "embedded reference" in text and inp["parameters"]["values_sha256"] in text
    assert "**quick**" in text and "40 speeds" in text and "36 clearances" in text
    assert f"rotorub_model {rotorub_model.__version__}" in text


def test_report_facts_are_prose_not_key_value_dumps(run):
    out, _ = run
    text = (out / "report.md").read_text()
    table = text.split("## The paper's facts")[1].split("\n## ")[0]
    rows = [ln for ln in table.splitlines() if re.match(r"\| (\d|6[ab]) \|", ln)]
    assert len(rows) == 7
    for row in rows:
        paper, ours = row.split(" | ")[2:4]
        for cell in (paper, ours):
            assert "{" not in cell and "[" not in cell and "True" not in cell and "False" not in cell, cell
            # a summary key ('closure_2d_max_mm: ...') is a dump; words and units are not
            assert not re.search(r"\b[a-z0-9]{2,}(_[a-z0-9]+)+\b", cell), cell
    assert "critical speeds at Ω = " in rows[0] and "blades in contact" in rows[4]


def test_parameter_source_of_a_file(write_params, ref_params):
    """A parameter file: its path, the sha256 of its bytes, and whether the model was built from it."""
    import hashlib

    from rotorub_model.app.reproduce import parameter_source
    from rotorub_model.structure.params import to_dict

    d = to_dict(ref_params)
    d["contact"]["k_r"] *= 10
    path = write_params(d, "stiff.toml")
    stiff = build_model(ref_params.replace(contact={"k_r": d["contact"]["k_r"]}))
    src = parameter_source(stiff, path)
    assert src["source"] == str(path) and src["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert src["file_matches_model"] is True
    assert parameter_source(build_model(), path)["file_matches_model"] is False
    mem = parameter_source(stiff)  # no file: only the values identify the configuration
    assert mem["absolute_path"] is None and mem["sha256"] == mem["values_sha256"] == src["values_sha256"]


def test_main_job_wears_the_liner_at_the_transient_point(run):
    """The section-6 rub against the parameter file's abradable liner: both formulations wear it, evenly (a
    synchronous whirl's 360-degree rub: no lobes), the clearance opens by the mean depth, and the report says so
    next to the wear figures."""
    out, summary = run
    w = summary["wear"]
    assert (w["speed"], w["g0_mm"]) == (summary["transient"]["speed"], summary["transient"]["g0_mm"])
    for f in ("2D", "3D"):
        s = w[f]
        assert s["depth_max_mm"] > 0.01 and s["removed_volume_mm3"] > 0 and s["plastic_work_J"] > 0
        assert s["clearance_effective_mm"] == pytest.approx(s["clearance_before_mm"] + s["depth_mean_mm"], rel=1e-9)
        assert s["lobes"] == 0
        assert (out / "wear" / f / "wear_profile.png").exists() and (out / "wear" / f / "wear_map.png").exists()
    text = (out / "report.md").read_text()
    assert "against an abradable liner" in text and "wear/3D/wear_map.png" in text


def test_main_job_reports_the_quick_forced_response_and_uncertainty(run):
    """Issue 25.3: the quick harmonic-balance and uncertainty sections are in the main job's report, their figures
    linked from the report's folder, and every stage's time is in the summary (what the main job is made of)."""
    out, summary = run
    text = (out / "report.md").read_text()
    assert "## Forced response of an oval casing (harmonic balance)" in text
    assert "## Will it rub? Uncertainty (quick)" in text
    assert "(forced_response/interaction_map.png)" in text
    assert (out / "forced_response" / "interaction_map.png").exists()
    t = summary["timings_s"]
    assert set(t) >= {"linear", "detection", "stability", "transient", "wear", "continuation", "forced_response",
                      "uncertainty"} and all(v > 0 for v in t.values())


def test_the_continuation_runs_at_the_section_6_point_and_says_so(run):
    """The branches explain the transients at the point the transient study picked: the same speed, its reason in
    the summary, the value in the report (a configuration whose point is not the paper's speed used to show the
    branches at 3.3 beside transients at another speed, with nothing to say why)."""
    out, summary = run
    c, t = summary["continuation"], summary["transient"]
    assert c["speed"] == t["speed"]
    assert c["speed_source"].startswith("the section-6 transients' speed")
    assert json.loads((out / "continuation" / "summary.json").read_text())["speed_source"] == c["speed_source"]
    assert f"at Ω = {t['speed']:.4g} Ω_ref (the section-6 transients' speed" in (out / "report.md").read_text()
