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
    checks), as numpy's, instead of raising ZeroDivisionError. ``nogil``: a compiled call
    releases Python's GIL, so the batch solvers' threads (:mod:`kinplan.ik.batch_threads`) run
    at once."""
    if numba is None:
        return function
    return numba.njit(cache=True, nogil=True, error_model="numpy")(function)


def inline(function):
    """:func:`jit`, inlined into its compiled callers. A compiled call increments and
    decrements the reference count of each array it is passed, and indexing a row out of an
    array (``a[i]``) makes a new array whose count is kept too, atomically (~10 ns a pair,
    and a cache line shared between threads): often more than a small helper's arithmetic
    (13 % of the UR kernel's time before its helpers were inlined and its rows indexed
    instead of sliced). Inlined, numba prunes the counts of a straight run of code."""
    if numba is None:
        return function
    return numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")(function)


@inline
def horner(c, degree, t):
    """P(t) and P'(t) of the polynomial ``P = Σ c[i] tⁱ`` (i ≤ ``degree``), by Horner's rule."""
    p = c[degree]
    dp = 0.0
    for i in range(degree - 1, -1, -1):
        dp = dp * t + p
        p = p * t + c[i]
    return p, dp


@jit
def turn_into(axis, v, c, s, out):
    """``out`` (3,) = R(axis, θ) v (Rodrigues) for the unit ``axis``, cos θ = ``c``,
    sin θ = ``s``; ``out`` may be ``v``."""
    x, y, z = v[0], v[1], v[2]
    ax, ay, az = axis[0], axis[1], axis[2]
    k = (ax * x + ay * y + az * z) * (1.0 - c)
    out[0] = x * c + (ay * z - az * y) * s + ax * k
    out[1] = y * c + (az * x - ax * z) * s + ay * k
    out[2] = z * c + (ax * y - ay * x) * s + az * k


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


@jit
def screw_kinematics(q, directions, points, tool, pose, jacobian, trig=None):
    """Tool pose (4, 4) and LOCAL_WORLD_ALIGNED Jacobian (6, nq) at ``q`` [rad] by the product
    of exponentials T(q) = exp(S1 q1) ⋯ exp(Sn qn) M of the joint screws at q = 0 (unit axes
    ``directions`` through ``points`` [m], tool pose ``tool`` at q = 0), written into ``pose``
    and ``jacobian``. Joint i's column is (ωᵢ × (p_tool − xᵢ), ωᵢ).

    The running rotation and translation are kept in numbers, not arrays (no allocation, no
    reference counts: this runs once an iteration of the numerical IK): per joint the
    Rodrigues rotation, then the running rotation times it as :func:`product_into` sums.
    ``trig`` (nq, 2), if given, holds cos qᵢ and sin qᵢ (a Newton polish updates them by its
    small steps instead of calling them again; compiled apart from the call without it)."""
    nq = q.shape[0]
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    t0 = t1 = t2 = 0.0
    for i in range(nq):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        x, y, z = directions[i, 0], directions[i, 1], directions[i, 2]
        jacobian[3, i] = r00 * x + r01 * y + r02 * z
        jacobian[4, i] = r10 * x + r11 * y + r12 * z
        jacobian[5, i] = r20 * x + r21 * y + r22 * z
        # joint i's origin x_i, kept in the linear rows until the tool position is known
        jacobian[0, i] = r00 * px + r01 * py + r02 * pz + t0
        jacobian[1, i] = r10 * px + r11 * py + r12 * pz + t1
        jacobian[2, i] = r20 * px + r21 * py + r22 * pz + t2
        if trig is None:
            c, s = np.cos(q[i]), np.sin(q[i])
        else:
            c, s = trig[i, 0], trig[i, 1]
        t = 1.0 - c
        s00, s01, s02 = c + x * x * t, x * y * t - z * s, x * z * t + y * s
        s10, s11, s12 = y * x * t + z * s, c + y * y * t, y * z * t - x * s
        s20, s21, s22 = z * x * t - y * s, z * y * t + x * s, c + z * z * t
        sx = px - (s00 * px + s01 * py + s02 * pz)
        sy = py - (s10 * px + s11 * py + s12 * pz)
        sz = pz - (s20 * px + s21 * py + s22 * pz)
        t0 += r00 * sx + r01 * sy + r02 * sz
        t1 += r10 * sx + r11 * sy + r12 * sz
        t2 += r20 * sx + r21 * sy + r22 * sz
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = (
            ((0.0 + r00 * s00) + r01 * s10) + r02 * s20,
            ((0.0 + r00 * s01) + r01 * s11) + r02 * s21,
            ((0.0 + r00 * s02) + r01 * s12) + r02 * s22,
            ((0.0 + r10 * s00) + r11 * s10) + r12 * s20,
            ((0.0 + r10 * s01) + r11 * s11) + r12 * s21,
            ((0.0 + r10 * s02) + r11 * s12) + r12 * s22,
            ((0.0 + r20 * s00) + r21 * s10) + r22 * s20,
            ((0.0 + r20 * s01) + r21 * s11) + r22 * s21,
            ((0.0 + r20 * s02) + r21 * s12) + r22 * s22,
        )
    for j in range(3):
        m0, m1, m2 = tool[0, j], tool[1, j], tool[2, j]
        pose[0, j] = ((0.0 + r00 * m0) + r01 * m1) + r02 * m2
        pose[1, j] = ((0.0 + r10 * m0) + r11 * m1) + r12 * m2
        pose[2, j] = ((0.0 + r20 * m0) + r21 * m1) + r22 * m2
    pose[0, 3] = r00 * tool[0, 3] + r01 * tool[1, 3] + r02 * tool[2, 3] + t0
    pose[1, 3] = r10 * tool[0, 3] + r11 * tool[1, 3] + r12 * tool[2, 3] + t1
    pose[2, 3] = r20 * tool[0, 3] + r21 * tool[1, 3] + r22 * tool[2, 3] + t2
    pose[3, 0] = pose[3, 1] = pose[3, 2] = 0.0
    pose[3, 3] = 1.0
    for i in range(nq):
        wx, wy, wz = jacobian[3, i], jacobian[4, i], jacobian[5, i]
        rx = pose[0, 3] - jacobian[0, i]
        ry = pose[1, 3] - jacobian[1, i]
        rz = pose[2, 3] - jacobian[2, i]
        jacobian[0, i] = wy * rz - wz * ry
        jacobian[1, i] = wz * rx - wx * rz
        jacobian[2, i] = wx * ry - wy * rx
