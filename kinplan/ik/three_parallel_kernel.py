"""The three-parallel-axes closed form of one pose, compiled (numba): every solution of a 6R arm
with axes 2 ∥ 3 ∥ 4 (axes 1, 5, 6 anywhere), and the one nearest a reference, for
:class:`~kinplan.ik.three_parallel.ThreeParallelIK`.

World frame at q = 0: axis i has unit direction h_i through p_i, ``e_i`` its screw motion
(rotation ``R_i = R(h_i, θ_i)``), ``T(q) = e1 ⋯ e6 M``. With the target ``(R_T, p_T)``,
``R = R_T R_Mᵀ`` and ``p6`` on axis 6 (:mod:`~kinplan.ik.three_parallel_geometry` takes the
point nearest axis 5), ``e1 ⋯ e5 p6 = w := R(p6 − p_M) + p_T``. Following IK-Geo (Elias & Wen
2022):

1. **θ1, θ5 by subproblem 6.** Rotations about axes ∥ h2 keep the h2 component of points and
   fix h2, ``h2ᵀ R2 R3 R4 = h2ᵀ``; hence

   * (A) ``h2·(R1ᵀ(w − p1) + p1) = h2·(R5(p6 − p5) + p5)`` [m],
   * (C) ``(R1 h2)·(R h6) = h2·(R5 h6)``,

   both linear in ``x = (cos θ1, sin θ1, cos θ5, sin θ5)``: two equations ``A x = b`` (rows
   scaled to unit length) and two unit circles. With ``x = x0 + N y`` (``x0`` the least-norm
   solution, N an orthonormal basis of the null space of A), the sum of the circles' equations
   is the circle ``|y|² = 2 − |x0|²`` (none when negative: the pose is out of reach), their
   difference ``xᵀ diag(1, 1, −1, −1) x = 0`` a trigonometric quadratic in the angle of y, a
   quartic in ``t = tan((φ − φ0)/2)`` with the origin φ0 turned away from every root (the
   largest of eight samples at t = ∞); its real roots
   (:func:`~kinplan.ik.three_parallel_quartic.real_roots`) give up to four pairs (θ1, θ5),
   each polished by Newton steps on (A), (C). Where two roots lie a rounding apart around a
   critical point (a double root: two branches meet at a singular pose), the critical point
   is tried first and the two roots only if it gives no solution.
2. **θ6 by subproblem 1**: ``R(h6, −θ6) R5ᵀ h2 = Rᵀ R1 h2``. Where ``R5ᵀ h2`` lies on axis 6
   (axes 2, 3, 4, 6 parallel: a continuum of θ6) θ6 is free and the pose is flagged singular:
   θ6 takes the reference's value, or the nearest value that keeps the elbow within reach.
3. **θ2, θ3 by subproblem 3, then 1**, on the point ``e2 e3 p4 = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹ p4``,
   in the plane normal to h2 (two elbow branches); **θ4** from the rest of ``R2 R3 R4 =
   R(h2, θ2 + σ3 θ3 + σ4 θ4) = R1ᵀ R R6ᵀ R5ᵀ`` (σ3, σ4 = ±1: axes 3, 4 along ±h2).

Where A loses rank (a continuum of θ1: (A) vanishes when the target's ``w`` is on axis 1 and
the arm's p6 on axis 5, as the Z1's shoulder singularity), θ1 takes the reference's value, or
the nearest value for which the other equation has a solution, θ5 comes from subproblem 4, and
the pose is flagged singular (when that θ1 leaves the elbow out of reach, the closed form gives
no solution there; :meth:`kinplan.Robot.ik` then falls back to the numerical solver). Each
solution is checked by forward kinematics (product of exponentials) and kept only within
:data:`VERIFY_TOL`: up to :data:`SLOTS` solutions, in the order of the quartic's roots, then
elbow. The choice of the nearest solution is that of :meth:`kinplan.ik.ClosedFormIK.nearest`
(:func:`~kinplan.ik.spherical_wrist_kernel.nearest_of`).

Modules: :mod:`~kinplan.ik.three_parallel_geometry` →
:mod:`~kinplan.ik.three_parallel_quartic` → ``three_parallel_kernel`` →
:mod:`~kinplan.ik.three_parallel`. Without numba, or with ``KINPLAN_JIT=0`` at import, the same
functions run as plain Python (about a thousand times slower).
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.compiled import numba
from kinplan.ik.screws import CLAMP, FREE_TOL, TAU
from kinplan.ik.spherical_wrist_kernel import nearest_of, pose_finite
from kinplan.ik.three_parallel_quartic import MOST, real_roots
from kinplan.ik.wrist_offset_branches import ENABLED, angle_to, jit, turn
from kinplan.ik.wrist_offset_kernel import VERIFY_TOL

#: Solution slots per pose (NaN rows past the solutions found): 4 pairs (θ1, θ5) × 2 elbows.
SLOTS = 8
#: What :func:`nearest` returns for an input with a NaN or inf (the caller reports it).
NOT_FINITE = -2
#: Below this sine² of the angle between the rows of A (scaled), A has lost rank [1].
RANK_TOL = 1e-20
#: Below this largest |difference of the circles' equations| over eight samples, every y on
#: the circle solves both: a continuum (handled as lost rank).
FLAT_TOL = 1e-13
#: Below this radius of the circle of y, its only point y = 0 is the candidate.
TINY_RADIUS = 1e-12
#: Newton steps at most that polish a pair (θ1, θ5) on (A), (C) (rows of unit length) ...
POLISH_STEPS = 4
#: ... until their residual is below this (a root of the quartic is to about 1e-13 already).
POLISHED = 1e-15

__all__ = ["SLOTS", "VERIFY_TOL", "available", "branches", "nearest", "nearest_many", "raw_many"]


def available() -> bool:
    """Whether the kernel runs compiled (numba installed and ``KINPLAN_JIT`` not 0)."""
    return ENABLED and numba is not None


# ---------------------------------------------------------------------------- θ1, θ5
@jit
def _equations(k, rotation, position, a, b):
    """(A), (C) of the target (``rotation`` R_T, ``position`` p_T [m]) as ``a x = b`` with
    ``x = (cos θ1, sin θ1, cos θ5, sin θ5)``: rows of ``a`` (2, 4) and ``b`` (2,) written,
    each row scaled to unit length (a row of zeros stays). Returns whether some row is
    zero."""
    wx = rotation[0, 0] * k[24, 0] + rotation[0, 1] * k[24, 1] + rotation[0, 2] * k[24, 2]
    wy = rotation[1, 0] * k[24, 0] + rotation[1, 1] * k[24, 1] + rotation[1, 2] * k[24, 2]
    wz = rotation[2, 0] * k[24, 0] + rotation[2, 1] * k[24, 1] + rotation[2, 2] * k[24, 2]
    vx, vy, vz = wx + position[0] - k[6, 0], wy + position[1] - k[6, 1], wz + position[2] - k[6, 2]
    ux = rotation[0, 0] * k[25, 0] + rotation[0, 1] * k[25, 1] + rotation[0, 2] * k[25, 2]
    uy = rotation[1, 0] * k[25, 0] + rotation[1, 1] * k[25, 1] + rotation[1, 2] * k[25, 2]
    uz = rotation[2, 0] * k[25, 0] + rotation[2, 1] * k[25, 1] + rotation[2, 2] * k[25, 2]
    hh = k[23, 0]
    a[0, 0] = k[21, 0] * vx + k[21, 1] * vy + k[21, 2] * vz
    a[0, 1] = -(k[22, 0] * vx + k[22, 1] * vy + k[22, 2] * vz)
    a[0, 2], a[0, 3] = -k[19, 0], -k[19, 1]
    b[0] = k[19, 2] - hh * (k[0, 0] * vx + k[0, 1] * vy + k[0, 2] * vz) - k[23, 1]
    a[1, 0] = k[21, 0] * ux + k[21, 1] * uy + k[21, 2] * uz
    a[1, 1] = -(k[22, 0] * ux + k[22, 1] * uy + k[22, 2] * uz)
    a[1, 2], a[1, 3] = -k[20, 0], -k[20, 1]
    b[1] = k[20, 2] - hh * (k[0, 0] * ux + k[0, 1] * uy + k[0, 2] * uz)
    zero = False
    for r in range(2):
        size = math.sqrt(a[r, 0] ** 2 + a[r, 1] ** 2 + a[r, 2] ** 2 + a[r, 3] ** 2)
        if size < FREE_TOL:
            zero = True
            continue
        for j in range(4):
            a[r, j] /= size
        b[r] /= size
    return zero


@jit
def _polish(a, b, pairs, i):
    """Newton steps on ``a x = b`` in (θ1, θ5) from row i of ``pairs`` = (cos θ1, sin θ1,
    cos θ5, sin θ5), in place, until the residual is below :data:`POLISHED` (a step is kept
    only when it lowers the residual)."""
    c1, s1, c5, s5 = pairs[i, 0], pairs[i, 1], pairs[i, 2], pairs[i, 3]
    f0 = a[0, 0] * c1 + a[0, 1] * s1 + a[0, 2] * c5 + a[0, 3] * s5 - b[0]
    f1 = a[1, 0] * c1 + a[1, 1] * s1 + a[1, 2] * c5 + a[1, 3] * s5 - b[1]
    error = f0 * f0 + f1 * f1
    for _ in range(POLISH_STEPS):
        if error <= POLISHED * POLISHED:
            break
        j00 = a[0, 1] * c1 - a[0, 0] * s1
        j01 = a[0, 3] * c5 - a[0, 2] * s5
        j10 = a[1, 1] * c1 - a[1, 0] * s1
        j11 = a[1, 3] * c5 - a[1, 2] * s5
        det = j00 * j11 - j01 * j10
        if det == 0.0:
            break
        d1 = -(j11 * f0 - j01 * f1) / det
        d5 = -(j00 * f1 - j10 * f0) / det
        n1, n5 = math.sqrt(1.0 + d1 * d1), math.sqrt(1.0 + d5 * d5)  # turn by atan(d)
        nc1, ns1 = (c1 - s1 * d1) / n1, (s1 + c1 * d1) / n1
        nc5, ns5 = (c5 - s5 * d5) / n5, (s5 + c5 * d5) / n5
        g0 = a[0, 0] * nc1 + a[0, 1] * ns1 + a[0, 2] * nc5 + a[0, 3] * ns5 - b[0]
        g1 = a[1, 0] * nc1 + a[1, 1] * ns1 + a[1, 2] * nc5 + a[1, 3] * ns5 - b[1]
        if g0 * g0 + g1 * g1 >= error:
            break
        c1, s1, c5, s5, f0, f1, error = nc1, ns1, nc5, ns5, g0, g1, g0 * g0 + g1 * g1
    pairs[i, 0], pairs[i, 1], pairs[i, 2], pairs[i, 3] = c1, s1, c5, s5


@jit
def _store(x0, x1, x2, x3, pairs, n):
    """Row n of ``pairs`` from a point x of the two lines' solutions (its two halves scaled
    onto the unit circles); returns the count of rows."""
    r1, r5 = math.sqrt(x0 * x0 + x1 * x1), math.sqrt(x2 * x2 + x3 * x3)
    if r1 == 0.0 or r5 == 0.0:
        return n
    pairs[n, 0], pairs[n, 1], pairs[n, 2], pairs[n, 3] = x0 / r1, x1 / r1, x2 / r5, x3 / r5
    return n + 1


@jit
def _nearest_within(fill, beta, lo, hi):
    """The angle θ nearest ``fill`` [rad] (mod 2π) with ``lo ≤ cos(θ − β) ≤ hi``, or NaN when
    none (lo > 1 or hi < −1, beyond rounding)."""
    if lo > 1.0 + CLAMP or hi < -1.0 - CLAMP:
        return np.nan
    delta = fill - beta
    delta -= TAU * np.round(delta / TAU)
    nearest = min(max(abs(delta), math.acos(min(max(hi, -1.0), 1.0))),
                  math.acos(max(min(lo, 1.0), -1.0)))  # fmt: skip
    return beta + math.copysign(nearest, delta)


@jit
def _numbered(n, groups):
    """``n``, with groups 0 … n − 1 (each pair its own) written into ``groups``."""
    for i in range(n):
        groups[i] = i
    return n


@jit
def _lost_rank(a, b, fill, pairs):
    """The pairs where A has lost rank (a continuum of θ1): θ1 nearest ``fill[0]`` for which
    the row that involves θ5 most has a solution, θ5 from that row (subproblem 4; ``fill[4]``
    when neither row involves it). Returns the count."""
    r = 0 if a[0, 2] ** 2 + a[0, 3] ** 2 >= a[1, 2] ** 2 + a[1, 3] ** 2 else 1
    size = math.hypot(a[r, 2], a[r, 3])
    if size < FREE_TOL:
        return _store(math.cos(fill[0]), math.sin(fill[0]), math.cos(fill[4]),
                      math.sin(fill[4]), pairs, 0)  # fmt: skip
    # a0 cos θ1 + a1 sin θ1 = ρ1 cos(θ1 − β1) must be within ``size`` of b
    reach = math.hypot(a[r, 0], a[r, 1])
    theta1 = fill[0]
    if reach >= FREE_TOL:
        beta = math.atan2(a[r, 1], a[r, 0])
        theta1 = _nearest_within(fill[0], beta, (b[r] - size) / reach, (b[r] + size) / reach)
        if theta1 != theta1:
            return 0
    c1, s1 = math.cos(theta1), math.sin(theta1)
    ratio = (b[r] - a[r, 0] * c1 - a[r, 1] * s1) / size
    if abs(ratio) > 1.0 + CLAMP:
        return 0
    ratio = min(max(ratio, -1.0), 1.0)
    cb, sb = a[r, 2] / size, a[r, 3] / size
    n = 0
    for sign in (1.0, -1.0):
        half = sign * math.sqrt(1.0 - ratio * ratio)
        n = _store(c1, s1, cb * ratio - sb * half, sb * ratio + cb * half, pairs, n)
    return n


@jit
def pairs_of(k, rotation, position, fill, pairs, groups):
    """Every (θ1, θ5) of one pose that solves (A) and (C), as rows (cos θ1, sin θ1, cos θ5,
    sin θ5) of ``pairs`` (MOST, 4), with the quartic's group of each in ``groups`` (MOST,):
    a group of three is a double root (first) and the two roots rounding may have split it
    into (see :func:`~kinplan.ik.three_parallel_quartic.real_roots`).

    Args:
        k: The packed geometry (:meth:`ThreeParallelGeometry.constants
            <kinplan.ik.three_parallel_geometry.ThreeParallelGeometry.constants>`), (26, 3).
        rotation: Tool rotation ``R_T`` in the world frame (3, 3).
        position: Tool position ``p_T`` in the world frame [m] (3,).
        fill: Values [rad] (6,) of θ1 (and θ5) where A has lost rank.
        pairs, groups: Written.

    Returns:
        (count, singular): singular where A lost rank (θ1 from ``fill``).
    """
    a = np.empty((2, 4))
    b = np.empty(2)
    zero = _equations(k, rotation, position, a, b)
    dot = a[0, 0] * a[1, 0] + a[0, 1] * a[1, 1] + a[0, 2] * a[1, 2] + a[0, 3] * a[1, 3]
    det = 1.0 - dot * dot
    if zero or det < RANK_TOL:
        return _numbered(_lost_rank(a, b, fill, pairs), groups), True
    # x0 = Aᵀ (A Aᵀ)⁻¹ b, and an orthonormal basis u, v of the rows
    l0, l1 = (b[0] - dot * b[1]) / det, (b[1] - dot * b[0]) / det
    x = np.empty(4)
    u = np.empty(4)
    v = np.empty(4)
    root = math.sqrt(det)
    for j in range(4):
        x[j] = l0 * a[0, j] + l1 * a[1, j]
        u[j] = a[0, j]
        v[j] = (a[1, j] - dot * a[0, j]) / root
    # the null space: the two columns of I − u uᵀ − v vᵀ that stand out most, orthonormalised
    best, best_size = 0, -1.0
    for j in range(4):
        size = 1.0 - u[j] * u[j] - v[j] * v[j]
        if size > best_size:
            best, best_size = j, size
    n1 = np.empty(4)
    n2 = np.empty(4)
    for j in range(4):
        n1[j] = (1.0 if j == best else 0.0) - u[best] * u[j] - v[best] * v[j]
    scale = math.sqrt(n1[0] ** 2 + n1[1] ** 2 + n1[2] ** 2 + n1[3] ** 2)
    for j in range(4):
        n1[j] /= scale
    second, second_size = 0, -1.0
    for j in range(4):
        if j != best:
            size = 1.0 - u[j] * u[j] - v[j] * v[j] - n1[j] * n1[j]
            if size > second_size:
                second, second_size = j, size
    for j in range(4):
        n2[j] = (1.0 if j == second else 0.0) - u[second] * u[j] - v[second] * v[j]
        n2[j] -= n1[second] * n1[j]
    scale = math.sqrt(n2[0] ** 2 + n2[1] ** 2 + n2[2] ** 2 + n2[3] ** 2)
    for j in range(4):
        n2[j] /= scale
    # the circle |y|² = 2 − |x0|²
    rest = 2.0 - (x[0] ** 2 + x[1] ** 2 + x[2] ** 2 + x[3] ** 2)
    if rest < -2.0 * CLAMP:
        return 0, False
    radius = math.sqrt(max(rest, 0.0))
    if radius < TINY_RADIUS:
        n = _store(x[0], x[1], x[2], x[3], pairs, 0)
        for i in range(n):
            _polish(a, b, pairs, i)
        return _numbered(n, groups), False
    # the difference of the circles: a cos 2φ + b sin 2φ + c cos φ + d sin φ + e = 0
    m11 = n1[0] ** 2 + n1[1] ** 2 - n1[2] ** 2 - n1[3] ** 2
    m22 = n2[0] ** 2 + n2[1] ** 2 - n2[2] ** 2 - n2[3] ** 2
    m12 = n1[0] * n2[0] + n1[1] * n2[1] - n1[2] * n2[2] - n1[3] * n2[3]
    g1 = n1[0] * x[0] + n1[1] * x[1] - n1[2] * x[2] - n1[3] * x[3]
    g2 = n2[0] * x[0] + n2[1] * x[1] - n2[2] * x[2] - n2[3] * x[3]
    e0 = x[0] ** 2 + x[1] ** 2 - x[2] ** 2 - x[3] ** 2
    r2 = radius * radius
    qa, qb = 0.5 * r2 * (m11 - m22), r2 * m12
    qc, qd = 2.0 * radius * g1, 2.0 * radius * g2
    qe = e0 + 0.5 * r2 * (m11 + m22)
    # t = ∞ where |q| is largest of eight samples φ_j = jπ/4
    top, top_j = -1.0, 0
    half = math.sqrt(0.5)
    for j in range(8):
        cj, sj = _EIGHTH[j, 0], _EIGHTH[j, 1]
        if j % 2 == 1:
            cj, sj = cj * half, sj * half
        c2j, s2j = cj * cj - sj * sj, 2.0 * cj * sj
        value = abs(qa * c2j + qb * s2j + qc * cj + qd * sj + qe)
        if value > top:
            top, top_j = value, j
    if top < FLAT_TOL:
        return _numbered(_lost_rank(a, b, fill, pairs), groups), True
    cj, sj = _EIGHTH[top_j, 0], _EIGHTH[top_j, 1]
    if top_j % 2 == 1:
        cj, sj = cj * half, sj * half
    c0, s0 = -cj, -sj  # φ0 = φ_j − π
    c20, s20 = cj * cj - sj * sj, 2.0 * cj * sj
    pa, pb = qa * c20 + qb * s20, qb * c20 - qa * s20
    pc, pd = qc * c0 + qd * s0, qd * c0 - qc * s0
    coefficients = np.empty(5)
    coefficients[0] = pa + pc + qe
    coefficients[1] = 4.0 * pb + 2.0 * pd
    coefficients[2] = 2.0 * qe - 6.0 * pa
    coefficients[3] = 2.0 * pd - 4.0 * pb
    coefficients[4] = pa - pc + qe
    roots = np.empty(MOST)
    numbers = np.empty(MOST, dtype=np.int64)
    count = real_roots(coefficients, 2.0, roots, numbers)  # (terms of |x|² = 2)
    n = 0
    for i in range(count):
        t = roots[i]
        w = 1.0 + t * t
        cp, sp = (1.0 - t * t) / w, 2.0 * t / w
        y1 = radius * (cp * c0 - sp * s0)
        y2 = radius * (sp * c0 + cp * s0)
        stored = _store(
            x[0] + y1 * n1[0] + y2 * n2[0],
            x[1] + y1 * n1[1] + y2 * n2[1],
            x[2] + y1 * n1[2] + y2 * n2[2],
            x[3] + y1 * n1[3] + y2 * n2[3],
            pairs,
            n,
        )
        if stored > n:
            groups[n] = numbers[i]
        n = stored
    for i in range(n):
        _polish(a, b, pairs, i)
    return n, False


#: (cos, sin) of jπ/4 up to the factor √½ of the odd j (exact in floats).
_EIGHTH = np.array(
    [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1]], dtype=np.float64
)


# ---------------------------------------------------------------------------- the rest
@jit
def _in_plane(k, big_r, position, c1, s1, x, y, z, point):
    """(e, f) coordinates of ``R1ᵀ R (x, y, z)``, where (x, y, z) is seen from the tool's
    origin at q = 0 (``point``: the point ``e1⁻¹ (R (x, y, z) + p_T)`` relative to axis 2,
    else the vector alone)."""
    gx = big_r[0, 0] * x + big_r[0, 1] * y + big_r[0, 2] * z
    gy = big_r[1, 0] * x + big_r[1, 1] * y + big_r[1, 2] * z
    gz = big_r[2, 0] * x + big_r[2, 1] * y + big_r[2, 2] * z
    if point:
        gx, gy, gz = (
            gx + position[0] - k[6, 0],
            gy + position[1] - k[6, 1],
            gz + position[2] - k[6, 2],
        )
    gx, gy, gz = turn(k, 0, gx, gy, gz, c1, -s1)
    if point:
        gx, gy, gz = gx + k[6, 0] - k[7, 0], gy + k[6, 1] - k[7, 1], gz + k[6, 2] - k[7, 2]
    return (
        gx * k[12, 0] + gy * k[12, 1] + gz * k[12, 2],
        gx * k[13, 0] + gy * k[13, 1] + gz * k[13, 2],
    )


@jit
def _free_turn(ce, cf, ue, uf, ve, vf, l1, l2, fill):
    """θ6 where it is free (axis 6 ∥ h2): the value nearest ``fill`` [rad] that keeps the point
    ``C + cos θ6 U + sin θ6 V`` (plane coordinates [m], |U| = |V|, U ⊥ V) within the elbow's
    reach ``|l1 − l2| ≤ |q| ≤ l1 + l2``. Returns (reachable, cos θ6, sin θ6)."""
    a = ce * ce + cf * cf + 0.5 * (ue * ue + uf * uf + ve * ve + vf * vf)
    cu, cv = ce * ue + cf * uf, ce * ve + cf * vf
    b = 2.0 * math.sqrt(cu * cu + cv * cv)  # |q|² = a + b cos(θ6 − β)
    if b < FREE_TOL * FREE_TOL:  # |q| does not change with θ6
        return True, math.cos(fill), math.sin(fill)
    theta = _nearest_within(fill, math.atan2(cv, cu), ((l1 - l2) ** 2 - a) / b,
                            ((l1 + l2) ** 2 - a) / b)  # fmt: skip
    if theta != theta:
        return False, 1.0, 0.0
    return True, math.cos(theta), math.sin(theta)


@jit
def _tail(k, tool, c5, s5, c6, s6, tail):
    """``e5 e6 M`` applied to the tool point and to the tool's x and y axes: rows of ``tail``
    (3, 3), the first half of the forward kinematics of every solution of one pair."""
    for r in range(3):
        if r == 0:
            x, y, z = tool[0, 3] - k[11, 0], tool[1, 3] - k[11, 1], tool[2, 3] - k[11, 2]
        else:
            x, y, z = tool[0, r - 1], tool[1, r - 1], tool[2, r - 1]
        x, y, z = turn(k, 5, x, y, z, c6, s6)
        if r == 0:
            x, y, z = x + k[11, 0] - k[10, 0], y + k[11, 1] - k[10, 1], z + k[11, 2] - k[10, 2]
        x, y, z = turn(k, 4, x, y, z, c5, s5)
        if r == 0:
            x, y, z = x + k[10, 0], y + k[10, 1], z + k[10, 2]
        tail[r, 0], tail[r, 1], tail[r, 2] = x, y, z


@jit
def _head(k, position, rotation, c1, s1, head):
    """``e1⁻¹`` applied to the target: its point and its three axes as rows of ``head``
    (4, 3), what ``e2 e3 e4`` must turn the tail (:func:`_tail`) into."""
    for r in range(4):
        if r == 0:
            x, y, z = position[0] - k[6, 0], position[1] - k[6, 1], position[2] - k[6, 2]
        else:
            x, y, z = rotation[0, r - 1], rotation[1, r - 1], rotation[2, r - 1]
        x, y, z = turn(k, 0, x, y, z, c1, -s1)
        if r == 0:
            x, y, z = x + k[6, 0], y + k[6, 1], z + k[6, 2]
        head[r, 0], head[r, 1], head[r, 2] = x, y, z


@jit
def _reaches(k, tail, head, c2, s2, c3, s3, c4, s4):
    """Whether the solution puts the tool at the pose within :data:`VERIFY_TOL`: ``e2 e3 e4``
    (axes and points of ``k``) turn the tail ``e5 e6 M`` (:func:`_tail`) into the head
    ``e1⁻¹ T`` (:func:`_head`), i.e. the product of exponentials ``e1 ⋯ e6 M`` equals the
    target T, position [m] and rotation (Frobenius, ~rad; both unchanged by ``e1⁻¹``)."""
    miss = 0.0
    spin = 0.0
    zx = zy = zz = 0.0
    for r in range(3):
        x, y, z = tail[r, 0], tail[r, 1], tail[r, 2]
        if r == 0:
            x, y, z = x - k[9, 0], y - k[9, 1], z - k[9, 2]
        x, y, z = turn(k, 3, x, y, z, c4, s4)
        if r == 0:
            x, y, z = x + k[9, 0] - k[8, 0], y + k[9, 1] - k[8, 1], z + k[9, 2] - k[8, 2]
        x, y, z = turn(k, 2, x, y, z, c3, s3)
        if r == 0:
            x, y, z = x + k[8, 0] - k[7, 0], y + k[8, 1] - k[7, 1], z + k[8, 2] - k[7, 2]
        x, y, z = turn(k, 1, x, y, z, c2, s2)
        if r == 0:
            x, y, z = x + k[7, 0], y + k[7, 1], z + k[7, 2]
            miss = (x - head[0, 0]) ** 2 + (y - head[0, 1]) ** 2 + (z - head[0, 2]) ** 2
            if miss > VERIFY_TOL * VERIFY_TOL:
                return False
        else:
            spin += (x - head[r, 0]) ** 2 + (y - head[r, 1]) ** 2 + (z - head[r, 2]) ** 2
            if r == 1:
                zx, zy, zz = x, y, z
            else:  # the z axis, x × y
                spin += (zy * z - zz * y - head[3, 0]) ** 2
                spin += (zz * x - zx * z - head[3, 1]) ** 2
                spin += (zx * y - zy * x - head[3, 2]) ** 2
    return spin <= 2.0 * VERIFY_TOL * VERIFY_TOL


@jit
def _complete(k, tool, big_r, rotation, position, pair, fill, raw, row, tail, head):
    """θ6, θ2, θ3, θ4 of one pair (θ1, θ5): the solutions that pass the FK check written into
    ``raw`` from ``row`` on (wrapped into [−π, π]). Returns (next row, singular)."""
    c1, s1, c5, s5 = pair[0], pair[1], pair[2], pair[3]
    singular = False
    # 2. θ6: R(h6, −θ6) R5ᵀ h2 = Rᵀ R1 h2
    ax, ay, az = turn(k, 4, k[1, 0], k[1, 1], k[1, 2], c5, -s5)
    tx, ty, tz = turn(k, 0, k[1, 0], k[1, 1], k[1, 2], c1, s1)
    bx = big_r[0, 0] * tx + big_r[1, 0] * ty + big_r[2, 0] * tz
    by = big_r[0, 1] * tx + big_r[1, 1] * ty + big_r[2, 1] * tz
    bz = big_r[0, 2] * tx + big_r[1, 2] * ty + big_r[2, 2] * tz
    c6, minus_s6, _ = angle_to(k, 5, ax, ay, az, bx, by, bz)
    s6 = -minus_s6
    # 3. the point e2 e3 p4 = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹ p4, in the plane normal to h2
    vx, vy, vz = turn(k, 4, k[9, 0] - k[10, 0], k[9, 1] - k[10, 1], k[9, 2] - k[10, 2], c5, -s5)
    vx, vy, vz = vx + k[10, 0] - k[11, 0], vy + k[10, 1] - k[11, 1], vz + k[10, 2] - k[11, 2]
    along = ax * k[5, 0] + ay * k[5, 1] + az * k[5, 2]
    if ax * ax + ay * ay + az * az - along * along < FREE_TOL * FREE_TOL:  # R5ᵀ h2 on axis 6
        # θ6 free: the point C + cos θ6 U + sin θ6 V turns about axis 6 (∥ h2 now)
        singular = True
        along = vx * k[5, 0] + vy * k[5, 1] + vz * k[5, 2]
        ca, cb = _in_plane(k, big_r, position, c1, s1, along * k[5, 0] + k[11, 0] - tool[0, 3],
                           along * k[5, 1] + k[11, 1] - tool[1, 3],
                           along * k[5, 2] + k[11, 2] - tool[2, 3], True)  # fmt: skip
        ue, uf = _in_plane(k, big_r, position, c1, s1, vx - along * k[5, 0],
                           vy - along * k[5, 1], vz - along * k[5, 2], False)  # fmt: skip
        # −h6 × v
        ve, vf = _in_plane(k, big_r, position, c1, s1, k[5, 2] * vy - k[5, 1] * vz,
                           k[5, 0] * vz - k[5, 2] * vx, k[5, 1] * vx - k[5, 0] * vy,
                           False)  # fmt: skip
        reached, c6, s6 = _free_turn(ca, cb, ue, uf, ve, vf, k[17, 0], k[17, 1], fill[5])
        if not reached:
            return row, singular
        qe, qf = ca + c6 * ue + s6 * ve, cb + c6 * uf + s6 * vf
    else:
        vx, vy, vz = turn(k, 5, vx, vy, vz, c6, -s6)
        vx, vy, vz = (
            vx + k[11, 0] - tool[0, 3],
            vy + k[11, 1] - tool[1, 3],
            vz + k[11, 2] - tool[2, 3],
        )
        qe, qf = _in_plane(k, big_r, position, c1, s1, vx, vy, vz, True)
    # subproblem 3: |r23 + R(ψ) r34|² = |q|², two elbows
    l1, l2 = k[17, 0], k[17, 1]
    d2 = qe * qe + qf * qf
    cosine = (d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if abs(cosine) > 1.0 + CLAMP:
        return row, singular
    cosine = min(max(cosine, -1.0), 1.0)
    sine = math.sqrt(1.0 - cosine * cosine)
    # the angle φ of R2 R3 R4 = R1ᵀ R R6ᵀ R5ᵀ about h2: where it turns e
    ex, ey, ez = turn(k, 4, k[12, 0], k[12, 1], k[12, 2], c5, -s5)
    ex, ey, ez = turn(k, 5, ex, ey, ez, c6, -s6)
    gx = big_r[0, 0] * ex + big_r[0, 1] * ey + big_r[0, 2] * ez
    gy = big_r[1, 0] * ex + big_r[1, 1] * ey + big_r[1, 2] * ez
    gz = big_r[2, 0] * ex + big_r[2, 1] * ey + big_r[2, 2] * ez
    gx, gy, gz = turn(k, 0, gx, gy, gz, c1, -s1)
    cf = gx * k[12, 0] + gy * k[12, 1] + gz * k[12, 2]
    sf = gx * k[13, 0] + gy * k[13, 1] + gz * k[13, 2]
    size = math.sqrt(cf * cf + sf * sf)
    cf, sf = cf / size, sf / size
    _tail(k, tool, c5, s5, c6, s6, tail)
    _head(k, position, rotation, c1, s1, head)
    t1, t5, t6 = math.atan2(s1, c1), math.atan2(s5, c5), math.atan2(s6, c6)
    co, so = k[18, 0], k[18, 1]
    sign3, sign4 = k[14, 0], k[14, 1]
    for elbow in (1.0, -1.0):
        cp = cosine * co + elbow * sine * so  # ψ = ±acos(cosine) − (∠r34 − ∠r23)
        sp = elbow * sine * co - cosine * so
        vx = k[15, 0] + cp * k[16, 0] - sp * k[16, 1]
        vy = k[15, 1] + sp * k[16, 0] + cp * k[16, 1]
        if d2 < FREE_TOL * FREE_TOL:  # the point on axis 2: θ2 free
            c2, s2 = math.cos(fill[1]), math.sin(fill[1])
            singular = True
        else:
            c2, s2 = qe * vx + qf * vy, qf * vx - qe * vy
            size = math.sqrt(c2 * c2 + s2 * s2)
            c2, s2 = c2 / size, s2 / size
        # σ4 θ4 = φ − θ2 − ψ
        cr, sr = cf * c2 + sf * s2, sf * c2 - cf * s2
        c4, s4 = cr * cp + sr * sp, sign4 * (sr * cp - cr * sp)
        s3 = sign3 * sp
        if row < SLOTS and _reaches(k, tail, head, c2, s2, cp, s3, c4, s4):
            raw[row, 0] = t1
            raw[row, 1] = math.atan2(s2, c2)
            raw[row, 2] = math.atan2(s3, cp)
            raw[row, 3] = math.atan2(s4, c4)
            raw[row, 4] = t5
            raw[row, 5] = t6
            row += 1
    return row, singular


@jit
def branches(k, tool, position, rotation, fill, raw, ok):
    """Every solution of one pose: rows of ``raw`` (SLOTS, 6) [rad] (wrapped into [−π, π]),
    with ``ok`` (SLOTS,) where a row holds one.

    Args:
        k: The packed geometry (:meth:`ThreeParallelGeometry.constants
            <kinplan.ik.three_parallel_geometry.ThreeParallelGeometry.constants>`), (26, 3).
        tool: The tool pose at q = 0 (4, 4).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        fill: Values [rad] (6,) of θ1, θ2, θ5, θ6 where they are free.
        raw, ok: Written.

    Returns:
        Whether some joint was free (took its ``fill`` value).
    """
    big_r = np.empty((3, 3))  # R = R_T R_Mᵀ
    for i in range(3):
        for j in range(3):
            big_r[i, j] = (
                rotation[i, 0] * tool[j, 0] + rotation[i, 1] * tool[j, 1]
                + rotation[i, 2] * tool[j, 2]
            )  # fmt: skip
    pairs = np.empty((MOST, 4))
    groups = np.empty(MOST, dtype=np.int64)
    count, singular = pairs_of(k, rotation, position, fill, pairs, groups)
    tail = np.empty((3, 3))
    head = np.empty((4, 3))
    row = 0
    solved = -1  # a group whose double root (its first pair) gave solutions: skip the rest
    for i in range(count):
        if groups[i] == solved:
            continue
        before = row
        row, free = _complete(
            k, tool, big_r, rotation, position, pairs[i], fill, raw, row, tail, head
        )
        if row > before:
            singular = singular or free
            if i == 0 or groups[i - 1] != groups[i]:
                solved = groups[i]
    for r in range(SLOTS):
        ok[r] = r < row
    return singular


@jit
def raw_many(k, tool, positions, rotations, fills, raw, singular):
    """:func:`branches` of many poses: ``raw`` (N, SLOTS, 6) [rad] with NaN rows where no
    solution, ``singular`` (N,)."""
    ok = np.empty(SLOTS, dtype=np.bool_)
    for n in range(positions.shape[0]):
        singular[n] = branches(k, tool, positions[n], rotations[n], fills[n], raw[n], ok)
        for r in range(SLOTS):
            if not ok[r]:
                raw[n, r, :] = np.nan


# ---------------------------------------------------------------------------- the nearest one
@jit
def nearest(k, tool, limits, position, rotation, ref, out):
    """The solution nearest ``ref`` [rad] (6,) written into ``out``; returns its row, −1 when
    none is within the limits, :data:`NOT_FINITE` for an input with a NaN or inf.

    Args:
        k, tool: As :func:`branches`.
        limits: Rows lower, upper [rad] and weights, shape (3, 6).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        ref: Reference configuration; also the value of joints free at a singularity.
        out: Written with the solution.
    """
    if not pose_finite(position, rotation, ref):
        return NOT_FINITE
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    branches(k, tool, position, rotation, ref, raw, ok)
    best, _ = nearest_of(raw, ok, limits, ref, out)
    return best


@jit
def nearest_many(k, tool, limits, positions, rotations, refs, q, row, mask):
    """:func:`nearest` of many poses, each with its own reference: ``q`` (N, 6), ``row`` (N,)
    (−1: none) and ``mask`` (N,) (bit r: row r within the limits) written."""
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    out = np.empty(6)
    for n in range(positions.shape[0]):
        branches(k, tool, positions[n], rotations[n], refs[n], raw, ok)
        best, bits = nearest_of(raw, ok, limits, refs[n], out)
        row[n] = best
        mask[n] = bits
        for j in range(6):
            q[n, j] = out[j] if best >= 0 else np.nan
