"""What kinplan's numba-compiled loops share: the decorator and small matrix helpers.

The compiled loops (:mod:`cartesian.lean_kernel`, :mod:`kinplan.ik.panda_kernel`) import this
module on first use, never the package: numba loads only when a compiled loop runs. Without
numba, :data:`numba` is None, :func:`jit` returns functions as they are, and the callers fall
back to their pure-Python code. Matrix products are written as loops: numba's ``@`` would need
SciPy's BLAS.
"""

from __future__ import annotations

import logging

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the callers fall back
    numba = None  # type: ignore[assignment]

logger = logging.getLogger(__name__)

COMPILE_NOTE = (
    "compiling kinplan's numba loops on first use (some seconds, once: cached on disk for the "
    "next runs; KINPLAN_JIT=0 runs the pure-Python loops instead)"
)
"""Logged (INFO, ``kinplan.compiled``) when numba starts compiling for the first time in a
process (a load from numba's disk cache compiles nothing and logs nothing); the ``kinplan``
command prints it as a one-line note."""


if numba is not None:
    from numba.core import event as _numba_event

    class _FirstCompile(_numba_event.Listener):
        """Logs :data:`COMPILE_NOTE` at the first compilation of the process."""

        noted = False

        def on_start(self, event: object) -> None:
            if not _FirstCompile.noted:
                _FirstCompile.noted = True
                logger.info(COMPILE_NOTE)

        def on_end(self, event: object) -> None:
            pass

    _numba_event.register("numba:compile", _FirstCompile())


def jit(function):
    """``function`` compiled by numba on first call and cached on disk, or as it is without
    numba. ``error_model="numpy"``: a division by zero gives inf or NaN (for the callers'
    checks), as numpy's, instead of raising ZeroDivisionError."""
    return function if numba is None else numba.njit(cache=True, error_model="numpy")(function)


@jit
def rotation_about(axis, c, s, out):
    """The rotation about the unit ``axis`` (3,) by the angle of cosine ``c`` and sine ``s``
    (Rodrigues), written into ``out`` (3, 3)."""
    x, y, z = axis[0], axis[1], axis[2]
    t = 1.0 - c
    out[0, 0] = c + x * x * t
    out[0, 1] = x * y * t - z * s
    out[0, 2] = x * z * t + y * s
    out[1, 0] = y * x * t + z * s
    out[1, 1] = c + y * y * t
    out[1, 2] = y * z * t - x * s
    out[2, 0] = z * x * t - y * s
    out[2, 1] = z * y * t + x * s
    out[2, 2] = c + z * z * t


@jit
def product_into(a, b, out):
    """``out`` = a b for small matrices (``out`` must not share memory with a or b)."""
    for i in range(a.shape[0]):
        for j in range(b.shape[1]):
            total = 0.0
            for m in range(a.shape[1]):
                total += a[i, m] * b[m, j]
            out[i, j] = total


@jit
def product(a, b):
    """a b for small matrices, as a new array."""
    out = np.empty((a.shape[0], b.shape[1]))
    product_into(a, b, out)
    return out
