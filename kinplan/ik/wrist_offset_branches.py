"""The stages of the 1-D search closed form at one θ6, compiled (numba): for a trial θ6 the
four branches' residual ``f_b(θ6) = h4·(W h5) − h4·h5`` of
:mod:`~kinplan.ik.wrist_offset_search`, every cosine and sine found by square roots (no
trigonometric call), for :class:`~kinplan.ik.wrist_offset.OffsetWristIK`.

With ``T(q) = e1 ⋯ e6 M`` and ``c`` the meeting point of axes 4 and 5 (which e4, e5 leave in
place), a trial θ6 fixes ``e1 e2 e3 c = T M⁻¹ e6(−θ6) c =: c_T(θ6)`` (``c_T`` runs on a circle
of radius :attr:`~kinplan.ik.wrist_offset_geometry.OffsetWristGeometry.miss` as θ6 turns). The
first three joints place ``c_T`` in closed form, four branches ``b = 2·first + second``:

* axes 2 ∥ 3: θ1 by subproblem 4 (two), θ2, θ3 by the planar elbow (two);
* axes 1 and 2 meeting at ``o``: θ3 by subproblem 3 (two), θ1, θ2 by subproblem 2 (two).

The wrist then needs ``R4 R5 = W(θ6) = (R1 R2 R3)ᵀ R_T R_Mᵀ R6(θ6)ᵀ``, which is solvable iff
``f_b(θ6)`` vanishes (``R4 h5 = W h5`` needs equal heights along h4; then R4ᵀW fixes h5).
The geometry comes packed by :meth:`OffsetWristGeometry.constants
<kinplan.ik.wrist_offset_geometry.OffsetWristGeometry.constants>`; rows are indexed, never
sliced (a slice costs numba a reference count in these hot loops).

Without numba, or with ``KINPLAN_JIT=0`` when this module is imported, the same functions run
as plain Python (about a thousand times slower).
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import jit as _compiled_jit
from kinplan.compiled import numba
from kinplan.ik.screws import CLAMP, FREE_TOL, TAU
from kinplan.ik.subproblems import FREE_ROOM

#: Whether the functions are compiled (read from ``KINPLAN_JIT`` at import).
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"

jit = _compiled_jit if ENABLED else (lambda function: function)


def inline(function):
    """:data:`jit` for the small helpers, inlined into their callers by numba (a call between
    compiled functions passes its arrays with reference counts: ~20 ns a call, more than the
    arithmetic of these helpers)."""
    if not ENABLED or numba is None:
        return function
    return numba.njit(inline="always", cache=True, nogil=True, error_model="numpy")(function)


# ---------------------------------------------------------------------------- small geometry
@inline
def turn(k, row, x, y, z, c, s):
    """R(h, θ)·(x, y, z) for the unit axis h = ``k[row]`` and cos θ = c, sin θ = s (rows are
    indexed, never sliced: a slice costs numba a reference count); :func:`turn3`."""
    return turn3((k[row, 0], k[row, 1], k[row, 2]), x, y, z, c, s)


@inline
def angle_to(k, row, px, py, pz, qx, qy, qz):
    """Subproblem 1 as (cos θ, sin θ, across): θ turns p about the unit axis ``k[row]``
    towards q; ``across`` is |p⊥|·|q⊥| (0: free, then (1, 0)); :func:`angle_to3`."""
    return angle_to3((k[row, 0], k[row, 1], k[row, 2]), px, py, pz, qx, qy, qz)


@inline
def wrap(angle):
    return angle - TAU * np.round(angle / TAU)


# ---------------------------------------------------------------------------- as tuples
# The hot loops take the packed geometry and the pose's terms as tuples of 3-tuples (read
# once a batch, once a pose), not arrays: an array passed to a compiled function, or to an
# inlined one (its parameters are new variables), has its reference count kept atomically
# (see kinplan.compiled.inline), 22 % of this search's time before.
@jit
def geometry(k):
    """The packed geometry ``k`` (36, 3) as a tuple of 36 3-tuples (its rows); a call, once a
    batch (compiled once, not inlined into each kernel)."""
    return (
        (k[0, 0], k[0, 1], k[0, 2]),
        (k[1, 0], k[1, 1], k[1, 2]),
        (k[2, 0], k[2, 1], k[2, 2]),
        (k[3, 0], k[3, 1], k[3, 2]),
        (k[4, 0], k[4, 1], k[4, 2]),
        (k[5, 0], k[5, 1], k[5, 2]),
        (k[6, 0], k[6, 1], k[6, 2]),
        (k[7, 0], k[7, 1], k[7, 2]),
        (k[8, 0], k[8, 1], k[8, 2]),
        (k[9, 0], k[9, 1], k[9, 2]),
        (k[10, 0], k[10, 1], k[10, 2]),
        (k[11, 0], k[11, 1], k[11, 2]),
        (k[12, 0], k[12, 1], k[12, 2]),
        (k[13, 0], k[13, 1], k[13, 2]),
        (k[14, 0], k[14, 1], k[14, 2]),
        (k[15, 0], k[15, 1], k[15, 2]),
        (k[16, 0], k[16, 1], k[16, 2]),
        (k[17, 0], k[17, 1], k[17, 2]),
        (k[18, 0], k[18, 1], k[18, 2]),
        (k[19, 0], k[19, 1], k[19, 2]),
        (k[20, 0], k[20, 1], k[20, 2]),
        (k[21, 0], k[21, 1], k[21, 2]),
        (k[22, 0], k[22, 1], k[22, 2]),
        (k[23, 0], k[23, 1], k[23, 2]),
        (k[24, 0], k[24, 1], k[24, 2]),
        (k[25, 0], k[25, 1], k[25, 2]),
        (k[26, 0], k[26, 1], k[26, 2]),
        (k[27, 0], k[27, 1], k[27, 2]),
        (k[28, 0], k[28, 1], k[28, 2]),
        (k[29, 0], k[29, 1], k[29, 2]),
        (k[30, 0], k[30, 1], k[30, 2]),
        (k[31, 0], k[31, 1], k[31, 2]),
        (k[32, 0], k[32, 1], k[32, 2]),
        (k[33, 0], k[33, 1], k[33, 2]),
        (k[34, 0], k[34, 1], k[34, 2]),
        (k[35, 0], k[35, 1], k[35, 2]),
    )


@inline
def pose_terms(k, position, rotation):
    """The pose's terms, 9 3-tuples: ``c_T(θ6) = B0 + cos θ6 B1 + sin θ6 B2``,
    ``R_T R_Mᵀ R6(θ6)ᵀ h5 = E0 + cos E1 + sin E2`` and the same for x5 (G0, G1, G2), of the
    geometry as tuples (:func:`geometry`) and the pose as tuples (3, and 3 rows of 3)."""
    p0, p1, p2 = position
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rotation
    return (
        (
            r00 * k[13][0] + r01 * k[13][1] + r02 * k[13][2] + p0,
            r10 * k[13][0] + r11 * k[13][1] + r12 * k[13][2] + p1,
            r20 * k[13][0] + r21 * k[13][1] + r22 * k[13][2] + p2,
        ),
        (
            r00 * k[14][0] + r01 * k[14][1] + r02 * k[14][2],
            r10 * k[14][0] + r11 * k[14][1] + r12 * k[14][2],
            r20 * k[14][0] + r21 * k[14][1] + r22 * k[14][2],
        ),
        (
            r00 * k[15][0] + r01 * k[15][1] + r02 * k[15][2],
            r10 * k[15][0] + r11 * k[15][1] + r12 * k[15][2],
            r20 * k[15][0] + r21 * k[15][1] + r22 * k[15][2],
        ),
        (
            r00 * k[16][0] + r01 * k[16][1] + r02 * k[16][2],
            r10 * k[16][0] + r11 * k[16][1] + r12 * k[16][2],
            r20 * k[16][0] + r21 * k[16][1] + r22 * k[16][2],
        ),
        (
            r00 * k[17][0] + r01 * k[17][1] + r02 * k[17][2],
            r10 * k[17][0] + r11 * k[17][1] + r12 * k[17][2],
            r20 * k[17][0] + r21 * k[17][1] + r22 * k[17][2],
        ),
        (
            r00 * k[18][0] + r01 * k[18][1] + r02 * k[18][2],
            r10 * k[18][0] + r11 * k[18][1] + r12 * k[18][2],
            r20 * k[18][0] + r21 * k[18][1] + r22 * k[18][2],
        ),
        (
            r00 * k[19][0] + r01 * k[19][1] + r02 * k[19][2],
            r10 * k[19][0] + r11 * k[19][1] + r12 * k[19][2],
            r20 * k[19][0] + r21 * k[19][1] + r22 * k[19][2],
        ),
        (
            r00 * k[20][0] + r01 * k[20][1] + r02 * k[20][2],
            r10 * k[20][0] + r11 * k[20][1] + r12 * k[20][2],
            r20 * k[20][0] + r21 * k[20][1] + r22 * k[20][2],
        ),
        (
            r00 * k[21][0] + r01 * k[21][1] + r02 * k[21][2],
            r10 * k[21][0] + r11 * k[21][1] + r12 * k[21][2],
            r20 * k[21][0] + r21 * k[21][1] + r22 * k[21][2],
        ),
    )


@inline
def turn3(axis, x, y, z, c, s):
    """R(h, θ)·(x, y, z) for the unit axis h = ``axis`` (a 3-tuple), cos θ = c, sin θ = s."""
    ax, ay, az = axis
    t = (ax * x + ay * y + az * z) * (1.0 - c)
    return (
        x * c + (ay * z - az * y) * s + ax * t,
        y * c + (az * x - ax * z) * s + ay * t,
        z * c + (ax * y - ay * x) * s + az * t,
    )


@inline
def angle_to3(axis, px, py, pz, qx, qy, qz):
    """Subproblem 1 as (cos θ, sin θ, across): θ turns p about the unit axis ``axis`` (a
    3-tuple) towards q; ``across`` is |p⊥|·|q⊥| (0: free, then (1, 0))."""
    ax, ay, az = axis
    kp = ax * px + ay * py + az * pz
    kq = ax * qx + ay * qy + az * qz
    cosine = px * qx + py * qy + pz * qz - kp * kq
    sine = ax * (py * qz - pz * qy) + ay * (pz * qx - px * qz) + az * (px * qy - py * qx)
    radius = math.sqrt(cosine * cosine + sine * sine)
    if radius == 0.0:
        return 1.0, 0.0, 0.0
    return cosine / radius, sine / radius, radius


@inline
def across3(axis, x, y, z):
    """|v⊥|² of (x, y, z) across the unit axis ``axis`` (a 3-tuple)."""
    a = axis[0] * x + axis[1] * y + axis[2] * z
    return x * x + y * y + z * z - a * a


#: The rows of the packed geometry that the branches read, in this order: the branch
#: functions below take ``k`` as these rows (:func:`branch_geometry`) and the pose's terms
#: as its first six rows (``c_T``'s and ``d``'s), ``fill`` as (θ1, θ2) [rad]: each call
#: between the search's compiled functions passes 53 numbers, not the whole geometry.
BRANCH_ROWS = (0, 1, 2, 3, 6, 7, 23, 24, 25, 26, 27, 28, 29, 30, 31, 32, 33)


@inline
def branch_geometry(g):
    """The rows :data:`BRANCH_ROWS` of the geometry as tuples (:func:`geometry`)."""
    return (
        g[0],
        g[1],
        g[2],
        g[3],
        g[6],
        g[7],
        g[23],
        g[24],
        g[25],
        g[26],
        g[27],
        g[28],
        g[29],
        g[30],
        g[31],
        g[32],
        g[33],
    )


# ---------------------------------------------------------------------------- one θ6


@inline
def _fails(stage, margin):
    """What :func:`branch` returns where stage 1 or 2 fails: (stage, False, False, margin < 0,
    then cos, sin of 0)."""
    return float(stage), False, False, margin, 0.0, 1.0, 0.0, 1.0, 0.0


@inline
def _moving(pre, c6, s6):
    """``c_T(θ6)`` and ``d(θ6) = R_T R_Mᵀ R6(θ6)ᵀ h5`` of the θ6 of cosine c6, sine s6."""
    return (
        pre[0][0] + c6 * pre[1][0] + s6 * pre[2][0],
        pre[0][1] + c6 * pre[1][1] + s6 * pre[2][1],
        pre[0][2] + c6 * pre[1][2] + s6 * pre[2][2],
        pre[3][0] + c6 * pre[4][0] + s6 * pre[5][0],
        pre[3][1] + c6 * pre[4][1] + s6 * pre[5][1],
        pre[3][2] + c6 * pre[4][2] + s6 * pre[5][2],
    )


@inline
def _pair(a, b, ratio, first):
    """(cos θ, sin θ) of the solution ``first`` (0: +, 1: −) of a cos θ + b sin θ = ratio·r
    with r = √(a² + b²) (a, b already divided by r; ratio clamped into [−1, 1])."""
    r = min(max(ratio, -1.0), 1.0)
    half = math.sqrt(max(1.0 - r * r, 0.0)) * (1.0 if first == 0 else -1.0)
    return a * r - b * half, b * r + a * half


# axes 2 ∥ 3 ------------------------------------------------------------------------------
@inline
def _parallel_shoulder(k, ctx, cty, ctz):
    """Subproblem 4 for −θ1: (v = c_T − p1, a/r, b/r, rhs/r, r, rhs) (r = 0: free)."""
    vx, vy, vz = ctx - k[4][0], cty - k[4][1], ctz - k[4][2]
    hk = k[1][0] * k[0][0] + k[1][1] * k[0][1] + k[1][2] * k[0][2]
    kp = vx * k[0][0] + vy * k[0][1] + vz * k[0][2]
    a = vx * k[1][0] + vy * k[1][1] + vz * k[1][2] - hk * kp
    b = (
        vx * (k[1][1] * k[0][2] - k[1][2] * k[0][1])
        + vy * (k[1][2] * k[0][0] - k[1][0] * k[0][2])
        + vz * (k[1][0] * k[0][1] - k[1][1] * k[0][0])
    )
    radius = math.sqrt(a * a + b * b)
    rhs = k[9][0] - hk * kp
    if radius < FREE_TOL:
        return vx, vy, vz, 1.0, 0.0, 0.0, radius, rhs
    return vx, vy, vz, a / radius, b / radius, rhs / radius, radius, rhs


@inline
def _parallel_elbow(k, vx, vy, vz, cm, sm):
    """The wrist point in the plane of the elbow after R1ᵀ: (tx, ty, d², cos of the elbow)."""
    sx, sy, sz = turn3(k[0], vx, vy, vz, cm, sm)
    sx += k[4][0] - k[5][0]
    sy += k[4][1] - k[5][1]
    sz += k[4][2] - k[5][2]
    tx = sx * k[7][0] + sy * k[7][1] + sz * k[7][2]
    ty = sx * k[8][0] + sy * k[8][1] + sz * k[8][2]
    d2 = tx * tx + ty * ty
    l1, l2 = k[12][0], k[12][1]
    return tx, ty, d2, (d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)


@inline
def _parallel_angles(k, tx, ty, d2, cosine, second, fill):
    """(free, cos, sin of θ2, of θ3, of θ2 + ψ3) of elbow branch ``second``."""
    ce, se = _pair(1.0, 0.0, cosine, second)
    cob, sob = k[13][0], k[13][1]
    cpsi, spsi = ce * cob - se * sob, se * cob + ce * sob
    wx = k[10][0] + cpsi * k[11][0] - spsi * k[11][1]
    wy = k[10][1] + spsi * k[11][0] + cpsi * k[11][1]
    free = d2 < FREE_TOL * FREE_TOL
    if free:
        c2, s2 = math.cos(fill[1]), math.sin(fill[1])
    else:
        norm = math.sqrt(d2 * (wx * wx + wy * wy))
        c2, s2 = (tx * wx + ty * wy) / norm, (wx * ty - wy * tx) / norm
    cphi, sphi = c2 * cpsi - s2 * spsi, s2 * cpsi + c2 * spsi
    return free, c2, s2, cpsi, k[9][1] * spsi, cphi, sphi


@inline
def _parallel_wrist(k, dx, dy, dz, cm, sm):
    """(P0, P1, P2) with f = P0 + cos φ P1 + sin φ P2 − h4·h5 for φ = θ2 + ψ3."""
    ex, ey, ez = turn3(k[0], dx, dy, dz, cm, sm)
    return (
        k[14][0] * (k[1][0] * ex + k[1][1] * ey + k[1][2] * ez),
        k[15][0] * ex + k[15][1] * ey + k[15][2] * ez,
        k[16][0] * ex + k[16][1] * ey + k[16][2] * ez,
    )


# axes 1 and 2 meet ----------------------------------------------------------------------------
@inline
def _meeting_elbow(k, ctx, cty, ctz):
    """Subproblem 3 for θ3: (y = c_T − o, |y|², the ratio of its cos form)."""
    yx, yy, yz = ctx - k[7][0], cty - k[7][1], ctz - k[7][2]
    dd = yx * yx + yy * yy + yz * yz
    return yx, yy, yz, dd, k[10][2] - dd * k[11][2]


@inline
def _meeting_third(k, ratio, first):
    """(cos θ3, sin θ3, x = e3 c − o, R3 h4) of branch ``first``."""
    c3, s3 = _pair(k[10][0], k[10][1], ratio, first)
    xx, xy, xz = turn3(k[2], k[8][0], k[8][1], k[8][2], c3, s3)
    gx, gy, gz = turn3(k[2], k[3][0], k[3][1], k[3][2], c3, s3)
    return c3, s3, xx - k[9][0], xy - k[9][1], xz - k[9][2], gx, gy, gz


@inline
def _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd):
    """Subproblem 2's common vector ``z = α h2 + β h1 (± γ n)``: (α h2 + β h1, γ², margin):
    the cones meet where the margin ``γ²n²/ℓ² + CLAMP`` (ℓ² the mean squared length) is ≥ 0."""
    c12, n2 = k[11][0], k[11][1]
    hx = k[1][0] * xx + k[1][1] * xy + k[1][2] * xz
    hy = k[0][0] * yx + k[0][1] * yy + k[0][2] * yz
    alpha = (hx - c12 * hy) / n2
    beta = (hy - c12 * hx) / n2
    length2 = 0.5 * (xx * xx + xy * xy + xz * xz + dd)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12
    return (
        alpha * k[1][0] + beta * k[0][0],
        alpha * k[1][1] + beta * k[0][1],
        alpha * k[1][2] + beta * k[0][2],
        max(rest, 0.0) / n2,
        rest / max(length2, 1e-300) + CLAMP,
    )


@inline
def _meeting_angles(k, xx, xy, xz, yx, yy, yz, mx, my, mz, gamma2, second, fill):
    """(free, cos, sin of −θ1, of θ2) of branch ``second`` of subproblem 2."""
    gamma = math.sqrt(gamma2) * (1.0 if second == 0 else -1.0)
    zx, zy, zz = mx + gamma * k[12][0], my + gamma * k[12][1], mz + gamma * k[12][2]
    free = False
    if across3(k[0], yx, yy, yz) < FREE_TOL * FREE_TOL:  # c_T on axis 1: θ1 free
        free = True
        cm, sm = math.cos(fill[0]), -math.sin(fill[0])
    else:
        cm, sm, _ = angle_to3(k[0], yx, yy, yz, zx, zy, zz)
    if across3(k[1], xx, xy, xz) < FREE_TOL * FREE_TOL:  # e3 c on axis 2: θ2 free
        free = True
        c2, s2 = math.cos(fill[1]), math.sin(fill[1])
    else:
        c2, s2, _ = angle_to3(k[1], xx, xy, xz, zx, zy, zz)
    return free, cm, sm, c2, s2


@inline
def _meeting_residual(k, gx, gy, gz, c2, s2, dx, dy, dz, cm, sm):
    """f = (R2 R3 h4)·(R1ᵀ d) − h4·h5."""
    gx, gy, gz = turn3(k[1], gx, gy, gz, c2, s2)
    ex, ey, ez = turn3(k[0], dx, dy, dz, cm, sm)
    return gx * ex + gy * ey + gz * ez - k[6][1]


# ---------------------------------------------------------------------------- branches
@jit
def branch(k, pre, c6, s6, b, fill):
    """Branch ``b`` (0–3) at the θ6 of cosine ``c6``, sine ``s6``: :func:`branch_inline`, as a
    call (for the callers that evaluate a branch at a few θ6 only)."""
    return branch_inline(k, pre, c6, s6, b, fill)


@inline
def branch_inline(k, pre, c6, s6, b, fill):
    """Branch ``b`` (0–3) at the θ6 of cosine ``c6``, sine ``s6``, inlined into its caller
    (Brent's method evaluates it a few dozen times a pose: no call, no reference counts).

    Returns:
        (f, ok, singular, cos, sin of −θ1, of θ2, of θ3): ``ok`` False where the branch does
        not reach ``c_T``; f is then 1 where the first stage fails (subproblem 4 for θ1, or 3
        for θ3: both branches of that stage fail) and 2 where the second does, and the
        cosine of −θ1 is replaced by the failing stage's margin (< 0; a smooth function of θ6
        whose zeros are the ends of the branch's reach); ``singular`` where a free angle took
        its ``fill`` value.
    """
    first, second = b // 2, b % 2
    ctx, cty, ctz, dx, dy, dz = _moving(pre, c6, s6)
    if k[6][0] == 0.0:  # axes 2 ∥ 3
        vx, vy, vz, a, bb, ratio, radius, rhs = _parallel_shoulder(k, ctx, cty, ctz)
        singular = radius < FREE_TOL
        if singular:
            if abs(rhs) > FREE_ROOM:
                return _fails(1, FREE_ROOM - abs(rhs))
            cm, sm = math.cos(fill[0]), -math.sin(fill[0])
        else:
            if abs(ratio) > 1.0 + CLAMP:
                return _fails(1, 1.0 + CLAMP - abs(ratio))
            cm, sm = _pair(a, bb, ratio, first)
        tx, ty, d2, cosine = _parallel_elbow(k, vx, vy, vz, cm, sm)
        if abs(cosine) > 1.0 + CLAMP:
            return _fails(2, 1.0 + CLAMP - abs(cosine))
        free, c2, s2, c3, s3, cphi, sphi = _parallel_angles(k, tx, ty, d2, cosine, second, fill)
        p0, p1, p2 = _parallel_wrist(k, dx, dy, dz, cm, sm)
        f = p0 + cphi * p1 + sphi * p2 - k[6][1]
        return f, True, singular or free, cm, sm, c2, s2, c3, s3
    yx, yy, yz, dd, ratio = _meeting_elbow(k, ctx, cty, ctz)
    if abs(ratio) > 1.0 + CLAMP:
        return _fails(1, 1.0 + CLAMP - abs(ratio))
    c3, s3, xx, xy, xz, gx, gy, gz = _meeting_third(k, ratio, first)
    mx, my, mz, gamma2, margin = _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd)
    if margin < 0.0:
        return _fails(2, margin)
    free, cm, sm, c2, s2 = _meeting_angles(
        k, xx, xy, xz, yx, yy, yz, mx, my, mz, gamma2, second, fill
    )
    f = _meeting_residual(k, gx, gy, gz, c2, s2, dx, dy, dz, cm, sm)
    return f, True, free, cm, sm, c2, s2, c3, s3


@inline
def reach(k, pre, c6, s6, b, fill):
    """Whether branch ``b`` reaches ``c_T`` at the θ6 of cosine ``c6``, sine ``s6``, decided as
    :func:`branch_inline` decides it (the same stages, the same tests) at about half its cost
    (no angle of the elbow or the wrist, no residual): (ok, the stage that fails (0: none),
    the margin of stage 1, that of stage 2 (stage 1's where stage 1 fails)); a margin is what
    :func:`branch_inline` returns for the failing stage, ≥ 0 where the stage passes."""
    first = b // 2
    ctx, cty, ctz, _, _, _ = _moving(pre, c6, s6)
    if k[6][0] == 0.0:  # axes 2 ∥ 3
        vx, vy, vz, a, bb, ratio, radius, rhs = _parallel_shoulder(k, ctx, cty, ctz)
        if radius < FREE_TOL:
            m1 = FREE_ROOM - abs(rhs)
            if abs(rhs) > FREE_ROOM:
                return False, 1, m1, m1
            cm, sm = math.cos(fill[0]), -math.sin(fill[0])
        else:
            m1 = 1.0 + CLAMP - abs(ratio)
            if abs(ratio) > 1.0 + CLAMP:
                return False, 1, m1, m1
            cm, sm = _pair(a, bb, ratio, first)
        _, _, _, cosine = _parallel_elbow(k, vx, vy, vz, cm, sm)
        m2 = 1.0 + CLAMP - abs(cosine)
        if abs(cosine) > 1.0 + CLAMP:
            return False, 2, m1, m2
        return True, 0, m1, m2
    yx, yy, yz, dd, ratio = _meeting_elbow(k, ctx, cty, ctz)
    m1 = 1.0 + CLAMP - abs(ratio)
    if abs(ratio) > 1.0 + CLAMP:
        return False, 1, m1, m1
    _, _, xx, xy, xz, _, _, _ = _meeting_third(k, ratio, first)
    _, _, _, _, m2 = _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd)
    if m2 < 0.0:
        return False, 2, m1, m2
    return True, 0, m1, m2


@inline
def _parallel_first(k, vx, vy, vz, a, bb, ratio, radius, dx, dy, dz, first, fill):
    """The two branches 2·first, 2·first + 1 of axes 2 ∥ 3 at one θ6 (θ1 of ``first``
    shared): (f or the elbow's margin for each, reached, their (cos, sin of −θ1, θ2, θ3),
    whether a free angle took its fill value, the elbow's margin)."""
    if radius < FREE_TOL:
        cm, sm = math.cos(fill[0]), -math.sin(fill[0])
    else:
        cm, sm = _pair(a, bb, ratio, first)
    tx, ty, d2, cosine = _parallel_elbow(k, vx, vy, vz, cm, sm)
    margin = 1.0 + CLAMP - abs(cosine)
    if margin < 0.0:
        return margin, margin, False, STAGE_2, STAGE_2, False, margin
    p0, p1, p2 = _parallel_wrist(k, dx, dy, dz, cm, sm)
    fa = fb = 0.0
    ta = tb = _UNUSED
    free = False
    for second in range(2):  # a loop: one compiled copy of the code
        fr, c2, s2, c3, s3, cphi, sphi = _parallel_angles(k, tx, ty, d2, cosine, second, fill)
        f = p0 + cphi * p1 + sphi * p2 - k[6][1]
        if second == 0:
            fa, ta = f, (cm, sm, c2, s2, c3, s3)
        else:
            fb, tb = f, (cm, sm, c2, s2, c3, s3)
        free = free or fr
    return fa, fb, True, ta, tb, free, margin


@inline
def _meeting_first(k, ratio, yx, yy, yz, dd, dx, dy, dz, first, fill):
    """:func:`_parallel_first` for axes 1 and 2 meeting (θ3 of ``first`` shared)."""
    c3, s3, xx, xy, xz, gx, gy, gz = _meeting_third(k, ratio, first)
    mx, my, mz, gamma2, margin = _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd)
    if margin < 0.0:
        return margin, margin, False, STAGE_2, STAGE_2, False, margin
    fa = fb = 0.0
    ta = tb = _UNUSED
    free = False
    for second in range(2):  # a loop: one compiled copy of the code
        fr, cm, sm, c2, s2 = _meeting_angles(
            k, xx, xy, xz, yx, yy, yz, mx, my, mz, gamma2, second, fill
        )
        f = _meeting_residual(k, gx, gy, gz, c2, s2, dx, dy, dz, cm, sm)
        if second == 0:
            fa, ta = f, (cm, sm, c2, s2, c3, s3)
        else:
            fb, tb = f, (cm, sm, c2, s2, c3, s3)
        free = free or fr
    return fa, fb, True, ta, tb, free, margin


#: The turns of a branch that does not reach (never read).
_UNUSED = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
#: What :func:`sample` gives as the turns of a branch that does not reach: its first entry the
#: stage that fails (1 or 2; the search tells a corner of the margin, where the failing stage
#: changes between two samples, by it), the rest never read.
STAGE_1 = (1.0, 0.0, 0.0, 0.0, 0.0, 0.0)
STAGE_2 = (2.0, 0.0, 0.0, 0.0, 0.0, 0.0)


@inline
def sample(k, pre, c6, s6, fill):
    """f of the four branches at one θ6, the shared stages computed once (:func:`branch` four
    times, at about half the cost): (whether a free angle took its fill value, f of each
    branch (a 4-tuple; where a branch does not reach, the failing stage's margin < 0
    instead), whether each reaches, each one's (cos, sin of −θ1, θ2, θ3) (6-tuples; anything
    where it does not reach), each one's room (the least margin of its two stages, as
    :func:`reach` gives them: ≥ 0 where it reaches, the failing stage's where not)). Numbers
    and tuples only: no array, no reference count."""
    ctx, cty, ctz, dx, dy, dz = _moving(pre, c6, s6)
    if k[6][0] == 0.0:
        vx, vy, vz, a, bb, ratio, radius, rhs = _parallel_shoulder(k, ctx, cty, ctz)
        singular = radius < FREE_TOL
        if singular:
            m1 = FREE_ROOM - abs(rhs)
            if abs(rhs) > FREE_ROOM:
                return _failed(m1)
        else:
            m1 = 1.0 + CLAMP - abs(ratio)
            if abs(ratio) > 1.0 + CLAMP:
                return _failed(m1)
        f0 = f1 = f2 = f3 = 0.0
        ok0 = ok1 = False
        t0 = t1 = t2 = t3 = _UNUSED
        r0 = r1 = m1
        for first in range(2):  # a loop: one compiled copy of the code
            fa, fb, ok, ta, tb, free, m2 = _parallel_first(
                k, vx, vy, vz, a, bb, ratio, radius, dx, dy, dz, first, fill
            )
            if first == 0:
                f0, f1, ok0, t0, t1, r0 = fa, fb, ok, ta, tb, (min(m1, m2) if ok else m2)
            else:
                f2, f3, ok1, t2, t3, r1 = fa, fb, ok, ta, tb, (min(m1, m2) if ok else m2)
            singular = singular or free
        return singular, (f0, f1, f2, f3), (ok0, ok0, ok1, ok1), (t0, t1, t2, t3), (r0, r0, r1, r1)
    yx, yy, yz, dd, ratio = _meeting_elbow(k, ctx, cty, ctz)
    m1 = 1.0 + CLAMP - abs(ratio)
    if abs(ratio) > 1.0 + CLAMP:
        return _failed(m1)
    singular = False
    f0 = f1 = f2 = f3 = 0.0
    ok0 = ok1 = False
    t0 = t1 = t2 = t3 = _UNUSED
    r0 = r1 = m1
    for first in range(2):  # a loop: one compiled copy of the code
        fa, fb, ok, ta, tb, free, m2 = _meeting_first(
            k, ratio, yx, yy, yz, dd, dx, dy, dz, first, fill
        )
        if first == 0:
            f0, f1, ok0, t0, t1, r0 = fa, fb, ok, ta, tb, (min(m1, m2) if ok else m2)
        else:
            f2, f3, ok1, t2, t3, r1 = fa, fb, ok, ta, tb, (min(m1, m2) if ok else m2)
        singular = singular or free
    return singular, (f0, f1, f2, f3), (ok0, ok0, ok1, ok1), (t0, t1, t2, t3), (r0, r0, r1, r1)


@inline
def _failed(margin):
    """What :func:`sample` returns where the first stage fails for all four branches."""
    return (
        False, (margin, margin, margin, margin), (False, False, False, False),
        (STAGE_1, STAGE_1, STAGE_1, STAGE_1), (margin, margin, margin, margin),
    )  # fmt: skip
