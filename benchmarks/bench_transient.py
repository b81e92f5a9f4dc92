"""run_transient end to end against a bare compiled loop of the same physics, in one run.

    python benchmarks/bench_transient.py [--t-end 2.5] [--repeat 5]

Scenario (issue 10): 3D contact, Omega = 3.3 omega_ref, g0 = 0.334 mm (the fact-6 point),
imbalance ramped over 1 s, outputs every 1 ms.

* library: ``run_transient(..., record_dt=1e-3)`` end to end (setup, the kernel's loop with
  its records and outputs, the result object with fixed-frame outputs);
* library, records every 10 ms: the same run with a tenth of the records (what the records cost);
* library, held inputs: ``run_transient(..., hold=1e-3)`` (what a co-simulation master does:
  one kernel call per 1 ms);
* bare: ``benchmarks/bare_loop.c``: the same steps (three mat-vecs + the contact law of the
  10 blades and its projection, the kernel's own code) and nothing else, compiled with the
  same compiler and flags as the kernel, called once.

Printed: time per step of each and the ratio library / bare (target <= 1.25, issue 24). The three are timed in turn,
best of ``--repeat`` rounds after a warm-up (a ratio of runs made under the same conditions).
"""

from __future__ import annotations

import argparse
import ctypes
import tempfile
from pathlib import Path

import numpy as np
from timing import best_of_interleaved, pin_to_one_cpu

from rotorub_model import kernel
from rotorub_model.analyses.transient import CentralDifference, run_transient
from rotorub_model.contact import make_contact
from rotorub_model.kernel.compiler import compile_shared, host_suffix
from rotorub_model.structure.model import build_model

HERE = Path(__file__).resolve().parent


def bare_library(tmp: Path, target: str | None = None) -> ctypes.CDLL:
    """The bare loop compiled with the kernel's compiler (``target``: an FMI platform folder, to build it with the
    compiler the native FMU's binary is built with, ziglang's clang: a ratio against the FMU compares one compiler's
    code with itself)."""
    out = compile_shared([HERE / "bare_loop.c", *kernel.SOURCES], tmp / f"bare_loop{host_suffix()}",
                         include=[kernel.HERE], target=target)
    lib = ctypes.CDLL(str(out))
    dp = ctypes.c_void_p
    lib.bare_cd.argtypes = [ctypes.POINTER(kernel.RRContact), ctypes.POINTER(kernel.RRMatrices), dp, dp,
                            ctypes.c_double, ctypes.c_double, ctypes.c_int, ctypes.c_double]
    lib.bare_cd.restype = None
    return lib


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=2.5)
    ap.add_argument("--repeat", type=int, default=25)
    ns = ap.parse_args(argv)

    pinned = pin_to_one_cpu()
    m = build_model()
    omega = 3.3 * m.params.normalisation.omega_ref
    me = m.params.imbalance.me
    c = make_contact(m, "3D", g0=0.334e-3)

    def library():
        return run_transient(m, c, omega, t_end=ns.t_end, record_dt=1e-3)

    def library_sparse():  # what the records cost: the same run recording every 10 ms
        return run_transient(m, c, omega, t_end=ns.t_end, record_dt=1e-2)

    def library_hold():
        return run_transient(m, c, omega, t_end=ns.t_end, record_dt=1e-3, hold=1e-3)

    r = library()  # warm-up: kernel loaded, and the step the run uses
    n_steps = int(round(ns.t_end / r.dt))
    cd = CentralDifference(m, c, dt=r.dt, t_ramp=1.0)
    mats = cd._matrices(omega, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        bare = bare_library(Path(tmp))
        q, qp = np.zeros(m.n_dofs), np.zeros(m.n_dofs)

        def bare_run():
            q[:] = 0.0
            qp[:] = 0.0
            bare.bare_cd(c.kernel, mats, kernel.ptr(q), kernel.ptr(qp), r.dt, omega, n_steps, me)

        bare_run()
        for _ in range(3):  # warm-up of every path (allocators, caches, the frequency governor)
            library(), library_sparse(), library_hold(), bare_run()
        t = best_of_interleaved({"lib": library, "sparse": library_sparse, "hold": library_hold, "bare": bare_run},
                                ns.repeat)
        t_lib, t_sparse, t_hold, t_bare = t["lib"], t["sparse"], t["hold"], t["bare"]
    h = library_hold()
    print(f"model: {m.n_dofs} dofs, 3D contact ({c.n_blades} blades x {c.n_points} points); "
          f"{n_steps} steps of {r.dt:.3e} s ({ns.t_end:g} s), records every 1 ms: {len(r.t)}; {pinned}")
    print(f"blades in contact at the end: {r.blades_in_contact()}; held-input run: {len(h.t)} records")
    print(f"run_transient end to end       : {t_lib / n_steps * 1e9:8.1f} ns/step  ({t_lib * 1e3:.1f} ms)")
    print(f"run_transient(hold=1 ms)       : {t_hold / n_steps * 1e9:8.1f} ns/step  ({t_hold * 1e3:.1f} ms)")
    print(f"bare compiled loop (no outputs): {t_bare / n_steps * 1e9:8.1f} ns/step  ({t_bare * 1e3:.1f} ms)")
    print(f"ratio run_transient / bare     : {t_lib / t_bare:8.2f}  (target <= 1.25)")
    print(f"ratio hold / bare              : {t_hold / t_bare:8.2f}")
    n_rec = len(r.t)
    print(f"records every 10 ms / bare     : {t_sparse / t_bare:8.2f}  (what a record costs: "
          f"{(t_lib - t_sparse) / (n_rec - n_rec // 10) * 1e9:.0f} ns each, kernel outputs and the result's arrays)")
    print(f"simulated seconds per wall second: {ns.t_end / t_lib:8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
