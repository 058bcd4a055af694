"""The 1-D search closed form of one pose, compiled (numba): every solution of a 6R arm whose
axes 4 and 5 meet while axis 6 misses that point, and the one nearest a reference, for
:class:`~kinplan.ik.wrist_offset.OffsetWristIK`.

The roots θ6 of the branch residuals come from :func:`~kinplan.ik.wrist_offset_search.search`;
at each, θ1–θ3 are the branch's (:func:`~kinplan.ik.wrist_offset_branches.branch`), θ4 turns
h5 onto ``W h5`` (subproblem 1) and θ5 the rest of ``W = R4 R5`` (subproblem 1 on a vector
across axis 5). Each solution is checked by forward kinematics (product of exponentials) and
kept only within :data:`VERIFY_TOL`. Up to :data:`SLOTS` solutions, sorted by branch then θ6.
The choice of the nearest solution is that of :meth:`kinplan.ik.ClosedFormIK.nearest` (per
joint the 2π-equivalent within the limits nearest the reference, then the least weighted
distance, ties to the lower row).

Modules: :mod:`~kinplan.ik.wrist_offset_geometry` → :mod:`~kinplan.ik.wrist_offset_branches`
→ :mod:`~kinplan.ik.wrist_offset_search` → ``wrist_offset_kernel`` →
:mod:`~kinplan.ik.wrist_offset`. Without numba, or with ``KINPLAN_JIT=0`` at import, the same
functions run as plain Python (about a thousand times slower).
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.compiled import numba, product_into, rotation_about
from kinplan.ik import wrist_offset_branches
from kinplan.ik.screws import TAU
from kinplan.ik.spherical_wrist_kernel import nearest_of, pose_finite
from kinplan.ik.wrist_offset_branches import angle_to, branch, jit, prepare, turn, wrap
from kinplan.ik.wrist_offset_search import search

#: Solution slots per pose (NaN rows past the solutions found).
SLOTS = 16
#: Largest FK miss of a returned solution [m], and of its rotation (Frobenius, ~rad).
VERIFY_TOL = 1e-9
#: What :func:`nearest` returns for an input with a NaN or inf (the caller reports it).
NOT_FINITE = -2


def available() -> bool:
    """Whether the kernel runs compiled (numba installed and ``KINPLAN_JIT`` not 0)."""
    return wrist_offset_branches.ENABLED and numba is not None


# ---------------------------------------------------------------------------- solutions
@jit
def _solution(k, pre, theta6, b, fill, q, cs):
    """The joint angles [rad] of root ``theta6`` of branch ``b``, written into ``q`` (6,), and
    their cosines and sines into ``cs`` (6, 2)."""
    c6, s6 = math.cos(theta6), math.sin(theta6)
    _, _, _, cm, sm, c2, s2, c3, s3 = branch(k, pre, c6, s6, b, fill)
    # W h5 = R3ᵀ R2ᵀ R1ᵀ (R_T R_Mᵀ R6ᵀ h5), W x5 likewise
    wx = pre[3, 0] + c6 * pre[4, 0] + s6 * pre[5, 0]
    wy = pre[3, 1] + c6 * pre[4, 1] + s6 * pre[5, 1]
    wz = pre[3, 2] + c6 * pre[4, 2] + s6 * pre[5, 2]
    ux = pre[6, 0] + c6 * pre[7, 0] + s6 * pre[8, 0]
    uy = pre[6, 1] + c6 * pre[7, 1] + s6 * pre[8, 1]
    uz = pre[6, 2] + c6 * pre[7, 2] + s6 * pre[8, 2]
    wx, wy, wz = turn(k, 0, wx, wy, wz, cm, sm)
    wx, wy, wz = turn(k, 1, wx, wy, wz, c2, -s2)
    wx, wy, wz = turn(k, 2, wx, wy, wz, c3, -s3)
    ux, uy, uz = turn(k, 0, ux, uy, uz, cm, sm)
    ux, uy, uz = turn(k, 1, ux, uy, uz, c2, -s2)
    ux, uy, uz = turn(k, 2, ux, uy, uz, c3, -s3)
    c4, s4, _ = angle_to(k, 3, k[4, 0], k[4, 1], k[4, 2], wx, wy, wz)
    ux, uy, uz = turn(k, 3, ux, uy, uz, c4, -s4)
    c5, s5, _ = angle_to(k, 4, k[22, 0], k[22, 1], k[22, 2], ux, uy, uz)
    q[0] = math.atan2(-sm, cm)
    q[1] = math.atan2(s2, c2)
    q[2] = math.atan2(s3, c3)
    q[3] = math.atan2(s4, c4)
    q[4] = math.atan2(s5, c5)
    q[5] = wrap(theta6)
    cs[0, 0], cs[0, 1], cs[1, 0], cs[1, 1] = cm, -sm, c2, s2
    cs[2, 0], cs[2, 1], cs[3, 0], cs[3, 1] = c3, s3, c4, s4
    cs[4, 0], cs[4, 1], cs[5, 0], cs[5, 1] = c5, s5, c6, s6


@jit
def _reaches(k, tool, cs, position, rotation, work):
    """Whether the configuration of cosines and sines ``cs`` (6, 2) puts the tool at the pose
    within :data:`VERIFY_TOL`: the product of exponentials ``e1 ⋯ e6 M`` (``work`` (3, 3, 3)
    scratch)."""
    turned, step, product = work[0], work[1], work[2]
    tx = ty = tz = 0.0
    for i in range(3):
        for j in range(3):
            turned[i, j] = 1.0 if i == j else 0.0
    for joint in range(6):
        rotation_about(k[joint], cs[joint, 0], cs[joint, 1], step)
        px, py, pz = k[6 + joint, 0], k[6 + joint, 1], k[6 + joint, 2]
        sx = px - (step[0, 0] * px + step[0, 1] * py + step[0, 2] * pz)
        sy = py - (step[1, 0] * px + step[1, 1] * py + step[1, 2] * pz)
        sz = pz - (step[2, 0] * px + step[2, 1] * py + step[2, 2] * pz)
        tx += turned[0, 0] * sx + turned[0, 1] * sy + turned[0, 2] * sz
        ty += turned[1, 0] * sx + turned[1, 1] * sy + turned[1, 2] * sz
        tz += turned[2, 0] * sx + turned[2, 1] * sy + turned[2, 2] * sz
        product_into(turned, step, product)
        turned[:, :] = product
    mx, my, mz = tool[0, 3], tool[1, 3], tool[2, 3]
    miss = (turned[0, 0] * mx + turned[0, 1] * my + turned[0, 2] * mz + tx - position[0]) ** 2
    miss += (turned[1, 0] * mx + turned[1, 1] * my + turned[1, 2] * mz + ty - position[1]) ** 2
    miss += (turned[2, 0] * mx + turned[2, 1] * my + turned[2, 2] * mz + tz - position[2]) ** 2
    spin = 0.0
    for i in range(3):
        for j in range(3):
            reached = turned[i, 0] * tool[0, j] + turned[i, 1] * tool[1, j]
            spin += (reached + turned[i, 2] * tool[2, j] - rotation[i, j]) ** 2
    return miss <= VERIFY_TOL * VERIFY_TOL and spin <= 2.0 * VERIFY_TOL * VERIFY_TOL


@jit
def branches(k, tool, position, rotation, fill, raw, ok):
    """Every solution of one pose: rows of ``raw`` (SLOTS, 6) [rad] (wrapped into [−π, π]),
    sorted by branch then θ6, with ``ok`` (SLOTS,) where a row holds one.

    Args:
        k: The packed geometry (:meth:`OffsetWristGeometry.constants
            <kinplan.ik.wrist_offset_geometry.OffsetWristGeometry.constants>`), (36, 3).
        tool: The tool pose at q = 0 (4, 4).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        fill: Values [rad] (6,) of θ1, θ2 where they are free (the meeting point of axes 4, 5
            on axis 1, or on axis 2's elbow centre).
        raw, ok: Written.

    Returns:
        Whether some joint was free (took its ``fill`` value) at a sample or root.
    """
    pre = np.empty((9, 3))
    prepare(k, position, rotation, pre)
    roots = np.empty(SLOTS)
    branch_of = np.empty(SLOTS, dtype=np.int64)
    count, singular = search(k, pre, fill, roots, branch_of)
    order = np.argsort(branch_of[:count] * 16.0 + (roots[:count] + math.pi) / TAU, kind="mergesort")
    work = np.empty((3, 3, 3))
    q = np.empty(6)
    cs = np.empty((6, 2))
    row = 0
    for r in order:
        _solution(k, pre, roots[r], branch_of[r], fill, q, cs)
        if _reaches(k, tool, cs, position, rotation, work):
            raw[row] = q
            ok[row] = True
            row += 1
    for r in range(row, SLOTS):
        ok[r] = False
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
