"""app/cli.py, what a user reads (issue 25.2, 25.7): every command ends with a short verdict (what was computed,
the key numbers, where the files are), never a JSON dump cut mid-string; ``--json`` prints the whole summary as
valid JSON (Ω as Ω); help that matches behaviour; one length unit, or both accepted and stated; ``wear`` on a liner
that is off says so."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from rotorub_model.app.cli import build_parser, length, main
from rotorub_model.app.studies import QUICK_GRID, default_grid


def _run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_modes_ends_with_a_verdict_not_a_json_dump(tmp_path, capsys):
    """The issue: `rotorub modes ... | python -c 'json.load(sys.stdin)'` failed at char 3999 of a dump cut with
    '... (full result in --out)'. Now a person reads two lines: what was computed and where the files are."""
    code, out, err = _run(capsys, "modes", "--speed", "3.3", "--out", str(tmp_path / "m"))
    assert code == 0
    lines = out.strip().splitlines()
    assert len(lines) == 2 and "full result in --out" not in out and not out.lstrip().startswith("{")
    assert lines[0].startswith("Modes at Ω = 3.3 Ω_ref: 38 modes") and "least damped" in lines[0]
    assert lines[-1].startswith(f"files: {tmp_path / 'm'}/") and "modes.png" in lines[-1] and "modes.json" in lines[-1]


def test_json_prints_the_whole_summary_as_valid_json(tmp_path, capsys):
    code, out, _ = _run(capsys, "modes", "--speed", "3.3", "--json", "--out", str(tmp_path / "m"))
    assert code == 0
    printed = json.loads(out)  # the whole of stdout parses
    assert printed == json.loads((tmp_path / "m" / "modes.json").read_text())
    assert len(printed["modes"]) == 38  # the whole summary, more than 4000 characters of it
    assert len(out) > 4000


def test_json_through_a_pipe_with_progress_on_stderr(tmp_path):
    """A script reads stdout: JSON alone, Ω written as Ω (not \\u03a9), progress and stages on stderr."""
    proc = subprocess.run([sys.executable, "-m", "rotorub_model.app.cli", "static", "--json", "--speed", "3.3",
                           "--g0", "0.3mm", "--out", str(tmp_path / "st")], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    s = json.loads(proc.stdout)
    assert s["g0_m"] == pytest.approx(0.3e-3) and s["stability"]["stable"] is False
    assert "Ω" in s["verdict"] or "Re λ" in s["verdict"]
    assert "\\u03" not in proc.stdout and "\\u03" not in (tmp_path / "st" / "static.json").read_text()


def test_static_is_a_result_object_with_its_verdict(tmp_path, capsys):
    """rotorub static no longer draws by hand: StaticResult.save writes static.png and static.json, the verdict
    in both and on the console."""
    code, out, _ = _run(capsys, "static", "--speed", "3.3", "--g0", "0.3e-3", "--formulation", "2D", "--out",
                        str(tmp_path / "st"))
    assert code == 0
    s = json.loads((tmp_path / "st" / "static.json").read_text())
    assert s["verdict"].startswith("balanced solution") and ("UNSTABLE" in s["verdict"] or "stable" in s["verdict"])
    assert s["verdict"] in out and (tmp_path / "st" / "static.png").stat().st_size > 20_000


@pytest.mark.parametrize("text, metres", [("0.3e-3", 3e-4), ("0.3mm", 3e-4), ("300um", 3e-4), ("300 µm", 3e-4),
                                          ("1 m", 1.0), ("-2.9mm", -2.9e-3)])
def test_a_length_is_metres_or_says_its_unit(text, metres):
    assert length(text) == pytest.approx(metres, rel=1e-12)


def test_a_length_with_an_unknown_unit_is_one_line(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "rotorub_model.app.cli", "static", "--g0", "0.3in", "--out",
                           str(tmp_path / "x")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "--g0" in lines[0] and "0.3mm" in lines[0]


def test_a_file_clearance_out_of_the_cli_range_names_the_file_field(tmp_path, capsys):
    """contact.g0 = -10 mm in a parameter file loads (an interference down to half a blade), but static refuses it
    beyond -max_penetration: the line named '--g0', a flag the user never gave; it names the file's field now, and
    a given --g0 keeps its name."""
    from rotorub_model.structure.params import reference_parameters, to_toml

    params = tmp_path / "deep.toml"
    params.write_text(to_toml(reference_parameters().replace(contact={"g0": -0.01})))
    code, _, err = _run(capsys, "static", "--params", str(params), "--speed", "3.3", "--out", str(tmp_path / "x"))
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "contact.g0 of the parameter file" in lines[0], lines
    assert "--g0:" not in lines[0] and "[-0.003, 0.1] m" in lines[0]
    code, _, err = _run(capsys, "static", "--params", str(params), "--speed", "3.3", "--g0=-5mm", "--out",
                        str(tmp_path / "y"))
    assert code == 2 and err.strip().startswith("rotorub static: error: --g0: -0.005 out of range")


def test_every_length_option_states_its_unit():
    """--g0-max-mm took millimetres where --g0 took metres: every length option now takes metres or a stated
    unit, and says so in its help; --g0-max-mm stays, named as the same length in millimetres."""
    ap = build_parser()
    sub = next(a for a in ap._actions if a.dest == "command")
    for name, sp in sub.choices.items():
        for a in sp._actions:
            if a.type is length:
                assert "[m]" in a.help and "0.3mm" in a.help, (name, a.option_strings, a.help)
    detect = sub.choices["detect"]
    opts = {s: a for a in detect._actions for s in a.option_strings}
    assert opts["--g0-max"].type is length and "millimetres" in opts["--g0-max-mm"].help


def test_help_states_what_the_commands_do():
    """stability --quick said 40 x 30 while the grid was 40 x 36; build-fmu --platforms left out aarch64-linux."""
    ap = build_parser()
    sub = next(a for a in ap._actions if a.dest == "command")
    quick = next(a for a in sub.choices["stability"]._actions if a.dest == "quick")
    assert f"{QUICK_GRID[0]} speeds x {QUICK_GRID[1]} clearances" in quick.help
    from rotorub_model.structure.model import build_model

    speeds, g0s = default_grid(build_model(), quick=True)
    assert (len(speeds), len(g0s)) == QUICK_GRID
    if "build-fmu" in sub.choices:
        from fmu_src.fmi.compile import ALL_PLATFORMS

        plats = next(a for a in sub.choices["build-fmu"]._actions if a.dest == "platforms")
        assert all(p in plats.help for p in ALL_PLATFORMS), plats.help


def test_wear_on_a_liner_that_is_off_says_so(tmp_path, capsys):
    """The reference's liner is off (abradable.enabled = false): `rotorub wear` ran it without a remark. It still
    wears it (that is the analysis), and says so on stderr first, in its summary and in its verdict."""
    code, out, err = _run(capsys, "wear", "--speed", "3.3", "--g0", "0.5mm", "--t-end", "1.2", "--out",
                          str(tmp_path / "w"))
    assert code == 0
    assert "abradable.enabled = false" in err and "abradable.enabled = false" in out.splitlines()[0]
    s = json.loads((tmp_path / "w" / "summary.json").read_text())
    assert "abradable.enabled = false" in s["liner_note"]
    assert "lobe" in out or "no wear" in out
