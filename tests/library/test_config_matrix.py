"""Every analysis command on a user's configuration (issue 18): more blades, more Ritz functions, the disk
moved, more friction, a stiffer contact. Each runs end to end through the CLI on small grids; the transient
point comes from the configuration's own maps (or the command says that none qualifies); the continuation's
boundary agreement on these configurations is tests/library/test_continuation_configs.py's."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.app.cli import main
from rotorub_model.app.studies import point_status
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import load_parameters, reference_parameters, to_dict, to_toml


def _moved_disk():
    d = to_dict(reference_parameters())
    d["disks"][0]["z"] = 0.15
    return d


CONFIGS = {
    "18 blades": lambda: to_dict(reference_parameters().replace(blades={"count": 18})),
    "24 blades": lambda: to_dict(reference_parameters().replace(blades={"count": 24})),
    "disk moved": _moved_disk,
    "n_ritz 5": lambda: to_dict(reference_parameters().replace(blades={"n_ritz": 5})),
    "mu 0.3": lambda: to_dict(reference_parameters().replace(contact={"mu": 0.3})),
    "k_r x 10": lambda: to_dict(reference_parameters().replace(contact={"k_r": 1.5e7})),  # the reference's 1.5e6
}


@pytest.mark.parametrize("name", list(CONFIGS))
def test_every_command_runs_on_the_configuration(name, tmp_path, capsys):
    from rotorub_model.structure.params import from_dict

    params = tmp_path / "config.toml"
    params.write_text(to_toml(from_dict(CONFIGS[name]())))
    p = load_parameters(params)
    base = ["--params", str(params)]

    def run(*args: str) -> int:
        code = main([*args, *base])
        capsys.readouterr()
        return code

    out = tmp_path / "out"
    assert run("response", "--n-speeds", "100", "--out", str(out / "response")) == 0
    assert run("modes", "--speed", "2", "--out", str(out / "modes")) == 0
    assert run("campbell", "--n-speeds", "20", "--out", str(out / "campbell")) == 0
    assert run("detect", "--n-speeds", "60", "--n-g0", "40", "--out", str(out / "detect")) == 0
    assert run("static", "--speed", "3.3", "--g0", "0.5e-3", "--out", str(out / "static")) == 0
    assert run("stability", "--quick", "--out", str(out / "stab")) == 0
    for f in ("response/response.png", "modes/modes.png", "campbell/campbell.png", "detect/detection_2d_3d.png",
              "stab/stability_maps.png"):
        assert (out / f).stat().st_size > 10_000, f
    code = main(["transient", "--t-end", "4", "--maps", str(out / "stab"), "--out", str(out / "tr"), *base])
    err = capsys.readouterr().err
    if name == "mu 0.3":  # measured: no cell of its maps has an unstable 2D and a stable 3D solution
        assert code == 2 and "no cell of this configuration's stability maps" in err
        return
    assert code == 0, err
    s = json.loads((out / "tr" / "summary.json").read_text())
    with np.load(out / "stab" / "stability_2D.npz") as z:
        speeds, g0s = z["speeds"], z["g0s"]
    assert speeds[0] <= s["speed"] <= speeds[-1] and 0 < s["g0_mm"] * 1e-3 <= g0s[-1]
    st = point_status(build_model(p), s["speed"], s["g0_mm"] * 1e-3)
    assert not st["2D"]["stability"].stable and st["3D"]["stability"].stable
    assert run("wear", "--t-end", "3", "--speed", repr(s["speed"]), "--g0", repr(s["g0_mm"] * 1e-3),
               "--out", str(out / "wear")) == 0
    assert (out / "wear" / "3D" / "wear_profile.png").exists()


# ------------------------------------------- defaults and limits from the configuration (issue 18, a newcomer's run)
def _write(tmp_path, **changes) -> list[str]:
    from rotorub_model.structure.params import from_dict

    d = to_dict(reference_parameters().replace(**changes))
    f = tmp_path / "my.toml"
    f.write_text(to_toml(from_dict(d)))
    return ["--params", str(f)]


def _one_line(capsys, code: int, *needles: str) -> None:
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "Traceback" not in err, err
    for n in needles:
        assert n in err, err


def test_the_speed_range_defaults_to_the_models_validity(tmp_path, capsys):
    """speed_max = 6: response, Campbell and detection ran to a hard-coded 10 and refused their own default."""
    base = _write(tmp_path, normalisation={"speed_max": 6.0})
    assert main(["response", "--n-speeds", "200", "--out", str(tmp_path / "r"), *base]) == 0
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["speed_range"][1] == 6.0 and s["critical_speeds"][0] == pytest.approx(3.49, abs=0.01)
    assert main(["campbell", "--n-speeds", "20", "--out", str(tmp_path / "c"), *base]) == 0
    capsys.readouterr()


def test_speeds_the_tool_chooses_stay_within_the_models_validity(tmp_path, capsys):
    """speed_max = 2, below the first critical (3.49): the studies centred on it ran at 2.7-4.3 and 3.3 with exit
    0; now they say there is no critical speed in the model's range."""
    base = _write(tmp_path, normalisation={"speed_max": 2.0})
    _one_line(capsys, main(["transient", "--out", str(tmp_path / "t"), *base]), "speed_max", "no critical speed")
    _one_line(capsys, main(["stability", "--quick", "--out", str(tmp_path / "s"), *base]), "speed_max")
    p = load_parameters(base[1])
    speeds, _ = __import__("rotorub_model.app.studies", fromlist=["default_grid"]).default_grid(
        build_model(p.replace(normalisation={"speed_max": 3.8})), quick=True)
    assert speeds[-1] == 3.8  # clipped to the validity, not c1 + 0.8 = 4.29


