"""How many threads a batch of IK targets runs on, and running it on them.

The batch solvers' work is compiled (numba, ``nogil``: the GIL is released while a kernel runs)
or in numpy's large-array operations, and every target is solved independently of the others
(:mod:`kinplan.ik.batch` already solves them in chunks): so a batch split into contiguous
parts, one per thread, gives the same answers on several cores at once — the same successes
and branches, q equal to the last bits of rounding (numpy's BLAS rounds a column of a product
by where it lies in its block, as the chunks of one thread do already).

:func:`thread_count` decides: ``threads`` given by the caller wins; otherwise the environment
variable ``KINPLAN_THREADS`` (a positive integer) or the cores this process may run on, but one
thread for batches below :data:`THREADED_FROM` targets (handing parts to threads costs tenths
of a millisecond: more than they save on a small batch) and one thread when called from a
thread other than the main one — Dask's workers, a user's thread pool — which already keeps
the cores busy, or without the compiled kernels (``KINPLAN_JIT=0`` or no numba: the
pure-Python loops hold the GIL). :func:`split_run` runs the parts: the first in the calling
thread, the others on a pool of threads kept between calls (started again in a forked child).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, wait

import numpy as np

from kinplan.errors import InputError

#: Targets from which an automatic choice uses more than one thread.
THREADED_FROM = 8192
#: Targets a solver's first threaded batch solves in the calling thread before the others start
#: (lazy per-solver caches and numba's compiled code are then in place when the threads arrive).
WARM_UP = 64


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS tells it)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def thread_count(count: int, threads: int | None = None) -> int:
    """The threads a batch of ``count`` targets runs on (see the module's text).

    Args:
        count: Targets in the batch.
        threads: The caller's choice (≥ 1), or None for the automatic one.

    Raises:
        InputError: ``threads`` or ``KINPLAN_THREADS`` not a positive integer.
    """
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
            raise InputError(f"threads must be a positive integer or None, got {threads!r}")
        return int(min(threads, max(1, count)))
    if count < THREADED_FROM or threading.current_thread() is not threading.main_thread():
        return 1
    if os.environ.get("KINPLAN_JIT", "1") == "0" or not _numba_installed():
        return 1  # the pure-Python loops hold the GIL: threads would take turns
    setting = os.environ.get("KINPLAN_THREADS", "").strip()
    if setting:
        if not setting.isdigit() or int(setting) < 1:
            raise InputError(
                f"KINPLAN_THREADS must be a positive integer, got {setting!r}; unset it for "
                "one thread per core"
            )
        return int(setting)
    return available_cores()


def _numba_installed() -> bool:
    from kinplan.compiled import numba  # the batch solvers load numba anyway

    return numba is not None


def split_run(
    solve: Callable[[slice], tuple[np.ndarray, ...]],
    count: int,
    threads: int,
    warm_up: bool = True,
) -> tuple[np.ndarray, ...]:
    """``solve(slice(0, count))`` computed on ``threads`` threads: with ``warm_up`` the first
    :data:`WARM_UP` targets alone in the calling thread (a solver's first batch: its lazy
    caches and numba's compiled code are then in place), then the rest in ``threads``
    contiguous parts at once, the first in the calling thread and the others on kinplan's
    pool of ``threads − 1`` threads (kept between calls: starting threads costs about as much
    as a thousand UR5 targets). The parts' outputs (arrays whose first axis runs over the
    targets) are joined in order."""
    if threads <= 1 or count <= WARM_UP + threads:
        return solve(slice(0, count))
    pieces = [solve(slice(0, WARM_UP))] if warm_up else []
    edges = np.linspace(WARM_UP if warm_up else 0, count, threads + 1).round().astype(int)
    parts = [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
    futures = [_pool(threads - 1).submit(solve, part) for part in parts[1:]]
    try:
        pieces.append(solve(parts[0]))
    finally:
        wait(futures)  # the other parts end before this returns or raises
    pieces += [future.result() for future in futures]
    return tuple(np.concatenate(arrays) for arrays in zip(*pieces))


_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """kinplan's pool of ``workers`` threads, started on first use and kept."""
    with _POOLS_LOCK:
        pool = _POOLS.get(workers)
        if pool is None:
            pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="kinplan-ik")
            _POOLS[workers] = pool
        return pool


def _forget_pools() -> None:
    """In a forked child the pools' threads are gone: start new ones on next use."""
    global _POOLS_LOCK
    _POOLS.clear()
    _POOLS_LOCK = threading.Lock()


if hasattr(os, "register_at_fork"):  # pragma: no branch - POSIX
    os.register_at_fork(after_in_child=_forget_pools)
