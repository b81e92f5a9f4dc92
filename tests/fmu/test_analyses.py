"""The fmpy harnesses of issue 6 agree with the library analyses they redo through the FMU."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("fmpy", reason="the harnesses drive the FMU with fmpy (pip install -e '.[fmu]')")
pytest.importorskip("pythonfmu", reason="building the FMU needs pythonfmu (pip install -e '.[fmu]')")

from fmu_src.masters import analyses as harness  # noqa: E402


@pytest.fixture(scope="module")
def fmu(contact_fmu):
    return contact_fmu


def test_transient_pair_matches_library_and_saves_fig12(fmu, ref_model, tmp_path):
    s = harness.transient_pair(fmu, ref_model, 3.3, 0.2e-3, tmp_path, t_end=1.5)
    for f in ("2D", "3D"):
        assert s[f]["max_normal_force_N"] > 50.0  # it rubs
        assert s[f]["max_rel_diff_F_N_vs_library"] < 1e-9
        assert s[f]["penetration_limit_hit"] == s[f]["library_penetration_limit_hit"]
        # 1.5 s: no growth verdict, and the limit was not hit: no verdict at all (null), not a false "no"
        assert s[f]["envelope_growing"] is None and s[f]["diverged"] is None
    assert (tmp_path / "fmu_contact_forces.png").stat().st_size > 10_000
    assert json.loads((tmp_path / "summary.json").read_text())["speed"] == 3.3


def test_run_up_matches_library_and_peaks_past_the_critical(fmu, ref_model, tmp_path):
    s = harness.run_up(fmu, ref_model, tmp_path, speed_from=3.0, speed_to=4.0, duration=1.5, g0=1e-3)
    assert s["max_rel_diff_F_N_vs_library"] < 1e-9 and s["max_rel_diff_disk_vs_library"] < 1e-9
    assert s["max_normal_force_N"] > 0.0
    assert (tmp_path / "run_up.png").exists()


def test_quasi_static_maps_agree_with_library_maps(fmu, ref_model, tmp_path):
    speeds = np.linspace(3.2, 3.8, 5)
    g0s = np.array([0.0, 0.5e-3, 1.5e-3, 20e-3])
    m = harness.quasi_static_maps(fmu, ref_model, speeds, g0s, tmp_path)
    s = m.summary()
    assert s["max_blades_in_contact_2D"] >= 2
    assert np.all(m.n_contact["2D"][:, -1] == 0)  # 20 mm: no contact anywhere
    for f in ("2D", "3D"):
        c = s["vs_library"][f]
        assert c["cells_same_blades_in_contact"] >= c["cells"] - 2
        assert c["same_stability_verdict_fraction"] == 1.0
        assert c["max_real_max_rel_diff"] < 1e-9
    m.save(tmp_path)


def test_quasi_static_sweep_goes_on_past_a_diverged_point(fmu, ref_model, tmp_path):
    """With max_penetration = 0.3 mm the deepest balanced solutions at g0 = 0 (1.5 mm at 4.0 omega_ref, the
    contact-stiffened critical) are divergences (the FMU ends that run: fmi2Terminated); the sweep rolls back to
    the state before each such point and goes on, so the speeds past the peak, where the penetration is
    shallower again (0.27 mm at 4.75), are solved."""
    speeds = np.linspace(3.0, 5.5, 11)
    m = harness.quasi_static_maps(fmu, ref_model, speeds, np.array([0.0]), tmp_path, formulations=("2D",),
                                  compare=False, max_penetration=0.3e-3)
    n = m.n_contact["2D"][:, 0]
    assert (n < 0).any(), n  # some points diverged ...
    first_bad = int(np.argmax(n < 0))
    assert (n[first_bad:] >= 0).any(), n  # ... and the sweep solved points after them


def test_quasi_static_map_hatches_unstable_cells_cell_by_cell(monkeypatch, tmp_path):
    """Issue 18.7: the hatch marks exactly the unstable cells (a contour of the boolean spilled it half a cell
    into the neighbours, one stroke a cell apart), densely; cells without a balanced solution get their own
    legend entry, and the legend sits below the axes."""
    from matplotlib.patches import Rectangle

    from rotorub_model.plotting import pyplot

    speeds, g0s = np.linspace(3.0, 3.8, 5), np.array([0.0, 0.5e-3, 1e-3, 2e-3])
    n = np.array([[3, 2, 0, 0], [4, 3, 1, 0], [5, 3, 2, 0], [5, 4, -1, 0], [4, 2, 0, 0]])
    re = np.where(n > 0, -1.0, np.nan)
    re[1, 1] = re[2, 0] = re[3, 1] = 0.5
    m = harness.QuasiStaticMaps(speeds, g0s, {"2D": n}, {"2D": re})
    figs = []
    monkeypatch.setattr(harness, "save_figure", lambda fig, path, **kw: figs.append(fig) or path)
    m.save(tmp_path)
    fig = figs[0]
    ax = fig.axes[0]
    hatched = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_hatch()]
    assert len(hatched) == 3 and all(len(p.get_hatch()) >= 5 for p in hatched)
    centres = sorted((round(p.get_x() + p.get_width() / 2, 9), round(p.get_y() + p.get_height() / 2, 9))
                     for p in hatched)
    assert centres == sorted((round(speeds[i], 9), round(g0s[j] * 1e3, 9)) for i, j in ((1, 1), (2, 0), (3, 1)))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(lab.startswith("unstable") for lab in labels) and any("no balanced solution" in lab for lab in labels)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    assert not fig.legends[0].get_window_extent(r).overlaps(ax.get_window_extent(r))
    pyplot().close(fig)


def test_a_run_up_whose_step_plan_changes_matches_the_library(tmp_path):
    """Fourteen thicker blades: the stability limit at 1 ms falls from 2 to 3 substeps inside the run-up (between
    2.4 and 4.2 Omega_ref). The FMU re-plans its substeps per rad/s band and restarts at the same velocity; the
    library's hold mode follows the same plan (transient.held_substep), so the two run the same steps: before it
    did, the library kept the top speed's step and the two differed by 2.5e-3."""
    from fmu_src.models.contact.builder import build_native_fmu
    from rotorub_model.analyses.transient import held_substep
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import REFERENCE_FILE, load_parameters

    text = REFERENCE_FILE.read_text().replace("\ncount = 10 ", "\ncount = 14 ").replace(
        "\nthickness = 0.011 ", "\nthickness = 0.01265 ")
    (tmp_path / "b14.toml").write_text(text)
    model = build_model(load_parameters(tmp_path / "b14.toml"))
    assert model.params.blades.count == 14
    w_ref, c = model.params.normalisation.omega_ref, make_contact(model, "3D", g0=1e-3)
    plans = {round(1e-3 / held_substep(model, c, w_ref * s, 1e-3)) for s in (2.4, 4.2)}
    assert plans == {2, 3}  # the plan changes inside the run-up
    fmu = build_native_fmu(tmp_path / "fmu", params_file=tmp_path / "b14.toml", platforms=("linux64",))["fmu"]
    s = harness.run_up(fmu, model, tmp_path / "ru", speed_from=2.4, speed_to=4.2, duration=6.0, g0=1e-3)
    assert s["max_normal_force_N"] > 100.0  # it rubs through the critical
    assert s["max_rel_diff_F_N_vs_library"] < 1e-9 and s["max_rel_diff_disk_vs_library"] < 1e-9
