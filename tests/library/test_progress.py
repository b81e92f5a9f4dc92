"""progress.py (issue 25.3, 25.7): a stage is named, says it is still running when it has been quiet for the
heartbeat, and its time at the end; lines from threads never run into each other."""

from __future__ import annotations

import threading
import time

from rotorub_model import progress


def test_a_quiet_stage_says_it_is_still_running(capsys):
    with progress.stage("a slow solver", heartbeat=1.0):
        time.sleep(2.6)
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0] == "[rotorub] a slow solver ..."
    beats = [ln for ln in lines if "still running" in ln]
    assert 1 <= len(beats) <= 3, lines
    assert lines[-1].startswith("[rotorub] a slow solver: done in 2.")


def test_a_stage_that_speaks_needs_no_heartbeat(capsys):
    """An inner stage or a line said inside counts as speaking: the outer stage does not add its own beats."""
    with progress.stage("outer", heartbeat=1.5):
        for k in range(5):
            progress.say(f"step {k}")
            time.sleep(0.5)
    err = capsys.readouterr().err
    assert "still running" not in err and err.count("step ") == 5


def test_parallel_lines_are_whole_lines(capsys):
    """Build messages of parallel compilations ran into each other on one line: every line is now written whole,
    under a lock."""
    def talk(name: str) -> None:
        for k in range(50):
            progress.say(f"{name}: line {k} " + "x" * 40, "build-fmu")

    threads = [threading.Thread(target=talk, args=(f"platform{i}",)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 200
    assert all(ln.startswith("[build-fmu] platform") and ln.endswith("x" * 40) and ln.count("[build-fmu]") == 1
               for ln in lines)


def test_a_disabled_stage_says_nothing(capsys):
    with progress.stage("quiet", enabled=False):
        pass
    assert capsys.readouterr().err == ""


def test_a_short_or_refused_stage_adds_no_line(capsys):
    """A stage over in less than half a second says nothing; one that fails fast adds nothing to its error line."""
    with progress.stage("quick"):
        pass
    try:
        with progress.stage("refused"):
            raise ValueError("bad input")
    except ValueError:
        pass
    assert capsys.readouterr().err == ""
