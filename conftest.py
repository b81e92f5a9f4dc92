"""Loaded first by pytest (the rootdir's conftest), before anything imports numpy: one BLAS thread per test process.

The suite runs on two processes (``pytest -n 2``, README) and many tests start process pools of their own; with
OpenBLAS's default of a thread per core each small solve would compete with every other process (measured on two
cores: 2000 small solves 17x slower). The parallelism is the processes'; the environment is inherited by the
pools' workers too."""

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
