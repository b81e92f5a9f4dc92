"""The FMU half of ``rotorub reproduce`` (fmu_src/reproduce.py) returns its own report section: the library's report
(rotorub_model/app/report.py) inserts it as it is and knows none of the FMU summary's keys (issue 24.3: a changed
harness summary broke the library's report)."""

from __future__ import annotations

import re
from pathlib import Path

from fmu_src.reproduce import report_section

ROOT = Path(__file__).resolve().parents[2]
FMU_KEYS = ("harnesses", "fmu_vs_library", "fmu_flavours", "coupled_run", "coupled_wear_run")


def _summary() -> dict:
    """A summary of the shape run_fmu_part returns (numbers made up: the renderer is under test, not the runs)."""
    tr = {"max_rel_diff_F_N_vs_library": 1e-13, "diverged": False, "penetration_limit_hit": False,
          "envelope_growing": False, "blades_in_contact_at_1s": 10}
    grows = {**tr, "diverged": True, "envelope_growing": True,
             "envelope_growth": {"factor": 8.6, "rate_per_s": 0.221, "window_s": [10.1, 19.9], "fit_r2": 0.99}}
    lib = {"cells": 320, "cells_same_blades_in_contact": 318, "cells_other_branch": 2, "cells_solved_by_one_only": 0,
           "same_stability_verdict_fraction": 1.0, "max_real_max_rel_diff": 1e-11}
    return {
        "harnesses": {"transient": {"2D": tr, "3D": grows},
                      "run_up": {"max_rel_diff_F_N_vs_library": 2e-13, "speed_of_peak_response": 3.5,
                                 "max_normal_force_N": 180.0},
                      "quasi_static": {"vs_library": {"2D": lib, "3D": lib}}},
        "fmu_vs_library_max_rel_diff": 1e-11, "fmu_vs_library_note": "under the same zero-order hold",
        "fmu_flavours": {"t_end_s": 3.0, "h_s": 1e-3, **{f: {"native_vs_pythonfmu": 0.0, "bit_identical": True,
                                                             "native_vs_library": 1e-13,
                                                             "seconds": {"native": 0.1, "pythonfmu": 0.4}}
                                                         for f in ("2D", "3D")}},
        "coupled_run": {"max_friction_torque_N_m": 1234.5, "ssp_valid": True, "figures": []},
    }


def test_the_section_says_what_the_fmu_half_found():
    md = report_section(_summary())
    assert md.startswith("\n## FMU against the library") and "**1.00e-11**" in md
    # the two meanings of "diverged" apart, with the growth rate (issue 25.1)
    assert ("| transient 3D (section 6), F_N | 1.00e-13 | diverged: yes (penetration limit hit: no, force envelope "
            "growing: yes (×8.6, +0.221 1/s))") in md
    assert "| 2D | 0.0e+00 | True |" in md and "| max friction torque [N·m] | 1234 |" in md
    assert "## Engine scenario with wear" not in md  # no wear run in this summary: no section about it


def test_the_librarys_report_knows_no_fmu_key():
    """report.py inserts the sections it is given; the FMU summary's keys are fmu_src's alone."""
    text = (ROOT / "rotorub_model" / "app" / "report.py").read_text()
    assert [k for k in FMU_KEYS if re.search(rf"['\"]{k}", text)] == []
    assert "sections" in text


def test_a_limit_cycle_through_the_fmu_reads_not_settled():
    """A run through the FMU whose envelope is flat but whose force still swings (a limit cycle: a user's 8-blade
    configuration swung a blade 90-181 N) says so in the report's table and in the harness's verdict, as the
    library's transient verdict does, instead of a bare 'diverged: no' that reads like a run at rest."""
    from fmu_src.masters.analyses import _verdict
    from fmu_src.reproduce import verdict_lines

    s = {**_summary(), "fmu": {"platforms": ["linux64"]}}
    s["harnesses"]["transient"]["2D"]["force_swing_last_s_N"] = [90.3, 181.0]
    md = report_section(s)
    assert "force envelope growing: no), not settled: F_N still swings 90.3-181 N, blades at 1 s: 10" in md
    line = next(x for x in verdict_lines(s) if "section 6 through the FMU" in x)
    assert "2D diverged: no (penetration limit no, envelope growing no), not settled: F_N still swings 90.3-181 N" \
        in line
    assert "not settled" not in line.split(";")[1]  # the 3D run has no swing
    flat = {"envelope_growing": False, "force_swing_last_s_N": [90.3, 181.0],
            "envelope_growth": {"factor": 1.02, "rate_per_s": 0.001, "window_s": [10.0, 20.0]}}
    assert _verdict(flat).endswith("not settled: F_N still swings 90.3-181 N over the last 2 s")
    assert "not settled" not in _verdict({**flat, "force_swing_last_s_N": None})
    # a diverged run swings too: the verdict says diverged and no more, as the library's
    s["harnesses"]["transient"]["3D"]["force_swing_last_s_N"] = [10.0, 500.0]
    assert "not settled" not in next(x for x in verdict_lines(s) if "section 6 through the FMU" in x).split(";")[1]