def test_no_imbalance_is_a_clear_error_where_a_study_needs_one(tmp_path, capsys):
    """imbalance.me = 0: the studies crashed (IndexError: no critical speed among the response's peaks). The
    response still finds the critical speeds (linear in me), with zero amplitudes; the studies say why not."""
    base = _write(tmp_path, imbalance={"me": 0.0})
    assert main(["response", "--n-speeds", "400", "--out", str(tmp_path / "r"), *base]) == 0
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["critical_speeds"][0] == pytest.approx(3.49, abs=0.01) and max(s["peak_amplitudes_m"]) == 0.0
    capsys.readouterr()
    for cmd in ("stability", "transient", "continuation"):
        _one_line(capsys, main([cmd, "--out", str(tmp_path / cmd), *base]), "imbalance.me")


def test_modes_and_static_default_to_the_configuration(tmp_path, capsys):
    """modes at this configuration's first critical (not 3.5), static at it and at its contact.g0 (not 3.3 and
    0.8 mm): a softer front bearing moves the critical down (3.45 from 3.49)."""
    d = to_dict(reference_parameters())
    d["bearings"][0]["k"] *= 0.5
    d["contact"]["g0"] = 0.6e-3
    from rotorub_model.structure.params import from_dict

    f = tmp_path / "soft.toml"
    f.write_text(to_toml(from_dict(d)))
    assert main(["static", "--params", str(f), "--out", str(tmp_path / "st")]) == 0
    s = json.loads((tmp_path / "st" / "summary.json").read_text())
    from rotorub_model.app.studies import first_critical

    c1 = first_critical(build_model(load_parameters(f)))[0]
    assert s["g0_m"] == 0.6e-3 and s["speed"] == c1 and c1 < first_critical(build_model())[0] - 0.03
    assert main(["modes", "--params", str(f), "--out", str(tmp_path / "m")]) == 0
    assert json.loads((tmp_path / "m" / "modes.json").read_text())["speed"] == s["speed"]
    capsys.readouterr()


def test_a_missing_maps_folder_an_unwritable_out_and_coincident_bearings_are_refused(tmp_path, capsys):
    _one_line(capsys, main(["transient", "--maps", str(tmp_path / "nowhere"), "--out", str(tmp_path / "t")]),
              "--maps", "stability_2D.npz")
    (tmp_path / "file").write_text("")
    _one_line(capsys, main(["modes", "--speed", "3", "--out", str(tmp_path / "file" / "out")]), "file")
    d = to_dict(reference_parameters())
    d["bearings"][1]["z"] = d["bearings"][0]["z"]
    from rotorub_model.structure.params import from_dict

    with pytest.raises(Exception, match="bearings.*position of its own"):
        from_dict(d)


# ------------------------------------------------------------------- a second newcomer's configurations
def test_two_blades_are_refused_with_the_reason(tmp_path, capsys):
    """Two blades make the bladed disk anisotropic: between its split critical speeds the rotating frame's static
    response is unbounded (a newcomer's run: 'peaks' of 2 and 10 km, a map axis of 1.2e7 mm, an empty figure)."""
    from rotorub_model.errors import ParameterError

    with pytest.raises(ParameterError, match="blades.count.*accepted range \\[3"):
        reference_parameters().replace(blades={"count": 2})
    d = to_dict(reference_parameters())
    d["blades"]["count"] = 3  # three hold the rotor isotropic: runs
    from rotorub_model.structure.params import from_dict

    assert build_model(from_dict(d)).n_dofs == 18 + 3 * 2


def test_a_first_critical_beyond_the_validity_says_what_to_do(tmp_path, capsys):
    """A shaft so stiff that its first critical lies beyond the model's validity: the response says there is none
    in its range, the studies refuse in one line that names the way out, detection too without imbalance."""
    d = to_dict(reference_parameters())
    d["shaft"]["outer_diameter"], d["shaft"]["inner_diameter"] = 0.30, 0.26
    d["normalisation"]["speed_max"] = 6.0
    from rotorub_model.structure.params import from_dict

    f = tmp_path / "stiff.toml"
    f.write_text(to_toml(from_dict(d)))
    assert main(["response", "--n-speeds", "200", "--params", str(f), "--out", str(tmp_path / "r")]) == 0
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["critical_speeds"] == [] and "no critical speed in" in s["note"]
    capsys.readouterr()
    _one_line(capsys, main(["stability", "--quick", "--params", str(f), "--out", str(tmp_path / "s")]),
              "no critical speed", "--speed and --g0")
    base = _write(tmp_path, imbalance={"me": 0.0})
    _one_line(capsys, main(["detect", "--n-speeds", "40", "--n-g0", "20", "--out", str(tmp_path / "d"), *base]),
              "imbalance.me")


def test_a_response_beyond_small_displacements_is_flagged():
    """Bearings ten times stiffer lock the dampers (they act only where the bearings move): the fan's linear peak is
    485 mm, half the tip radius, and nothing said so. The summary warns beyond 5 % of the tip radius; the
    reference (5.2 mm) does not."""
    from rotorub_model.analyses.linear import run_response
    from rotorub_model.structure.params import from_dict

    d = to_dict(reference_parameters())
    for b in d["bearings"]:
        b["k"] *= 10
    s = run_response(build_model(from_dict(d)), n_speeds=800).summary()
    assert "beyond the small displacements" in s["warning"] and max(s["peak_amplitudes_m"]) > 0.4
    assert run_response(build_model(), n_speeds=800).summary()["warning"] == ""
