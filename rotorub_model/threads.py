"""How many BLAS threads a dense problem gets.

The library's dense problems are mostly small (the reference's 38 dofs, an imported fan of 10 blades 158): below
about a thousand unknowns LAPACK's eigen-solves and solves gain nothing from a second thread on a quiet machine
(eigvals + solve, 2 cores: 1.09x at 160, 0.99x at 320 and 640, 0.81x only at 1200 unknowns), while OpenBLAS's
thread per core, spinning against other work on a loaded machine, made the same analyses several times slower
(continuation of an 18-blade configuration at load 5.5: 2 min 57 s against 44 s on one thread; the transient point
search 44.6 s against 5.5 s). Analyses of many small problems therefore run on one thread below BLAS_THREADS_FROM
unknowns and on the library's default above it.
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits

BLAS_THREADS_FROM = 1500  # unknowns of a dense problem from which the BLAS's threads are used


def blas_threads(unknowns: int) -> threadpool_limits:
    """A context in which the BLAS uses one thread for a problem of ``unknowns`` below :data:`BLAS_THREADS_FROM`,
    and its default otherwise (whatever limit the caller set stays: ``limits=None`` changes nothing)."""
    return threadpool_limits(limits=1 if unknowns < BLAS_THREADS_FROM else None)
