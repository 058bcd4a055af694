"""What kinplan's numba-compiled loops share: the decorator and small matrix helpers.

The compiled loops (:mod:`cartesian.lean_kernel`, :mod:`kinplan.ik.panda_kernel`) import this
module on first use, never the package: numba loads only when a compiled loop runs. Without
numba, :data:`numba` is None, :func:`jit` returns functions as they are, and the callers fall
back to their pure-Python code. Matrix products are written as loops: numba's ``@`` would need
SciPy's BLAS.
"""

from __future__ import annotations

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - numba is a dependency; the callers fall back
    numba = None  # type: ignore[assignment]


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
