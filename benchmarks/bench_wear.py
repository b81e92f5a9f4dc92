"""What the abradable liner costs a transient: the same run with and without it, as a ratio, in one run.

    .venv/bin/python benchmarks/bench_wear.py [--repeat 5]

The section-6 point of the reference (3.3 Omega_ref, g0 = 0.335 mm, 20 s, the imbalance ramped over 1 s: a
360-degree rub), 2D and 3D: run_transient without a liner; with a rigid surface (the liner's gap correction
alone, nothing cut); with the abradable liner wearing (the default 720 cells, the profile recorded every
50 ms). Best of --repeat. Target (issue 19): wearing <= 1.3x the run without it.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from timing import best_of  # noqa: E402

from rotorub_model import build_model  # noqa: E402
from rotorub_model.analyses.transient import run_transient  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402
from rotorub_model.contact.liner import Liner  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ns = ap.parse_args()
    m = build_model()
    w = 3.3 * m.params.normalisation.omega_ref
    print(f"20 s at 3.3 Omega_ref, g0 = 0.335 mm (best of {ns.repeat})")
    worst = 0.0
    for f in ("2D", "3D"):
        c = make_contact(m, f, g0=0.335e-3)
        run_transient(m, c, w, t_end=0.1)  # kernel loaded, matrices warm
        base = best_of(lambda c=c: run_transient(m, c, w, t_end=20.0), ns.repeat)
        rigid = best_of(lambda c=c: run_transient(m, c, w, t_end=20.0, liner=Liner.for_model(m, c, wears=False)),
                        ns.repeat)
        wear = best_of(lambda c=c: run_transient(m, c, w, t_end=20.0, liner=Liner.for_model(m, c, wears=True)),
                       ns.repeat)
        worst = max(worst, wear / base)
        print(f"  {f}: no liner {base * 1e3:7.1f} ms   rigid surface {rigid * 1e3:7.1f} ms ({rigid / base:4.2f}x)   "
              f"wearing {wear * 1e3:7.1f} ms ({wear / base:4.2f}x)")
    print(f"target: wearing <= 1.3x the run without a liner: {'met' if worst <= 1.3 else 'NOT met'} ({worst:.2f}x)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
