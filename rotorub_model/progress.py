"""What a long command says while it works: stage lines and a heartbeat, on stderr (stdout carries only the
command's verdict, or its JSON with ``--json``).

Rule (issue 25.3): no silent stretch longer than 10 s. Loops with a count show a tqdm bar; a stage without one
(a solver, a compilation, a picker) runs inside :func:`stage`, which names it (once it has run half a second: a
refusal on bad input stays the one line it is), says it is still running when nothing has been shown for
HEARTBEAT_S seconds, and ends with its time. Lines go through ``tqdm.write``: a bar being drawn is cleared and
redrawn around them, so a line never lands in the middle of a bar or of another thread's line.

>>> with stage("a short stage", enabled=False):
...     pass
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

HEARTBEAT_S = 8.0  # below the 10 s a user waits without a word
_LOCK = threading.Lock()
_LAST = [0.0]  # when the last line was said (a heartbeat stays quiet while something else speaks)


def _quiet_for() -> float:
    """Seconds since anything was last shown: a line said here, or a tqdm bar redrawn."""
    from tqdm import tqdm

    last = _LAST[0]
    for bar in list(getattr(tqdm, "_instances", [])):
        last = max(last, float(getattr(bar, "last_print_t", 0.0) or 0.0))
    return time.time() - last


def say(msg: str, prefix: str = "rotorub") -> None:
    """One line on stderr, whole (threads' lines never run into each other), around any tqdm bar."""
    from tqdm import tqdm

    with _LOCK:
        tqdm.write(f"[{prefix}] {msg}" if prefix else msg, file=sys.stderr)
        sys.stderr.flush()
        _LAST[0] = time.time()


ANNOUNCE_AFTER_S = 0.5  # a stage over before this says nothing (a refusal stays the one line it is)


@contextmanager
def stage(what: str, enabled: bool = True, prefix: str = "rotorub", heartbeat: float = HEARTBEAT_S,
          done: bool = True, announce_after: float = ANNOUNCE_AFTER_S) -> Iterator[None]:
    """Announce ``what`` once it has run ``announce_after`` seconds (a stage that ends, or fails on bad input,
    sooner says nothing: the error stays one line), say every ``heartbeat`` seconds that it is still running, and
    (``done``) its time at the end; nothing at all when not ``enabled`` (a library call with progress off)."""
    if not enabled:
        yield
        return
    t0 = time.perf_counter()
    stop = threading.Event()
    announced = threading.Event()

    def beat() -> None:
        if stop.wait(announce_after):
            return
        say(f"{what} ...", prefix)
        announced.set()
        # every second, a line when nothing (this stage, an inner one, a progress bar) has spoken for `heartbeat`
        while not stop.wait(1.0):
            if _quiet_for() >= heartbeat:
                say(f"{what}: still running ({time.perf_counter() - t0:.0f} s)", prefix)

    thread = threading.Thread(target=beat, daemon=True)
    thread.start()
    ok = False
    try:
        yield
        ok = True
    finally:
        stop.set()
        thread.join(timeout=1.0)
    if done and ok and announced.is_set():
        say(f"{what}: done in {time.perf_counter() - t0:.1f} s", prefix)
