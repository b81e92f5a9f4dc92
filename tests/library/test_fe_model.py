"""A parameter file's [fe_blade] section at model level (rotorub_model/structure/model.py, build_model): the
superelement named relative to the file, and the bad inputs (issue 26.8), each one line naming the parameter or the
file and what is accepted, nothing written."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rotorub_model.errors import FEImportError, ParameterError, RotorubError
from rotorub_model.structure.model import build_model, save_model
from rotorub_model.structure.params import load_parameters, reference_parameters

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fan_blade"
BLADE = EXAMPLE / "coarse" / "blade.npz"


def _file(tmp_path: Path, superelement: str, name: str = "p.toml", **replace: str) -> Path:
    text = (EXAMPLE / "example.toml").read_text().replace('superelement = "coarse/blade.npz"',
                                                          f"superelement = {json.dumps(superelement)}")
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    f = tmp_path / name
    f.write_text(text)
    return f


def test_superelement_relative_to_the_parameter_file(tmp_path, monkeypatch):
    """A relative path is the parameter file's folder's, wherever the command runs."""
    d = tmp_path / "case"
    d.mkdir()
    (d / "blades").mkdir()
    (d / "blades" / "fan.npz").write_bytes(BLADE.read_bytes())
    f = _file(d, "blades/fan.npz")
    monkeypatch.chdir(tmp_path)
    p = load_parameters(f)
    assert Path(p.fe_blade.superelement) == (d / "blades" / "fan.npz").resolve()
    assert build_model(p).blade_dofs == 14


BAD = [
    # (what, superelement, replacements of the example's text, error class, the line's words)
    ("tip radius not [blades]'", str(BLADE), {"length = 0.6 ": "length = 0.8 "}, ParameterError,
     r"fe_blade.superelement \(blade.npz\): its tip lies at radius 1 m but \[blades\] puts the tips at hub_radius "
     r"\+ length = 1.2 m; accepted: within 1%"),
    ("blades overlapping", str(BLADE), {"count = 10 ": "count = 24 "}, ParameterError,
     r"blades.count: 24 blades of fe_blade.superelement \(blade.npz\) overlap \(each spans 18.1 deg .* the pitch is "
     r"15 deg\); accepted: at most 19"),
    ("missing file", "no_such_blade.npz", {}, ParameterError,
     r"fe_blade.superelement: .*no_such_blade.npz: no such file; accepted: the blade.npz rotorub import-blade wrote"),
    ("stations out of range", str(BLADE), {"stations = 12 ": "stations = 1 "}, ParameterError,
     r"fe_blade.stations: value 1 out of range; accepted range \[2, 64\]"),
    ("not a path", str(BLADE), {f"superelement = {json.dumps(str(BLADE))}": "superelement = 3"}, ParameterError,
     r"fe_blade.superelement: expected a file path"),
]


@pytest.mark.parametrize("what, se, replace, cls, line", BAD, ids=[b[0] for b in BAD])
def test_bad_input_is_one_line(tmp_path, what, se, replace, cls, line):
    f = _file(tmp_path, se, **replace)
    with pytest.raises(cls, match=line) as e:
        build_model(load_parameters(f))
    assert "\n" not in str(e.value)


def test_superelement_of_another_format(tmp_path):
    """A saved model (another npz of the project), a file that is no npz, an npz of another format's meta: each
    is named with what is accepted."""
    save_model(build_model(reference_parameters()), tmp_path / "model.npz")
    (tmp_path / "blade.mtx").write_text("%%MatrixMarket matrix coordinate real symmetric\n1 1 1\n1 1 2.0\n")
    with np.load(BLADE) as d:
        arrays = {k: d[k] for k in d.files}
    meta = json.loads(str(arrays["meta"]))
    meta["format"] = "someone-else-2"
    arrays["meta"] = json.dumps(meta)
    np.savez(tmp_path / "other.npz", **arrays)
    for name, words in (("model.npz", r"no 'meta' entry \(format rotorub-superelement-1\)"),
                        ("blade.mtx", "not an .npz file"),
                        ("other.npz", r"format 'someone-else-2' in 'SI'; accepted: 'rotorub-superelement-1'")):
        with pytest.raises(FEImportError, match=words):
            build_model(load_parameters(_file(tmp_path, str(tmp_path / name))))


@pytest.mark.parametrize("what, se, replace, cls, line", BAD[:3], ids=[b[0] for b in BAD[:3]])
def test_the_command_says_it_in_one_line_and_writes_nothing(tmp_path, what, se, replace, cls, line):
    f = _file(tmp_path, se, **replace)
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "rotorub_model.app.cli", "static", "--params", str(f), "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("rotorub static: error: ")
    assert not out.exists()


def test_every_error_is_a_rotorub_error():
    assert issubclass(FEImportError, RotorubError) and issubclass(ParameterError, RotorubError)
