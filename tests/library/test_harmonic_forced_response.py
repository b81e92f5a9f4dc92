"""The forced-response command and its library function (rotorub_model/app/forced_response.py): the files it writes,
the verdict, the HB-transient agreement with its reasons, and one-line errors on bad input."""

from __future__ import annotations

import json

from rotorub_model.app.cli import main

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_forced_response_writes_the_map_and_says_where_hb_and_transients_disagree(tmp_path, capsys):
    """2D, the default oval casing (2 lobes of 0.3 g0), 3.0-3.5 Omega_ref, two 60 s transients (serial): the map, its
    harmonic content and the JSON are written; every transient speed carries a verdict; at 3.25 the HB orbit is
    stable but its multiplier 0.995 leaves a 60 s transient settling, which the verdict names."""
    out = tmp_path / "fr"
    rc = main(["forced-response", "--out", str(out), "--speeds", "3.0", "3.25", "--g0", "0.5e-3", "--transients",
               "2", "--executor", "serial"])
    assert rc == 0
    for name in ("interaction_map.png", "interaction_map_harmonics.png"):
        assert (out / name).read_bytes()[:8] == PNG_MAGIC
    s = json.loads((out / "interaction_map.json").read_text())
    assert s["forcing"]["lobes"]["2"]["amplitude_m"] == 0.15e-3
    assert s["branch_message"].endswith("reached omega = 173.55 rad/s")
    assert s["branch_message"].startswith("from omega = 160.2 rad/s: ")  # 3.0 Omega_ref, with its unit
    ag = {round(a["speed"], 3): a for a in s["agreement"]}
    assert ag[3.0]["verdict"] == "agree" and ag[3.0]["transient"] == "periodic"
    assert ag[3.25]["verdict"] == "disagree" and "not settled" in ag[3.25]["why"]
    assert "DISAGREE at 1 speed" in s["verdict"]
    out = capsys.readouterr().out
    assert out.startswith("Forced rub response over") and "DISAGREE at 1 speed" in out  # the verdict a person reads


def test_forced_response_bad_input(tmp_path, capsys):
    for args, needle in ((["--lobe", "1", "--amplitude", "1e-4"], "lobes: 1 is the casing's rigid offset"),
                         (["--lobe", "2"], "--amplitude"),
                         (["--amplitude", "0.1mm"], "--lobe: needed with --amplitude 0.0001"),
                         (["--lobe", "2", "--amplitude", "0.02"], "clearances"),
                         (["--harmonics", "1", "--lobe", "2", "--amplitude", "1e-4"], "fewer than the casing's lobe")):
        rc = main(["forced-response", "--out", str(tmp_path / "x"), "--speeds", "3.0", "3.1", *args])
        err = capsys.readouterr().err.strip().splitlines()
        assert rc == 2 and len(err) == 1 and needle in err[0], (args, err)
    assert not (tmp_path / "x").exists() or not any((tmp_path / "x").iterdir())


def test_forced_response_figure_names_the_special_points():
    """The legend names each kind of special point once, in words ("HB change of stability", not "HB stability",
    which read as a state): 2D, g0 0.5 mm, the oval of the main job from 3 to 4.5 Omega_ref (two stability changes and
    six folds on the reference), without transients (4 s)."""
    from rotorub_model.analyses.harmonic.interaction import run_interaction_map
    from rotorub_model.structure.model import build_model

    r = run_interaction_map(build_model(), "2D", (3.0, 4.5), g0=0.5e-3, n_transients=0, wear=False, progress=False)
    kinds = {s.kind for s in r.branch.specials}
    assert kinds == {"stability", "fold"}
    labels = r.figure().axes[0].get_legend_handles_labels()[1]
    assert labels.count("HB change of stability") == 1 and labels.count("HB fold") == 1, labels
    assert "HB stability" not in labels
    verdict = r.summary()["verdict"]
    assert "no transients beside it" in verdict and "no disagreement" not in verdict and "at 0 speeds" not in verdict
    assert "8 special points;" in verdict
