"""fmu_src/fmi/compile.py's messages (issue 25.7): the parallel compilations' lines never run into each other."""

from __future__ import annotations

import subprocess
import sys

from fmu_src.fmi import compile as fc

SCRIPT = """
import sys, threading
sys.setswitchinterval(1e-6)  # threads switch as often as they can: the worst case of a loaded machine
from fmu_src.fmi.compile import ALL_PLATFORMS, say
ts = [threading.Thread(target=lambda p=p: [say(f"RotorCasingContact: {p}: compiling ({k})") for k in range(400)])
      for p in ALL_PLATFORMS]
[t.start() for t in ts]
[t.join() for t in ts]
"""


def test_build_messages_of_parallel_compilations_are_one_per_line():
    """Each platform compiles in its own thread and says when it starts, beats and ends. print() wrote a message
    and its newline apart: with the threads switching often, 482 of 10 000 lines ran into another (measured with
    the old say on a pipe). Every line is now written whole, under a lock."""
    proc = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 400 * len(fc.ALL_PLATFORMS)
    broken = [ln for ln in lines if ln.count("[build-fmu]") != 1 or not ln.endswith(")")]
    assert broken == [], broken[:3]
    assert fc.HEARTBEAT_S < 10  # a compilation quiet for longer says it is still running
