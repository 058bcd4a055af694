"""The closed form of a spherical-wrist 6R arm with axes 2 ∦ 3 for one pose, compiled (numba):
every solution, and the one nearest a reference, for
:class:`~kinplan.ik.spherical_general.GeneralWristIK`.

With ``T(q) = e1 ⋯ e6 M`` and ``c`` the wrist centre (which e4, e5, e6 leave in place), the
target's wrist centre ``c_T = p_T + R_T R_Mᵀ(c − p_M)`` is ``e1 e2 e3 c``: the first three
joints place it by the mode's subproblems (:mod:`~kinplan.ik.spherical_general_positions`,
polished by Newton steps); positions that still miss ``c_T`` by more than
:data:`~kinplan.ik.wrist_offset_kernel.VERIFY_TOL` are dropped, and in the general mode a
position equal to an earlier one (:data:`SAME`). The wrist is that of the spherical-wrist
kernel (:mod:`~kinplan.ik.spherical_wrist_kernel`): θ4, θ5 by subproblem 2 from
``R4 R5 h6 = W h6``, ``W = (R1 R2 R3)ᵀ R_T R_Mᵀ`` (at the wrist singularity θ4 takes the
reference's value, :func:`~kinplan.ik.spherical_wrist_kernel.free_wrist`), θ6 by subproblem 1.

Row ``2·position + wrist`` of :data:`SLOTS`; every row is checked by forward kinematics (the
product of exponentials, as ``e4 e5 e6 M = (e1 e2 e3)⁻¹ T``) to
:data:`~kinplan.ik.wrist_offset_kernel.VERIFY_TOL` and kept only then. The nearest solution
is chosen as :meth:`kinplan.ik.ClosedFormIK.nearest` does
(:func:`~kinplan.ik.spherical_wrist_kernel.nearest_of`).

Modules, each importing only those before it: :mod:`~kinplan.ik.spherical_general_geometry`
→ :mod:`~kinplan.ik.spherical_general_quartic` → :mod:`~kinplan.ik.spherical_general_positions`
→ ``spherical_general_kernel`` → :mod:`~kinplan.ik.spherical_general`. Without numba, or with
``KINPLAN_JIT=0`` at import, the same functions run as plain Python (slowly).
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.compiled import numba
from kinplan.ik import wrist_offset_branches
from kinplan.ik.screws import CLAMP, FREE_TOL
from kinplan.ik.spherical_general_geometry import GENERAL, MEETING_12
from kinplan.ik.spherical_general_positions import (
    CANDIDATES,
    POSITIONS,
    general_shoulder,
    meeting_12,
    meeting_23,
    off_axis2,
    polish,
    rotated,
)
from kinplan.ik.spherical_wrist_kernel import free_wrist, nearest_of, pose_finite
from kinplan.ik.wrist_offset_branches import angle_to, inline, jit, turn, wrap
from kinplan.ik.wrist_offset_kernel import VERIFY_TOL

#: Solution rows per pose: 4 positions × 2 wrists (NaN rows where none).
SLOTS = 8
#: What :func:`nearest` returns for an input with a NaN or inf (the caller reports it).
NOT_FINITE = -2
#: Two positions closer than this [rad] on θ1, θ2 and θ3 are one (subproblem 5's mirrors).
SAME = 1e-9


def available() -> bool:
    """Whether the kernel runs compiled (numba installed and ``KINPLAN_JIT`` not 0)."""
    return wrist_offset_branches.ENABLED and numba is not None


# ---------------------------------------------------------------------------- every solution
@jit
def branches(k, tool, limits, position, rotation, fill, raw, ok, cand, valid, work):
    """Every solution of one pose: rows ``2·position + wrist`` of ``raw`` (SLOTS, 6) [rad]
    (wrapped into [−π, π]) with ``ok`` (SLOTS,) where a row holds one, each within
    :data:`VERIFY_TOL` of the pose by forward kinematics (rows without one hold garbage).

    Args:
        k: The packed geometry (:meth:`GeneralWristGeometry.constants
            <kinplan.ik.spherical_general_geometry.GeneralWristGeometry.constants>`), (24, 3).
        tool: The tool pose at q = 0 (4, 4).
        limits: Rows lower, upper [rad] (and weights), shape (3, 6): for θ4 at the wrist
            singularity.
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        fill: Values [rad] (6,) of joints that are free at a singularity (θ1, θ2, θ4).
        raw, ok: Written.
        cand, valid: Scratch, (CANDIDATES, 9) and (CANDIDATES,).
        work: Scratch, (8, 10).

    Returns:
        Whether some joint was free (took its ``fill`` value).
    """
    for r in range(SLOTS):
        ok[r] = False
    for r in range(CANDIDATES):
        valid[r] = False
    # the target's wrist centre
    ctx, cty, ctz = position[0], position[1], position[2]
    for j in range(3):
        ctx += rotation[0, j] * k[13, j]
        cty += rotation[1, j] * k[13, j]
        ctz += rotation[2, j] * k[13, j]
    mode = int(k[17, 0])
    if mode == GENERAL:
        count, singular = general_shoulder(k, ctx, cty, ctz, rotation, fill, cand, valid, work)
    elif mode == MEETING_12:
        count, singular = POSITIONS, meeting_12(k, ctx, cty, ctz, rotation, fill, cand, valid)
    else:
        count, singular = POSITIONS, meeting_23(k, ctx, cty, ctz, rotation, fill, cand, valid)
    slot = 0
    t = work[7]
    for j in range(count):
        if mode != GENERAL:
            slot = j
        if not valid[j] or slot >= POSITIONS:
            continue
        for i in range(9):
            t[i] = cand[j, i]
        if polish(k, ctx, cty, ctz, t) > VERIFY_TOL:
            continue
        if mode == GENERAL:
            repeated = False
            for r in range(slot):
                repeated = repeated or (
                    abs(wrap(raw[2 * r, 0] - t[0])) < SAME
                    and abs(wrap(raw[2 * r, 1] - t[1])) < SAME
                    and abs(wrap(raw[2 * r, 2] - t[2])) < SAME
                )
            if repeated:
                continue
        free = _wrist(k, tool, limits, position, rotation, fill, t, slot, raw, ok)
        singular = singular or free
        slot += 1
    return singular


@inline
def _wrist(k, tool, limits, position, rotation, fill, t, slot, raw, ok):
    """The two wrist rows of position ``t`` (θ1, θ2, θ3) [rad] in slot ``slot``, each kept
    only within :data:`VERIFY_TOL` of the pose by FK (``ok``); returns whether θ4 was free.
    Both rows get the position's θ1–θ3 even where no wrist is kept (the general mode's check
    of repeated positions reads them)."""
    c1, s1, c2, s2, c3, s3 = t[3], t[4], t[5], t[6], t[7], t[8]
    for wr in range(2):
        raw[2 * slot + wr, 0] = t[0]
        raw[2 * slot + wr, 1] = t[1]
        raw[2 * slot + wr, 2] = t[2]
    seen = _seen(k, position, rotation, c1, s1, c2, s2, c3, s3)
    # W h6, W x6 with W = (R1 R2 R3)ᵀ R_T R_Mᵀ
    ax, ay, az = rotated(rotation, k, 14)
    ax, ay, az = turn(k, 0, ax, ay, az, c1, -s1)
    ax, ay, az = turn(k, 1, ax, ay, az, c2, -s2)
    ax, ay, az = turn(k, 2, ax, ay, az, c3, -s3)
    bx, by, bz = rotated(rotation, k, 15)
    bx, by, bz = turn(k, 0, bx, by, bz, c1, -s1)
    bx, by, bz = turn(k, 1, bx, by, bz, c2, -s2)
    bx, by, bz = turn(k, 2, bx, by, bz, c3, -s3)
    # subproblem 2: R(h5, θ5) h6 = R(h4, −θ4) W h6
    kq = ax * k[3, 0] + ay * k[3, 1] + az * k[3, 2]
    kp5 = k[5, 0] * k[4, 0] + k[5, 1] * k[4, 1] + k[5, 2] * k[4, 2]
    c45, n2 = k[17, 1], k[17, 2]
    alpha = (kp5 - c45 * kq) / n2
    beta = (kq - c45 * kp5) / n2
    length2 = 0.5 * (1.0 + ax * ax + ay * ay + az * az)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c45
    if rest < -CLAMP * length2:
        return False
    gamma = math.sqrt(max(rest, 0.0) / n2)
    free4 = off_axis2(k, 3, ax, ay, az) < FREE_TOL * FREE_TOL
    for wr in range(2):
        g = gamma if wr == 0 else -gamma
        if free4:  # on the free wrist, z = W h6 exactly
            zx, zy, zz = ax, ay, az
        else:
            zx = alpha * k[4, 0] + beta * k[3, 0] + g * k[18, 0]
            zy = alpha * k[4, 1] + beta * k[3, 1] + g * k[18, 1]
            zz = alpha * k[4, 2] + beta * k[3, 2] + g * k[18, 2]
        c5, s5, _ = angle_to(k, 4, k[5, 0], k[5, 1], k[5, 2], zx, zy, zz)
        if free4:
            c4, s4 = 1.0, 0.0  # of −θ4
        else:
            c4, s4, _ = angle_to(k, 3, ax, ay, az, zx, zy, zz)
        # θ6: R(h6, θ6) x6 = R5ᵀ R4ᵀ W x6
        ux, uy, uz = turn(k, 3, bx, by, bz, c4, s4)
        ux, uy, uz = turn(k, 4, ux, uy, uz, c5, -s5)
        c6, s6, _ = angle_to(k, 5, k[16, 0], k[16, 1], k[16, 2], ux, uy, uz)
        t4 = math.atan2(-s4, c4)  # in [−π, π]
        t6 = math.atan2(s6, c6)
        if free4:  # θ4 + σ·θ6 fixed
            sigma = 1.0 if kq >= 0.0 else -1.0
            t4 = free_wrist(t6, sigma, fill[3], limits[0, 3], limits[1, 3],
                            limits[0, 5], limits[1, 5])  # fmt: skip
            t6 = wrap(t6 - sigma * t4)
            t4 = wrap(t4)
            c4, s4 = math.cos(t4), -math.sin(t4)
            c6, s6 = math.cos(t6), math.sin(t6)
        row = 2 * slot + wr
        raw[row, 3] = t4
        raw[row, 4] = math.atan2(s5, c5)
        raw[row, 5] = t6
        ok[row] = _reaches(k, tool, seen, c4, -s4, c5, s5, c6, s6)
    return free4


# ---------------------------------------------------------------------------- FK check
@inline
def _about(k, row, x, y, z, c, s):
    """The point (x, y, z) turned about the line of joint ``row`` (axis ``k[row]`` through
    ``k[6 + row]``) by the angle of cosine ``c``, sine ``s``."""
    px, py, pz = k[6 + row, 0], k[6 + row, 1], k[6 + row, 2]
    x, y, z = turn(k, row, x - px, y - py, z - pz, c, s)
    return x + px, y + py, z + pz


@inline
def _seen(k, position, rotation, c1, s1, c2, s2, c3, s3):
    """The target pose seen through ``(e1 e2 e3)⁻¹`` at θ1–θ3 (cosines, sines): its position
    and the first two columns of its rotation, nine floats."""
    px, py, pz = _about(k, 0, position[0], position[1], position[2], c1, -s1)
    px, py, pz = _about(k, 1, px, py, pz, c2, -s2)
    px, py, pz = _about(k, 2, px, py, pz, c3, -s3)
    ax, ay, az = turn(k, 0, rotation[0, 0], rotation[1, 0], rotation[2, 0], c1, -s1)
    ax, ay, az = turn(k, 1, ax, ay, az, c2, -s2)
    ax, ay, az = turn(k, 2, ax, ay, az, c3, -s3)
    bx, by, bz = turn(k, 0, rotation[0, 1], rotation[1, 1], rotation[2, 1], c1, -s1)
    bx, by, bz = turn(k, 1, bx, by, bz, c2, -s2)
    bx, by, bz = turn(k, 2, bx, by, bz, c3, -s3)
    return px, py, pz, ax, ay, az, bx, by, bz


@inline
def _reaches(k, tool, seen, c4, s4, c5, s5, c6, s6):
    """Whether the configuration puts the tool at the target within :data:`VERIFY_TOL`
    (position [m]; rotation in Frobenius norm, ≤ √2·VERIFY_TOL as the other kernels): forward
    kinematics as ``e4 e5 e6 M = (e1 e2 e3)⁻¹ T`` (both sides products of exponentials; the
    right one is ``seen``, :func:`_seen`'s, shared by the two wrists)."""
    px, py, pz = _about(k, 5, tool[0, 3], tool[1, 3], tool[2, 3], c6, s6)
    px, py, pz = _about(k, 4, px, py, pz, c5, s5)
    px, py, pz = _about(k, 3, px, py, pz, c4, s4)
    ax, ay, az = turn(k, 5, tool[0, 0], tool[1, 0], tool[2, 0], c6, s6)
    ax, ay, az = turn(k, 4, ax, ay, az, c5, s5)
    ax, ay, az = turn(k, 3, ax, ay, az, c4, s4)
    bx, by, bz = turn(k, 5, tool[0, 1], tool[1, 1], tool[2, 1], c6, s6)
    bx, by, bz = turn(k, 4, bx, by, bz, c5, s5)
    bx, by, bz = turn(k, 3, bx, by, bz, c4, s4)
    qx, qy, qz, ex, ey, ez, fx, fy, fz = seen
    miss = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
    spin = (ax - ex) ** 2 + (ay - ey) ** 2 + (az - ez) ** 2
    spin += (bx - fx) ** 2 + (by - fy) ** 2 + (bz - fz) ** 2
    # the third columns: cross products of the first two, on both sides
    spin += (ay * bz - az * by - (ey * fz - ez * fy)) ** 2
    spin += (az * bx - ax * bz - (ez * fx - ex * fz)) ** 2
    spin += (ax * by - ay * bx - (ex * fy - ey * fx)) ** 2
    return miss <= VERIFY_TOL * VERIFY_TOL and spin <= 2.0 * VERIFY_TOL * VERIFY_TOL


# ---------------------------------------------------------------------------- many poses
@inline
def _take(position, rotation, ref, p, r, f):
    """Copy a pose and its reference into the scratch arrays ``p`` (3,), ``r`` (3, 3), ``f``
    (6,): :func:`branches` then always sees writable C arrays, and numba compiles it once
    (read-only inputs, as ``np.broadcast_to``'s, would each compile it again)."""
    for i in range(3):
        p[i] = position[i]
        for j in range(3):
            r[i, j] = rotation[i, j]
    for j in range(6):
        f[j] = ref[j]


@jit
def raw_many(k, tool, limits, positions, rotations, fills, raw, singular):
    """:func:`branches` of many poses: ``raw`` (N, SLOTS, 6) [rad] with NaN rows where no
    solution, ``singular`` (N,)."""
    ok = np.empty(SLOTS, dtype=np.bool_)
    cand = np.empty((CANDIDATES, 9))
    valid = np.empty(CANDIDATES, dtype=np.bool_)
    work = np.empty((8, 10))
    p, r, f, rows = np.empty(3), np.empty((3, 3)), np.empty(6), np.empty((SLOTS, 6))
    for n in range(positions.shape[0]):
        _take(positions[n], rotations[n], fills[n], p, r, f)
        singular[n] = branches(k, tool, limits, p, r, f, rows, ok, cand, valid, work)
        for row in range(SLOTS):
            for j in range(6):
                raw[n, row, j] = rows[row, j] if ok[row] else np.nan


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
    cand = np.empty((CANDIDATES, 9))
    valid = np.empty(CANDIDATES, dtype=np.bool_)
    p, r, f = np.empty(3), np.empty((3, 3)), np.empty(6)
    _take(position, rotation, ref, p, r, f)
    branches(k, tool, limits, p, r, f, raw, ok, cand, valid, np.empty((8, 10)))
    best, _ = nearest_of(raw, ok, limits, f, out)
    return best


@jit
def nearest_many(k, tool, limits, positions, rotations, refs, q, row, mask):
    """:func:`nearest` of many poses, each with its own reference: ``q`` (N, 6), ``row`` (N,)
    (−1: none) and ``mask`` (N,) (bit r: row r within the limits) written."""
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    cand = np.empty((CANDIDATES, 9))
    valid = np.empty(CANDIDATES, dtype=np.bool_)
    work = np.empty((8, 10))
    out = np.empty(6)
    p, r, f = np.empty(3), np.empty((3, 3)), np.empty(6)
    for n in range(positions.shape[0]):
        _take(positions[n], rotations[n], refs[n], p, r, f)
        branches(k, tool, limits, p, r, f, raw, ok, cand, valid, work)
        best, bits = nearest_of(raw, ok, limits, f, out)
        row[n] = best
        mask[n] = bits
        for j in range(6):
            q[n, j] = out[j] if best >= 0 else np.nan
