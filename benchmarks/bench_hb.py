"""Harmonic-balance speed sweep against the transient sweep that gives the same amplitudes within 1 %, in one run.

    python benchmarks/bench_hb.py [--formulation 2D] [--speeds 9] [--t-end 30]

Reference with a casing offset of 0.3 mm at g0 = 0.5 mm (the n = 1 term of the casing surface; the oval, n = 2,
once the kernel's distortion is in the build: --lobe 2). Both sweeps over the same speeds, serial, one BLAS thread:

* HB: H = 10, Newton from the previous speed's orbit, the Floquet multipliers (monodromy) at every speed;
* transients: from the static deflection, ``--t-end`` seconds per speed (30 s: what settles the slowest stable
  orbit, multiplier 0.995, to below 1 %), the settled amplitude read on the last revolution.

Printed: both times, the ratio, and the largest relative amplitude difference where both are periodic.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

from rotorub_model.analyses.harmonic.orbit import OrbitView
from rotorub_model.analyses.harmonic.problem import HBProblem, newton
from rotorub_model.analyses.harmonic.stability import monodromy_multipliers
from rotorub_model.analyses.harmonic.surface import CasingForcing
from rotorub_model.analyses.harmonic.transients import KINDS, forced_transient
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import to_dict


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--formulation", default="2D")
    ap.add_argument("--speeds", type=int, default=9)
    ap.add_argument("--t-end", type=float, default=30.0)
    ap.add_argument("--lobe", type=int, default=None)
    ns = ap.parse_args(argv)
    m = build_model()
    wr = m.params.normalisation.omega_ref
    g0 = 0.5e-3
    forcing = CasingForcing.lobe(ns.lobe, 0.15e-3) if ns.lobe else CasingForcing(offset=(0.3e-3, 0.0))
    speeds = np.linspace(2.5, 4.5, ns.speeds)
    with threadpool_limits(limits=1):
        t0 = time.perf_counter()
        pb = HBProblem(m, make_contact(m, ns.formulation, g0=g0), 10, forcing=forcing)
        Y, hb = None, []
        for s in speeds:
            om = s * wr
            r = newton(pb, pb.linear_start(om, om) if Y is None else Y, om, om)
            if not r.converged:
                r = newton(pb, pb.linear_start(om, om), om, om)
            Y = r.Y
            fl = monodromy_multipliers(pb, Y, om, om)
            me = OrbitView(pb, Y, om, om, samples=256).measures()
            hb.append((r.converged, fl.stable, me.tip_amplitude, me.disk_amplitude))
        t_hb = time.perf_counter() - t0
        t0 = time.perf_counter()
        pd = to_dict(m.params)
        tr = [forced_transient(pd, ns.formulation, s * wr, g0, forcing.offset,
                               {k: list(v) for k, v in forcing.lobes.items()}, ns.t_end) for s in speeds]
        t_tr = time.perf_counter() - t0
    worst, both = 0.0, 0
    for (ok, stable, tip, disk), t in zip(hb, tr):
        if ok and stable and KINDS[int(t["kind"])] == "periodic":
            both += 1
            floor = 1e-3 * g0
            worst = max(worst, abs(float(t["disk_amplitude"]) - disk) / max(disk, floor),
                        abs(float(t["tip_amplitude"]) - tip) / max(tip, floor))
    print(f"{ns.formulation}, {len(speeds)} speeds 2.5-4.5, {forcing.summary()['forced_harmonics']} forced harmonics")
    print(f"HB sweep (H = 10, with stability): {t_hb:.3f} s")
    print(f"transient sweep ({ns.t_end:g} s each):  {t_tr:.3f} s")
    print(f"ratio transient / HB: {t_tr / t_hb:.1f} (target >= 20)")
    print(f"speeds where both are periodic: {both}; largest relative amplitude difference there: {100 * worst:.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
