"""Uncertainty studies on the executors: the per-task overhead, and the speed-up from one worker to two.

    python benchmarks/bench_uq.py [--tasks 200] [--transients 96] [--no-dask]

1. Overhead per task: a study of the analytic test function (``model = "ishigami"``, one evaluation a task,
   the evaluation itself ~1 us) through ``run_tasks`` as a study runs it, with its store: wall time per task
   on the serial loop (the store's write and the bookkeeping), a process pool of 2, a Dask LocalCluster of 2.
2. Speed-up: one transient-level study (reference, 3D, section-6 point, mistuned disks, 4 s runs, 4 per
   task) serially, on a pool of 1 worker and of 2, and on a LocalCluster of 1 and of 2 workers, each the best
   of two runs in this run: the ratios are what count (the machine is shared: the load average is printed
   beside them; on a machine busy with other work the second worker finds no free core).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from rotorub_model.uncertainty import run_uq, study_from_dict


def ishigami(n: int):
    u = {"distribution": "uniform", "low": -3.14159, "high": 3.14159}
    return study_from_dict({"study": {"model": "ishigami", "method": "montecarlo", "sampler": "mc", "n": n,
                                      "chunk": 1, "quantiles": [0.5], "seed": 1},
                            "inputs": {"x1": u, "x2": u, "x3": u}})


def transients(n: int):
    return study_from_dict({"study": {"method": "montecarlo", "sampler": "mc", "n": n, "chunk": 4, "seed": 1,
                                      "quantities": ["peak_force", "amp_contact_transient"], "quantiles": [0.5]},
                            "operating": {"speed": 3.3, "t_end": 4.0},
                            "inputs": {"g0": {"parameter": "contact.g0", "distribution": "fixed", "value": 0.335e-3}},
                            "mistuning": {"kind": "frequency", "sd": 0.02}})


def timed(study, executor, repeat: int = 2) -> tuple[float, dict]:
    """The best of ``repeat`` runs (benchmarks/timing.py's rule), each into a fresh store (nothing reused)."""
    best, cost = float("inf"), {}
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as d:
            t = time.perf_counter()
            r = run_uq(study, executor=executor, out=d, progress=False)
            w = time.perf_counter() - t
        if w < best:
            best, cost = w, r.cost
    return best, cost


def make_executor(kind: str, workers: int):
    """(executor, what to close): a process pool, or a Dask LocalCluster of ``workers`` single-threaded processes."""
    if kind == "process pool":
        from concurrent.futures import ProcessPoolExecutor

        return ProcessPoolExecutor(workers), None
    from dask.distributed import Client, LocalCluster

    cl = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    client = Client(cl)
    return client.get_executor(), (client, cl)


def warm(ex) -> None:
    """Start the workers and load the kernel in each before timing (a pool starts them lazily)."""
    futs = [ex.submit(time.sleep, 0.3) for _ in range(4)]
    for f in futs:
        f.result()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", type=int, default=200)
    ap.add_argument("--transients", type=int, default=96)
    ap.add_argument("--no-dask", action="store_true")
    ns = ap.parse_args(argv)
    dask = not ns.no_dask
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at the start")

    print(f"\n1. overhead per task ({ns.tasks} tasks of one analytic evaluation, store on)")
    st = ishigami(ns.tasks)
    w0, _ = timed(st, "serial")
    print(f"  serial loop                 {1e3 * w0 / ns.tasks:7.2f} ms per task (the reference)")
    kinds = ["process pool"] + (["Dask LocalCluster"] if dask else [])
    for kind in kinds:
        ex, own = make_executor(kind, 2)
        warm(ex)
        w, _ = timed(st, ex)
        print(f"  {kind + ' x2':27s} {1e3 * w / ns.tasks:7.2f} ms per task ({w / w0:.1f}x the serial loop's)")
        _close(ex, own)

    print(f"\n2. speed-up, {ns.transients} transients (3D, 4 s runs, mistuned disks, 4 a task)")
    st = transients(ns.transients)
    base, cost = timed(st, "serial")
    per = cost["levels"]["transient"]["ms_per_evaluation_mean"]
    print(f"  serial                      {base:6.2f} s   ({per:.1f} ms per transient inside)")
    for kind in kinds:
        times, load = {}, {}
        for workers in (1, 2):
            ex, own = make_executor(kind, workers)
            warm(ex)
            times[workers], _ = timed(st, ex)
            load[workers] = os.getloadavg()[0]
            _close(ex, own)
        # the 1-minute load average includes this run's own workers (1 or 2): above that, others ran too
        print(f"  {kind:27s} 1 worker {times[1]:6.2f} s, 2 workers {times[2]:6.2f} s: speed-up "
              f"{times[1] / times[2]:.2f}x (1 worker / serial {times[1] / base:.2f}; load after each "
              f"{load[1]:.1f}, {load[2]:.1f})")
    print(f"\nload average {os.getloadavg()[0]:.2f} at the end (2 cores: above 2, the workers share them with others)")
    return 0


def _close(ex, own) -> None:
    if own is None:
        ex.shutdown()
    else:
        client, cl = own
        client.close()
        cl.close()


if __name__ == "__main__":
    raise SystemExit(main())
