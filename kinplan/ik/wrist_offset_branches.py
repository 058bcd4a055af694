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
    indexed, never sliced: a slice costs numba a reference count)."""
    ax, ay, az = k[row, 0], k[row, 1], k[row, 2]
    t = (ax * x + ay * y + az * z) * (1.0 - c)
    return (
        x * c + (ay * z - az * y) * s + ax * t,
        y * c + (az * x - ax * z) * s + ay * t,
        z * c + (ax * y - ay * x) * s + az * t,
    )


@inline
def angle_to(k, row, px, py, pz, qx, qy, qz):
    """Subproblem 1 as (cos θ, sin θ, across): θ turns p about the unit axis ``k[row]``
    towards q; ``across`` is |p⊥|·|q⊥| (0: free, then (1, 0))."""
    ax, ay, az = k[row, 0], k[row, 1], k[row, 2]
    kp = ax * px + ay * py + az * pz
    kq = ax * qx + ay * qy + az * qz
    cosine = px * qx + py * qy + pz * qz - kp * kq
    sine = ax * (py * qz - pz * qy) + ay * (pz * qx - px * qz) + az * (px * qy - py * qx)
    radius = math.sqrt(cosine * cosine + sine * sine)
    if radius == 0.0:
        return 1.0, 0.0, 0.0
    return cosine / radius, sine / radius, radius


@inline
def across(k, row, x, y, z):
    """|v⊥|² of (x, y, z) across the unit axis ``k[row]``."""
    a = k[row, 0] * x + k[row, 1] * y + k[row, 2] * z
    return x * x + y * y + z * z - a * a


@inline
def wrap(angle):
    return angle - TAU * np.round(angle / TAU)


@jit
def prepare(k, position, rotation, pre):
    """The pose's terms (rows of ``pre`` (9, 3)): ``c_T(θ6) = B0 + cos θ6 B1 + sin θ6 B2``,
    ``R_T R_Mᵀ R6(θ6)ᵀ h5 = E0 + cos E1 + sin E2`` and the same for x5 (G0, G1, G2)."""
    for r in range(9):
        for i in range(3):
            pre[r, i] = (
                rotation[i, 0] * k[13 + r, 0]
                + rotation[i, 1] * k[13 + r, 1]
                + rotation[i, 2] * k[13 + r, 2]
            )
    for i in range(3):
        pre[0, i] += position[i]


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
        pre[0, 0] + c6 * pre[1, 0] + s6 * pre[2, 0],
        pre[0, 1] + c6 * pre[1, 1] + s6 * pre[2, 1],
        pre[0, 2] + c6 * pre[1, 2] + s6 * pre[2, 2],
        pre[3, 0] + c6 * pre[4, 0] + s6 * pre[5, 0],
        pre[3, 1] + c6 * pre[4, 1] + s6 * pre[5, 1],
        pre[3, 2] + c6 * pre[4, 2] + s6 * pre[5, 2],
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
    vx, vy, vz = ctx - k[6, 0], cty - k[6, 1], ctz - k[6, 2]
    hk = k[1, 0] * k[0, 0] + k[1, 1] * k[0, 1] + k[1, 2] * k[0, 2]
    kp = vx * k[0, 0] + vy * k[0, 1] + vz * k[0, 2]
    a = vx * k[1, 0] + vy * k[1, 1] + vz * k[1, 2] - hk * kp
    b = (
        vx * (k[1, 1] * k[0, 2] - k[1, 2] * k[0, 1])
        + vy * (k[1, 2] * k[0, 0] - k[1, 0] * k[0, 2])
        + vz * (k[1, 0] * k[0, 1] - k[1, 1] * k[0, 0])
    )
    radius = math.sqrt(a * a + b * b)
    rhs = k[26, 0] - hk * kp
    if radius < FREE_TOL:
        return vx, vy, vz, 1.0, 0.0, 0.0, radius, rhs
    return vx, vy, vz, a / radius, b / radius, rhs / radius, radius, rhs


@inline
def _parallel_elbow(k, vx, vy, vz, cm, sm):
    """The wrist point in the plane of the elbow after R1ᵀ: (tx, ty, d², cos of the elbow)."""
    sx, sy, sz = turn(k, 0, vx, vy, vz, cm, sm)
    sx += k[6, 0] - k[7, 0]
    sy += k[6, 1] - k[7, 1]
    sz += k[6, 2] - k[7, 2]
    tx = sx * k[24, 0] + sy * k[24, 1] + sz * k[24, 2]
    ty = sx * k[25, 0] + sy * k[25, 1] + sz * k[25, 2]
    d2 = tx * tx + ty * ty
    l1, l2 = k[29, 0], k[29, 1]
    return tx, ty, d2, (d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)


@inline
def _parallel_angles(k, tx, ty, d2, cosine, second, fill):
    """(free, cos, sin of θ2, of θ3, of θ2 + ψ3) of elbow branch ``second``."""
    ce, se = _pair(1.0, 0.0, cosine, second)
    cob, sob = k[30, 0], k[30, 1]
    cpsi, spsi = ce * cob - se * sob, se * cob + ce * sob
    wx = k[27, 0] + cpsi * k[28, 0] - spsi * k[28, 1]
    wy = k[27, 1] + spsi * k[28, 0] + cpsi * k[28, 1]
    free = d2 < FREE_TOL * FREE_TOL
    if free:
        c2, s2 = math.cos(fill[1]), math.sin(fill[1])
    else:
        norm = math.sqrt(d2 * (wx * wx + wy * wy))
        c2, s2 = (tx * wx + ty * wy) / norm, (wx * ty - wy * tx) / norm
    cphi, sphi = c2 * cpsi - s2 * spsi, s2 * cpsi + c2 * spsi
    return free, c2, s2, cpsi, k[26, 1] * spsi, cphi, sphi


@inline
def _parallel_wrist(k, dx, dy, dz, cm, sm):
    """(P0, P1, P2) with f = P0 + cos φ P1 + sin φ P2 − h4·h5 for φ = θ2 + ψ3."""
    ex, ey, ez = turn(k, 0, dx, dy, dz, cm, sm)
    return (
        k[31, 0] * (k[1, 0] * ex + k[1, 1] * ey + k[1, 2] * ez),
        k[32, 0] * ex + k[32, 1] * ey + k[32, 2] * ez,
        k[33, 0] * ex + k[33, 1] * ey + k[33, 2] * ez,
    )


# axes 1 and 2 meet ----------------------------------------------------------------------------
@inline
def _meeting_elbow(k, ctx, cty, ctz):
    """Subproblem 3 for θ3: (y = c_T − o, |y|², the ratio of its cos form)."""
    yx, yy, yz = ctx - k[24, 0], cty - k[24, 1], ctz - k[24, 2]
    dd = yx * yx + yy * yy + yz * yz
    return yx, yy, yz, dd, k[27, 2] - dd * k[28, 2]


@inline
def _meeting_third(k, ratio, first):
    """(cos θ3, sin θ3, x = e3 c − o, R3 h4) of branch ``first``."""
    c3, s3 = _pair(k[27, 0], k[27, 1], ratio, first)
    xx, xy, xz = turn(k, 2, k[25, 0], k[25, 1], k[25, 2], c3, s3)
    gx, gy, gz = turn(k, 2, k[3, 0], k[3, 1], k[3, 2], c3, s3)
    return c3, s3, xx - k[26, 0], xy - k[26, 1], xz - k[26, 2], gx, gy, gz


@inline
def _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd):
    """Subproblem 2's common vector ``z = α h2 + β h1 (± γ n)``: (α h2 + β h1, γ², margin):
    the cones meet where the margin ``γ²n²/ℓ² + CLAMP`` (ℓ² the mean squared length) is ≥ 0."""
    c12, n2 = k[28, 0], k[28, 1]
    hx = k[1, 0] * xx + k[1, 1] * xy + k[1, 2] * xz
    hy = k[0, 0] * yx + k[0, 1] * yy + k[0, 2] * yz
    alpha = (hx - c12 * hy) / n2
    beta = (hy - c12 * hx) / n2
    length2 = 0.5 * (xx * xx + xy * xy + xz * xz + dd)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c12
    return (
        alpha * k[1, 0] + beta * k[0, 0],
        alpha * k[1, 1] + beta * k[0, 1],
        alpha * k[1, 2] + beta * k[0, 2],
        max(rest, 0.0) / n2,
        rest / max(length2, 1e-300) + CLAMP,
    )


@inline
def _meeting_angles(k, xx, xy, xz, yx, yy, yz, mx, my, mz, gamma2, second, fill):
    """(free, cos, sin of −θ1, of θ2) of branch ``second`` of subproblem 2."""
    gamma = math.sqrt(gamma2) * (1.0 if second == 0 else -1.0)
    zx, zy, zz = mx + gamma * k[29, 0], my + gamma * k[29, 1], mz + gamma * k[29, 2]
    free = False
    if across(k, 0, yx, yy, yz) < FREE_TOL * FREE_TOL:  # c_T on axis 1: θ1 free
        free = True
        cm, sm = math.cos(fill[0]), -math.sin(fill[0])
    else:
        cm, sm, _ = angle_to(k, 0, yx, yy, yz, zx, zy, zz)
    if across(k, 1, xx, xy, xz) < FREE_TOL * FREE_TOL:  # e3 c on axis 2: θ2 free
        free = True
        c2, s2 = math.cos(fill[1]), math.sin(fill[1])
    else:
        c2, s2, _ = angle_to(k, 1, xx, xy, xz, zx, zy, zz)
    return free, cm, sm, c2, s2


@inline
def _meeting_residual(k, gx, gy, gz, c2, s2, dx, dy, dz, cm, sm):
    """f = (R2 R3 h4)·(R1ᵀ d) − h4·h5."""
    gx, gy, gz = turn(k, 1, gx, gy, gz, c2, s2)
    ex, ey, ez = turn(k, 0, dx, dy, dz, cm, sm)
    return gx * ex + gy * ey + gz * ez - k[23, 1]


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
    if k[23, 0] == 0.0:  # axes 2 ∥ 3
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
        f = p0 + cphi * p1 + sphi * p2 - k[23, 1]
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
def sample(k, pre, c6, s6, fill, values, reached, turns, i):
    """f of the four branches at one θ6 into row ``i`` of ``values``, ``reached`` (·, 4) and
    the cosines and sines of −θ1, θ2, θ3 into row ``i`` of ``turns`` (·, 4, 6) (the shared
    stages computed once: :func:`branch` four times, at about half the cost); where a branch
    does not reach, ``values`` holds the failing stage's margin (< 0) instead. Returns whether
    a free angle took its fill value. Inlined into the sampling loop (a call would pass seven
    arrays, with their reference counts, at each sample)."""
    ctx, cty, ctz, dx, dy, dz = _moving(pre, c6, s6)
    singular = False
    for b in range(4):
        reached[i, b] = False
        values[i, b] = 0.0
    if k[23, 0] == 0.0:
        vx, vy, vz, a, bb, ratio, radius, rhs = _parallel_shoulder(k, ctx, cty, ctz)
        if radius < FREE_TOL:
            if abs(rhs) > FREE_ROOM:
                _fill(values, i, FREE_ROOM - abs(rhs))
                return False
            singular = True
        elif abs(ratio) > 1.0 + CLAMP:
            _fill(values, i, 1.0 + CLAMP - abs(ratio))
            return False
        for first in range(2):
            if radius < FREE_TOL:
                cm, sm = math.cos(fill[0]), -math.sin(fill[0])
            else:
                cm, sm = _pair(a, bb, ratio, first)
            tx, ty, d2, cosine = _parallel_elbow(k, vx, vy, vz, cm, sm)
            if abs(cosine) > 1.0 + CLAMP:
                values[i, 2 * first] = values[i, 2 * first + 1] = 1.0 + CLAMP - abs(cosine)
                continue
            p0, p1, p2 = _parallel_wrist(k, dx, dy, dz, cm, sm)
            for second in range(2):
                free, c2, s2, c3, s3, cphi, sphi = _parallel_angles(
                    k, tx, ty, d2, cosine, second, fill
                )
                row = 2 * first + second
                values[i, row] = p0 + cphi * p1 + sphi * p2 - k[23, 1]
                reached[i, row] = True
                _store(turns, i, row, cm, sm, c2, s2, c3, s3)
                singular = singular or free
        return singular
    yx, yy, yz, dd, ratio = _meeting_elbow(k, ctx, cty, ctz)
    if abs(ratio) > 1.0 + CLAMP:
        _fill(values, i, 1.0 + CLAMP - abs(ratio))
        return False
    for first in range(2):
        c3, s3, xx, xy, xz, gx, gy, gz = _meeting_third(k, ratio, first)
        mx, my, mz, gamma2, margin = _meeting_cone(k, xx, xy, xz, yx, yy, yz, dd)
        if margin < 0.0:
            values[i, 2 * first] = values[i, 2 * first + 1] = margin
            continue
        for second in range(2):
            free, cm, sm, c2, s2 = _meeting_angles(
                k, xx, xy, xz, yx, yy, yz, mx, my, mz, gamma2, second, fill
            )
            row = 2 * first + second
            values[i, row] = _meeting_residual(k, gx, gy, gz, c2, s2, dx, dy, dz, cm, sm)
            reached[i, row] = True
            _store(turns, i, row, cm, sm, c2, s2, c3, s3)
            singular = singular or free
    return singular


@inline
def _store(turns, i, row, cm, sm, c2, s2, c3, s3):
    turns[i, row, 0], turns[i, row, 1], turns[i, row, 2] = cm, sm, c2
    turns[i, row, 3], turns[i, row, 4], turns[i, row, 5] = s2, c3, s3


@inline
def _fill(values, i, margin):
    """Row ``i`` of ``values`` (·, 4) set to ``margin``."""
    for b in range(4):
        values[i, b] = margin


@jit
def value(k, pre, theta, b, fill):
    """(f_b(θ6), ok) at ``theta`` [rad]."""
    out = branch(k, pre, math.cos(theta), math.sin(theta), b, fill)
    return out[0], out[1]
