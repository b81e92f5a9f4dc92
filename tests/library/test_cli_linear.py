"""Command-line interface of the linear analyses: outputs, and one-line errors on bad input."""

from __future__ import annotations

import json
import subprocess
import sys
import time

import numpy as np
import pytest

from rotorub_model.analyses.linear import run_response
from rotorub_model.app.cli import main
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters, to_dict

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
N_SPEEDS = "300"


def _png_ok(path) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC, f"{path} is not a PNG"
    assert len(data) > 2000, f"{path} is suspiciously small ({len(data)} bytes)"


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "rotorub_model.app.cli", *args], capture_output=True, text=True, timeout=120
    )


def _one_error_line(stderr: str, *needles: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, f"expected exactly one line on stderr, got {lines}"
    line = lines[0]
    assert line.startswith("rotorub"), line
    for needle in needles:
        assert needle in line, f"{needle!r} not in {line!r}"
    return line


def _check_response_summary(out, ref_model) -> dict:
    s = json.loads((out / "summary.json").read_text())
    for key in ("critical_speeds", "peak_amplitudes_m", "omega_ref_rad_s", "n_dofs"):
        assert key in s, f"summary.json lacks {key}"
    assert s["n_dofs"] == 38
    assert s["omega_ref_rad_s"] == reference_parameters().normalisation.omega_ref
    # the library on the same grid (independent call, not through the CLI)
    r = run_response(ref_model, 0.05, 10.0, int(N_SPEEDS))
    np.testing.assert_allclose(s["critical_speeds"], r.critical_speeds, rtol=1e-12)
    np.testing.assert_allclose(s["peak_amplitudes_m"], r.peak_amplitudes, rtol=1e-12)
    np.testing.assert_allclose(
        s["critical_speeds_rad_s"], np.array(s["critical_speeds"]) * s["omega_ref_rad_s"], rtol=1e-14
    )
    assert len(s["critical_speeds"]) == 2 and 0 < s["critical_speeds"][0] < s["critical_speeds"][1] <= 10
    _png_ok(out / "response.png")
    return s


def test_response_in_process(tmp_path, capsys, ref_model):
    out = tmp_path / "resp"
    assert main(["response", "--n-speeds", N_SPEEDS, "--json", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert captured.err == ""
    printed = json.loads(captured.out)
    s = _check_response_summary(out, ref_model)
    assert printed["critical_speeds"] == s["critical_speeds"]


def test_response_subprocess(tmp_path, ref_model):
    out = tmp_path / "resp"
    proc = _cli("response", "--n-speeds", N_SPEEDS, "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    _check_response_summary(out, ref_model)


def test_response_with_user_params_file(tmp_path, capsys, write_params):
    """--params is honoured: a 36-dof model gives what the library gives for it."""
    p = reference_parameters().replace(shaft={"n_ritz": 4})
    path = write_params(to_dict(p))
    out = tmp_path / "user"
    assert main(["response", "--params", str(path), "--n-speeds", N_SPEEDS, "--out", str(out)]) == 0
    capsys.readouterr()
    s = json.loads((out / "summary.json").read_text())
    assert s["n_dofs"] == 36
    r = run_response(build_model(p), 0.05, 10.0, int(N_SPEEDS))
    np.testing.assert_allclose(s["critical_speeds"], r.critical_speeds, rtol=1e-12)


def test_modes_writes_png_and_json(tmp_path, capsys):
    out = tmp_path / "modes"
    assert main(["modes", "--speed", "2.0", "--out", str(out)]) == 0
    capsys.readouterr()
    s = json.loads((out / "modes.json").read_text())
    assert s["speed"] == 2.0
    assert len(s["modes"]) >= 30
    keys = {"rotating_frame_hz", "fixed_frame_hz", "nodal_diameter_index", "damping_ratio", "real_part"}
    assert all(keys <= set(m) for m in s["modes"])
    _png_ok(out / "modes.png")


def test_campbell_writes_png_and_json(tmp_path, capsys):
    out = tmp_path / "campbell"
    assert main(["campbell", "--speed-max", "2", "--n-speeds", "5", "--out", str(out)]) == 0
    capsys.readouterr()
    s = json.loads((out / "campbell.json").read_text())
    np.testing.assert_allclose(s["speeds"], np.linspace(0, 2, 5))
    f = np.array(s["fixed_frame_hz"])
    assert f.shape[0] == 5 and f.shape[1] >= 30
    # at rest the rotating and fixed frames coincide
    np.testing.assert_allclose(f[0], np.abs(s["rotating_frame_hz"][0]), rtol=1e-12)
    _png_ok(out / "campbell.png")


# ---------------------------------------------------------------------------
# bad input: non-zero exit, exactly one line on stderr naming the problem
# ---------------------------------------------------------------------------


@pytest.fixture
def bad_params_file(write_params):
    data = to_dict(reference_parameters())
    data["shaft"]["E"] = -2.1e11
    return write_params(data, "bad.toml")


@pytest.mark.parametrize(
    "args, needles",
    [
        (["response", "--speed-min", "-1"], ["response", "--speed-min", "out of range", "[0, 12]"]),
        (["response", "--speed-min", "5", "--speed-max", "2"], ["--speed-min", "below --speed-max"]),
        (["response", "--speed-max", "nan"], ["--speed-max", "out of range"]),
        (["response", "--n-speeds", "3"], ["n_speeds", "range"]),
        (["modes", "--speed", "-1"], ["modes", "--speed", "range"]),
        (["campbell", "--speed-max", "-2"], ["campbell", "--speed-max", "out of range"]),
        # issue 18.6: each of these ran (or traced back) before
        (["campbell", "--n-speeds", "0"], ["campbell", "--n-speeds", "[2, inf)"]),
        (["modes", "--speed", "99"], ["--speed", "normalisation.speed_max = 12"]),
        (["continuation", "--speed", "-1"], ["continuation", "--speed", "out of range"]),
        (["transient", "--g0", "-1"], ["transient", "--g0", "contact.max_penetration"]),
        (["transient", "--t-end", "0"], ["transient", "--t-end", "(0, inf) s"]),
    ],
)
def test_bad_arguments_in_process(tmp_path, capsys, args, needles):
    out = tmp_path / "never"
    t0 = time.perf_counter()
    assert main([*args, "--out", str(out)]) != 0
    # refused before any work (continuation --speed -1 used to compute 8 s of maps first)
    assert time.perf_counter() - t0 < 2.0
    captured = capsys.readouterr()
    _one_error_line(captured.err, *needles)
    assert captured.out == ""


def test_bad_params_value_in_process(tmp_path, capsys, bad_params_file):
    assert main(["response", "--params", str(bad_params_file), "--out", str(tmp_path / "x")]) != 0
    _one_error_line(capsys.readouterr().err, "bad.toml", "shaft.E", "range")


def test_missing_params_file_in_process(tmp_path, capsys):
    missing = tmp_path / "nope.toml"
    assert main(["modes", "--params", str(missing), "--out", str(tmp_path / "x")]) != 0
    _one_error_line(capsys.readouterr().err, "nope.toml", "cannot be read")


def test_bad_input_subprocess(tmp_path, bad_params_file):
    proc = _cli("response", "--params", str(bad_params_file), "--out", str(tmp_path / "x"))
    assert proc.returncode != 0
    _one_error_line(proc.stderr, "shaft.E", "range")
    proc = _cli("response", "--params", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "x"))
    assert proc.returncode != 0
    _one_error_line(proc.stderr, "nope.toml", "cannot be read")
    proc = _cli("response", "--speed-min", "-1", "--out", str(tmp_path / "x"))
    assert proc.returncode != 0
    _one_error_line(proc.stderr, "--speed-min", "out of range")
    assert not (tmp_path / "x").exists(), "no output folder on bad input"


def test_malformed_number_gives_one_line(tmp_path):
    proc = _cli("response", "--n-speeds", "abc", "--out", str(tmp_path / "x"))
    assert proc.returncode != 0
    _one_error_line(proc.stderr, "--n-speeds", "abc")
