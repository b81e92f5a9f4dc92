"""Every analysis command on a user's configuration (issue 18): more blades, more Ritz functions, the disk
moved, more friction, a stiffer contact. Each runs end to end through the CLI on small grids; the transient
point comes from the configuration's own maps (or the command says that none qualifies); the continuation's
boundary agreement on these configurations is tests/test_continuation_configs.py's."""

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
