"""analyses/transient.py: one meaning per word (issue 25.1). A run carries the penetration limit and the growing
envelope as two named fields, with the fitted growth rate; ``diverged`` is either, the same in the run's JSON and in
the transient study's summary."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.analyses.stability import stability_of
from rotorub_model.analyses.static import solve_static
from rotorub_model.analyses.transient import run_transient
from rotorub_model.app.studies import run_transient_study
from rotorub_model.contact import make_contact
from rotorub_model.writing import dumps

SECTION_6 = (3.3, 0.3347658066492161e-3)  # the reference's transient point (2D unstable, 3D stable)


def test_the_readme_snippet_says_its_run_diverges_with_its_rate(ref_model, tmp_path):
    """The README's library snippet (3D, g0 = 0.3 mm, 3.3 Omega_ref, 5 s) runs at an unstable static solution; its
    JSON said "diverged": false with no growth rate. Now the envelope is measured about that static solution and
    grows at a rate of the order of the leading eigenvalue."""
    m = ref_model
    c = make_contact(m, "3D", g0=0.3e-3)
    w = 3.3 * m.params.normalisation.omega_ref
    st = solve_static(m, c, w)
    lam = stability_of(m, c, w, st.q).max_real
    assert lam > 0.3  # the README's max Re lambda, +0.39 1/s
    tr = run_transient(m, c, w, t_end=5.0)
    s = tr.save(tmp_path)
    on_disk = json.loads((tmp_path / "transient_3D.json").read_text())
    assert on_disk == json.loads(dumps(s))
    assert on_disk["penetration_limit_hit"] is False
    assert on_disk["envelope_growing"] is True and on_disk["diverged"] is True
    g = on_disk["envelope_growth"]
    assert g["about"] == "the static solution" and g["window_s"][0] >= 2.0
    assert 0.3 * lam < g["rate_per_s"] < 2.0 * lam, (g["rate_per_s"], lam)
    assert "diverged" in tr.verdict() and f"{g['rate_per_s']:+.3g} 1/s" in tr.verdict()


def test_a_short_run_has_no_growth_verdict_and_says_so(ref_model):
    tr = run_transient(ref_model, make_contact(ref_model, "2D", g0=0.2e-3), 176.0, t_end=1.5)
    assert tr.penetration_limit_hit is False and tr.envelope_growing is None and tr.diverged is None
    assert tr.envelope_growth["rate_per_s"] is None and "no growth verdict" in tr.verdict()


def test_through_the_liner_is_the_penetration_limit(ref_model):
    """An interference deeper than max_penetration: the run stops; diverged, by the limit, with no growth fit."""
    tr = run_transient(ref_model, make_contact(ref_model, "2D", g0=-2.9e-3), 176.0, t_end=5.0,
                       max_penetration=0.5e-3)
    assert tr.penetration_limit_hit is True and tr.diverged is True and tr.envelope_growing is None
    s = tr.summary()
    assert s["penetration_limit_hit"] is True and s["diverged"] is True and "penetration" in s["message"]
    assert tr.verdict().startswith("diverged at t = ") and "diverged: diverged" not in tr.verdict()


def test_a_run_without_a_static_solution_is_measured_peak_to_peak(ref_model):
    """A spin-speed history has no one static solution: the envelope is the oscillation's peak-to-peak range,
    and the result says so."""
    w0 = 3.3 * ref_model.params.normalisation.omega_ref
    tr = run_transient(ref_model, make_contact(ref_model, "3D", g0=1e-3), lambda t: w0 * (1 + 0.01 * t), t_end=4.0)
    assert tr.envelope_growth["about"] == "the oscillation (peak to peak)"
    assert tr.envelope_growth["rate_per_s"] is not None


@pytest.fixture(scope="module")
def study(ref_model, tmp_path_factory):
    out = tmp_path_factory.mktemp("tr")
    return out, run_transient_study(ref_model, out, *SECTION_6, t_end=12.0, progress=False)


def test_diverged_means_one_thing_across_one_transients_files(study):
    """The issue's folder: transient_2D.json had "diverged": false where summary.json had "diverged_2d": true and
    "penetration_limit_hit": {"2D": false}. Every file now names both meanings and they agree."""
    out, s = study
    on_disk = json.loads((out / "summary.json").read_text())
    for f in ("2D", "3D"):
        run = json.loads((out / f"transient_{f}.json").read_text())
        assert run["diverged"] == on_disk[f"diverged_{f.lower()}"]
        assert run["penetration_limit_hit"] == on_disk["penetration_limit_hit"][f]
        assert run["envelope_growing"] == on_disk["envelope_growing"][f]
        assert run["envelope_growth"] == on_disk["envelope_growth"][f]
    assert on_disk["diverged_2d"] is True and on_disk["penetration_limit_hit"]["2D"] is False
    assert on_disk["envelope_growing"]["2D"] is True and on_disk["envelope_growth"]["2D"]["rate_per_s"] > 0.05
    assert on_disk["diverged_3d"] is False and on_disk["settled_3d"]


def test_the_study_figure_states_each_runs_verdict(study, ref_model):
    from rotorub_model.analyses.transient import run_transient as rt
    from rotorub_model.app.studies import TransientStudy

    out, s = study
    runs = {f: rt(ref_model, make_contact(ref_model, f, g0=SECTION_6[1]), SECTION_6[0] * 53.4, t_end=4.0)
            for f in ("2D", "3D")}
    fig = TransientStudy(SECTION_6[0], SECTION_6[1], runs, {}).figure()
    titles = [a.get_title() for a in fig.axes]
    assert any(t.startswith("2D: ") and ("diverged" in t or "not diverging" in t) for t in titles), titles
    assert np.all([("1/s" in t) for t in titles if t])


@pytest.mark.parametrize("n_rec", [0, 3, 2500, 100_000])
def test_record_arrays_are_zeros_the_kernel_can_write(n_rec):
    """The records' block (mapped with its pages present from POPULATE_FROM_BYTES on): zeros, C-contiguous and
    writable, the two arrays side by side without overlap."""
    import mmap

    from rotorub_model.analyses.transient import POPULATE_FROM_BYTES, POPULATE_UP_TO_BYTES, record_arrays

    q, out = record_arrays(n_rec, 38, 68)
    assert q.shape == (n_rec, 38) and out.shape == (n_rec, 68)
    for a in (q, out):
        assert a.flags.c_contiguous and a.flags.writeable and not a.any()
    q[...] = 1.0
    assert not out.any()
    assert q.base is not None and out.base is q.base  # one block
    populated = POPULATE_FROM_BYTES <= n_rec * 106 * 8 <= POPULATE_UP_TO_BYTES
    mapped = isinstance(q.base.base, memoryview) and isinstance(q.base.base.obj, mmap.mmap)
    assert mapped == (populated and hasattr(mmap, "MAP_POPULATE"))


def test_a_limit_cycle_is_not_called_settled(ref_model):
    """A user's 8-blade fan (casing suspension halved, k_r doubled, mu 0.05) at its picked section-6 point: the 2D
    static solution is unstable (+0.16 1/s) and the run saturates into a limit cycle, blade 5's force swinging about
    90-181 N for ever. Its envelope neither grows nor decays, and the verdict said only "not diverging", as for a
    run at rest. It must say the force still swings; the same point's 3D run, which settles, must not."""
    from rotorub_model.structure.model import build_model

    p = ref_model.params
    m = build_model(p.replace(blades={"count": 8}, contact={"k_r": 3.0e6, "mu": 0.05},
                              suspension={"k_translation": 2.5e7, "k_rotation": 1.0e7}))
    w = 4.108 * m.params.normalisation.omega_ref
    r2 = run_transient(m, make_contact(m, "2D", g0=0.2587e-3), w, t_end=20.0, progress=False)
    assert r2.diverged is False
    lo, hi = r2.force_swing()
    assert 60.0 < lo < 120.0 and 150.0 < hi < 220.0, (lo, hi)
    assert r2.verdict().startswith("not diverging: ") and "not settled: F_N still swings" in r2.verdict()
    assert r2.summary()["force_swing_last_s_N"] == [lo, hi]
    r3 = run_transient(m, make_contact(m, "3D", g0=0.2587e-3), w, t_end=20.0, progress=False)
    assert r3.diverged is False and r3.force_swing() is None and "not settled" not in r3.verdict()
    assert r3.summary()["force_swing_last_s_N"] is None
