"""Linear analyses side by side with ROSS (petrobras/ross), the open rotordynamics library, in one run.

    .venv/bin/python benchmarks/bench_ross.py [--ross-python PATH] [--repeat 5]

ROSS's own example rotor (`ross.rotor_example()`: 42 dofs, a shaft of 6 elements, 2 disks, 2 bearings)
against rotorub's reference model (38 dofs: shaft, fan and LPT disks, 10 flexible blades, casing ring),
the same kind of model and size. Measured (best of --repeat, seconds; rotorub/ROSS ratios):

* modes at one speed: ROSS `run_modal(speed, sparse=False)` (its dense eigen-solver) against rotorub
  `run_modes` (every mode, with its fixed-frame frequency and nodal-diameter label);
* a Campbell diagram over 50 speeds: ROSS `run_campbell` against rotorub `run_campbell`;
* an imbalance response over 400 speeds: ROSS `run_unbalance_response` against rotorub `run_response`
  (which also locates the critical speeds).

ROSS runs in this interpreter when it imports here, else in the one given by --ross-python (or the
ROSS_PYTHON environment variable: a venv with `pip install ross-rotordynamics 'plotly<6'`: ROSS 2.3
fails to import with plotly 6), in a child process timed the same way during this run. Without ROSS the
script says so and prints rotorub's figures alone. Target (issue 18): modes and Campbell >= 10x faster.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from timing import best_of  # noqa: E402

ROSS_CHILD = r"""
import json, sys, time, warnings
warnings.filterwarnings("ignore")
import numpy as np
import ross as rs

def best_of(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter(); fn(); best = min(best, time.perf_counter() - t)
    return best

repeat = int(sys.argv[1])
rotor = rs.rotor_example()
k = iter(range(10**6))  # a new speed each call: run_modal caches by speed
modal = best_of(lambda: rotor.run_modal(100.0 + next(k) * 1e-3, sparse=False), repeat)
campbell = best_of(lambda: rotor.run_campbell(np.linspace(0.0, 1000.0, 50) + next(k) * 1e-3), max(1, repeat // 2))
response = best_of(lambda: rotor.run_unbalance_response(node=3, unbalance_magnitude=0.001, unbalance_phase=0.0,
                                                        frequency=np.linspace(1.0, 1000.0, 400)), max(1, repeat // 2))
print(json.dumps({"version": rs.__version__, "ndof": int(rotor.ndof), "modes_s": modal, "campbell_50_s": campbell,
                  "response_400_s": response}))
"""


def ross_figures(python: str | None, repeat: int) -> dict | str:
    """ROSS's timings (a dict), or why there are none (a str)."""
    exe = python
    if exe is None:
        try:
            import ross  # noqa: F401

            exe = sys.executable
        except Exception as exc:  # noqa: BLE001 - any import failure means: not usable here
            return (f"ROSS does not import here ({type(exc).__name__}); give --ross-python or ROSS_PYTHON (a venv "
                    "with: pip install ross-rotordynamics 'plotly<6')")
    proc = subprocess.run([exe, "-c", ROSS_CHILD, str(repeat)], capture_output=True, text=True, timeout=1800)
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("{")]
    if proc.returncode != 0 or not lines:
        return f"ROSS run failed ({exe}): {proc.stderr.strip().splitlines()[-1:]}"
    return json.loads(lines[-1])


def rotorub_figures(repeat: int) -> dict:
    from rotorub_model import build_model
    from rotorub_model.analyses.linear import run_campbell, run_modes, run_response

    model = build_model()
    model.cyclic  # noqa: B018 - built once per model (as a study does), not part of one analysis
    k = iter(range(10**6))
    return {
        "ndof": model.n_dofs,
        "modes_s": best_of(lambda: run_modes(model, 2.0 + next(k) * 1e-6), repeat),
        "campbell_50_s": best_of(lambda: run_campbell(model, 10.0, 50), repeat),
        "response_400_s": best_of(lambda: run_response(model, 0.05, 10.0, 400), max(1, repeat // 2)),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ross-python", default=os.environ.get("ROSS_PYTHON"))
    ap.add_argument("--repeat", type=int, default=5)
    ns = ap.parse_args()
    ours = rotorub_figures(ns.repeat)
    ross = ross_figures(ns.ross_python, ns.repeat)
    print(f"rotorub reference model: {ours['ndof']} dofs")
    if isinstance(ross, str):
        print(f"ROSS: not run: {ross}")
        for key in ("modes_s", "campbell_50_s", "response_400_s"):
            print(f"  {key:16s} rotorub {ours[key] * 1e3:9.2f} ms")
        return 0
    print(f"ROSS {ross['version']} rotor_example: {ross['ndof']} dofs (dense solver)")
    print(f"  {'':16s} {'rotorub':>12s} {'ROSS':>12s} {'ROSS / rotorub':>15s}")
    for key, label in (("modes_s", "modes, 1 speed"), ("campbell_50_s", "Campbell, 50"), ("response_400_s",
                                                                                         "response, 400")):
        print(f"  {label:16s} {ours[key] * 1e3:9.2f} ms {ross[key] * 1e3:9.2f} ms {ross[key] / ours[key]:14.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
