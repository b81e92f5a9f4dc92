"""Wall time of a 100 x 100 static + stability map (one formulation) on all cores.

Run: python benchmarks/bench_maps.py [n]   (default n = 100)
"""

from __future__ import annotations

import os
import sys
import time

from rotorub_model.analyses.maps import run_stability_map
from rotorub_model.app.studies import default_grid
from rotorub_model.structure.model import build_model


def main(n: int = 100) -> None:
    m = build_model()
    speeds, g0s = default_grid(m, quick=False)
    import numpy as np

    speeds = np.linspace(speeds[0], speeds[-1], n)
    g0s = np.linspace(g0s[0], g0s[-1], n)
    for f in ("2D", "3D"):
        t = time.perf_counter()
        r = run_stability_map(m, f, speeds, g0s, progress=False)
        el = time.perf_counter() - t
        s = r.summary()
        print(f"{f}: {n} x {n} map on {os.cpu_count()} cores: {el:6.1f} s "
              f"({el / n / n * 1e3:.2f} ms per point; {s['contact_points']} contact points)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
