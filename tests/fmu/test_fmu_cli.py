"""fmu_src/cli.py: `rotorub build-fmu` says which configuration it built in."""

from __future__ import annotations

import pytest

from rotorub_model.app.cli import main
from rotorub_model.structure.params import reference_parameters, to_toml


def test_build_fmu_verdict_names_the_model_built_in(tmp_path, capsys):
    """The same file name (RotorCasingContact.fmu) holds the reference or a user's fan; the verdict said neither,
    so a build from --params into fmus/native/ replaced the reference's FMU without a word."""
    pytest.importorskip("fmpy", reason="the native build takes the FMI headers from fmpy (pip install -e '.[fmu]')")
    params = tmp_path / "eight.toml"
    params.write_text(to_toml(reference_parameters().replace(blades={"count": 8})))
    rc = main(["build-fmu", "--native", "--platforms", "linux64", "--params", str(params), "--out",
               str(tmp_path / "fmu")])
    out = capsys.readouterr().out
    assert rc == 0 and f"with the model of {params} built in (8 blades)." in out.splitlines()[0], out
