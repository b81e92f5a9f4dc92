"""What importing and reducing a fine FE blade costs: time and peak memory, against CalculiX's own modal solve
of the same mesh, in one run.

    .venv/bin/python benchmarks/bench_fe_import.py [--fe-dir DIR] [--mesh-size 11]

The blade is the project's example (examples/fan_blade/make_fan_blade.py); at --mesh-size 11 mm it has about
60 000 dofs. Without --fe-dir the script makes it (needs gmsh and calculix-ccx). Each measurement runs in a
child process of its own (its peak resident memory is the child's): reading the CalculiX files alone; reading
and reducing (the modes at rest and at the top speed, the condensed basis, the speed terms, the tip's residual
flexibility: what ``rotorub import-blade`` needs); and the same with the full model solved at every speed (the
report's check). The reference, in the same run: CalculiX's own modal step on the same mesh (its rest job, run
again). Targets (issue 26): import and reduce <= 60 s and <= 2 GB on 2 cores. The machine's load average is
printed beside the numbers (a loaded machine's times are longer; the ratio to CalculiX's own holds better).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import json, resource, sys, time
import numpy as np
from rotorub_model.fe import read_calculix, reduce_blade
d, what = sys.argv[1], sys.argv[2]
t0 = time.perf_counter()
jobs = json.load(open(d + "/ccx_frequencies.json"))["jobs"]
fe = read_calculix([d + "/" + j for j in jobs], coordinates=d + "/mesh.inp", units="N-mm-t-s", mass_free=d + "/free")
t_read = time.perf_counter() - t0
out = {"dofs": fe.n_dofs, "read_s": t_read}
if what != "read":
    tips = np.loadtxt(d + "/tip_nodes.txt", dtype=int)
    b = reduce_blade(fe, tips, cutoff_hz=1500.0, reference_speeds=(what == "check"))
    out.update(reduce_s=time.perf_counter() - t0 - t_read, m=b.m)
out["total_s"] = time.perf_counter() - t0
out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print(json.dumps(out))
"""


def child(fe_dir: Path, what: str) -> dict:
    env = dict(os.environ, OMP_NUM_THREADS="2", OPENBLAS_NUM_THREADS="2")
    r = subprocess.run([sys.executable, "-c", CHILD, str(fe_dir), what], capture_output=True, text=True, env=env,
                       cwd=ROOT)
    if r.returncode:
        raise SystemExit(f"the {what} child failed:\n{r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def ccx_reference(fe_dir: Path) -> float:
    """Seconds of CalculiX's own rest job (modal step and matrix storage) on the same mesh, run again in a copy."""
    with tempfile.TemporaryDirectory() as tmp:
        for f in ("mesh.inp", "speed0.inp"):
            shutil.copy(fe_dir / f, tmp)
        env = dict(os.environ, OMP_NUM_THREADS="2")
        t = time.perf_counter()
        subprocess.run(["ccx", "-i", "speed0"], cwd=tmp, capture_output=True, env=env, check=True)
        return time.perf_counter() - t


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fe-dir", default=None, help="a folder made by examples/fan_blade/make_fan_blade.py")
    ap.add_argument("--mesh-size", type=float, default=11.0, help="mesh size [mm] when the blade is made here")
    ns = ap.parse_args()
    load0 = os.getloadavg()
    if ns.fe_dir is None:
        if shutil.which("ccx") is None or shutil.which("gmsh") is None:
            raise SystemExit("needs gmsh and calculix-ccx to make the blade (or give --fe-dir)")
        sys.path.insert(0, str(ROOT / "examples" / "fan_blade"))
        import make_fan_blade

        fe_dir = Path(tempfile.mkdtemp(prefix="fan_fine_"))
        t = time.perf_counter()
        make_fan_blade.make(fe_dir, mesh_size=ns.mesh_size)
        print(f"made the blade with gmsh and CalculiX (4 speeds + the unclamped mass) in "
              f"{time.perf_counter() - t:.0f} s: {fe_dir}")
    else:
        fe_dir = Path(ns.fe_dir)
    ref = ccx_reference(fe_dir) if shutil.which("ccx") else None
    rows = {what: child(fe_dir, what) for what in ("read", "reduce", "check")}
    load1 = os.getloadavg()
    dofs = rows["read"]["dofs"]
    print(f"blade of {dofs} dofs ({fe_dir}); load average {load0[0]:.1f} at the start, {load1[0]:.1f} at the end "
          f"(2 cores)")
    if ref is not None:
        print(f"reference: CalculiX's own rest job (modal step + matrix storage) {ref:.1f} s")
    for what, r in rows.items():
        ratio = f", {r['total_s'] / ref:.2f}x CalculiX's rest job" if ref else ""
        print(f"  {what:7s} {r['total_s']:6.1f} s (read {r['read_s']:.1f} s), peak RSS {r['peak_rss_mb']:6.0f} MB"
              f"{ratio}" + (f", {r['m']} dofs kept" if "m" in r else ""))
    r = rows["reduce"]
    ok = r["total_s"] <= 60.0 and r["peak_rss_mb"] <= 2048.0
    print(f"target (import and reduce <= 60 s, <= 2 GB): {'met' if ok else 'NOT met'} ({r['total_s']:.1f} s, "
          f"{r['peak_rss_mb']:.0f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
