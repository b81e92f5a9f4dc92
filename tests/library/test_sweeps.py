"""Sweeps: the same map through a serial loop, a process pool and a local Dask cluster,
and an interrupted sweep resumes from the rows already written."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.analyses.maps import run_stability_map
from rotorub_model.structure.model import build_model

SPEEDS = np.array([3.3, 3.4, 3.45])
G0S = np.array([0.0, 0.6e-3, 1.2e-3])


@pytest.fixture(scope="module")
def model():
    return build_model()


@pytest.fixture(scope="module")
def serial(model):
    return run_stability_map(model, "3D", SPEEDS, G0S, executor="serial", progress=False)


def _same(a, b):
    np.testing.assert_array_equal(a.n_contact, b.n_contact)
    np.testing.assert_allclose(a.max_real, b.max_real, rtol=1e-9, atol=1e-12)


def test_map_has_contact_and_no_contact(serial):
    assert serial.contact.any() and (serial.n_contact == 0).any()


def test_process_pool_matches_serial(model, serial):
    _same(run_stability_map(model, "3D", SPEEDS, G0S, progress=False), serial)


def test_dask_cluster_matches_serial(model, serial):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        with distributed.Client(cl) as client:
            res = run_stability_map(model, "3D", SPEEDS, G0S, executor=client.get_executor(), progress=False)
    _same(res, serial)


def test_interrupted_sweep_resumes(model, serial, tmp_path, monkeypatch):
    import rotorub_model.analyses.maps as maps

    calls = []
    real = maps.map_row

    def flaky(**kw):
        calls.append(kw["speed"])
        if len(calls) == 2:
            raise KeyboardInterrupt("simulated interruption")
        return real(**kw)

    monkeypatch.setattr(maps, "map_row", flaky)
    with pytest.raises(KeyboardInterrupt):
        run_stability_map(model, "3D", SPEEDS, G0S, executor="serial", out=tmp_path, progress=False)
    assert len(list((tmp_path / "rows").glob("*.npz"))) == 1
    calls.clear()
    monkeypatch.setattr(maps, "map_row", real)
    counted = []
    monkeypatch.setattr(maps, "map_row", lambda **kw: counted.append(kw["speed"]) or real(**kw))
    res = run_stability_map(model, "3D", SPEEDS, G0S, executor="serial", out=tmp_path, progress=False)
    assert len(counted) == 2  # only the two missing rows were computed
    _same(res, serial)


def _blas_threads(tag: int) -> dict[str, np.ndarray]:
    from threadpoolctl import threadpool_info

    pools = [p["num_threads"] for p in threadpool_info() if p.get("user_api") == "blas"]
    return {"tag": np.array(tag), "threads": np.array(max(pools) if pools else 1)}


def test_pool_tasks_run_blas_on_one_thread():
    """Each worker is one core's worth of work: a task whose BLAS started a thread per core
    made the 18-blade maps 5-20x slower (issue 18.1). The limit must hold in the worker."""
    from concurrent.futures import ProcessPoolExecutor

    from rotorub_model.analyses.sweeps import run_tasks

    with ProcessPoolExecutor(max_workers=2) as ex:
        res = run_tasks(_blas_threads, [{"tag": i} for i in range(4)], executor=ex, progress=False)
    assert [int(r["tag"]) for r in res] == [0, 1, 2, 3]
    assert all(int(r["threads"]) == 1 for r in res), [int(r["threads"]) for r in res]
