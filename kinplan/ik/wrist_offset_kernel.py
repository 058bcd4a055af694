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

from kinplan.compiled import numba
from kinplan.ik import wrist_offset_branches
from kinplan.ik.screws import TAU
from kinplan.ik.spherical_wrist_kernel import _choice, branch_cost, nearest_of, pose_finite
from kinplan.ik.wrist_offset_branches import (
    angle_to3,
    branch,
    branch_geometry,
    geometry,
    inline,
    jit,
    pose_terms,
    turn3,
    wrap,
)
from kinplan.ik.wrist_offset_search import search, workspace

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
@inline
def _solution(k, search_k, pre, theta6, b, fill, known):
    """The joint angles [rad] (a 6-tuple) of root ``theta6`` of branch ``b``, and their
    cosines and sines (cos θ1, sin θ1, …, cos θ6, sin θ6). ``k`` is the geometry as tuples
    (:func:`geometry`), ``search_k`` the branches' rows of it (:func:`branch_geometry`);
    ``known``: cos, sin of θ6, −θ1, θ2, θ3 at the root as the search found them (the same
    branch evaluation), or NaN where it did not evaluate the branch there."""
    if known[0] == known[0]:
        c6, s6, cm, sm, c2, s2, c3, s3 = known
    else:
        c6, s6 = math.cos(theta6), math.sin(theta6)
        moving = (pre[0], pre[1], pre[2], pre[3], pre[4], pre[5])
        _, _, _, cm, sm, c2, s2, c3, s3 = branch(search_k, moving, c6, s6, b, fill)
    # W h5 = R3ᵀ R2ᵀ R1ᵀ (R_T R_Mᵀ R6ᵀ h5), W x5 likewise
    wx = pre[3][0] + c6 * pre[4][0] + s6 * pre[5][0]
    wy = pre[3][1] + c6 * pre[4][1] + s6 * pre[5][1]
    wz = pre[3][2] + c6 * pre[4][2] + s6 * pre[5][2]
    ux = pre[6][0] + c6 * pre[7][0] + s6 * pre[8][0]
    uy = pre[6][1] + c6 * pre[7][1] + s6 * pre[8][1]
    uz = pre[6][2] + c6 * pre[7][2] + s6 * pre[8][2]
    wx, wy, wz = turn3(k[0], wx, wy, wz, cm, sm)
    wx, wy, wz = turn3(k[1], wx, wy, wz, c2, -s2)
    wx, wy, wz = turn3(k[2], wx, wy, wz, c3, -s3)
    ux, uy, uz = turn3(k[0], ux, uy, uz, cm, sm)
    ux, uy, uz = turn3(k[1], ux, uy, uz, c2, -s2)
    ux, uy, uz = turn3(k[2], ux, uy, uz, c3, -s3)
    c4, s4, _ = angle_to3(k[3], k[4][0], k[4][1], k[4][2], wx, wy, wz)
    ux, uy, uz = turn3(k[3], ux, uy, uz, c4, -s4)
    c5, s5, _ = angle_to3(k[4], k[22][0], k[22][1], k[22][2], ux, uy, uz)
    q = (
        math.atan2(-sm, cm), math.atan2(s2, c2), math.atan2(s3, c3), math.atan2(s4, c4),
        math.atan2(s5, c5), wrap(theta6),
    )  # fmt: skip
    return q, (cm, -sm, c2, s2, c3, s3, c4, s4, c5, s5, c6, s6)


@inline
def _screw_exp(k, joint, c, s):
    """The exponential of joint j = ``joint`` at cos θ = c, sin θ = s: its rotation (9
    entries, row by row; Rodrigues about the unit axis ``k[joint]``) and translation
    ``p − R p`` [m] (the axis through ``p = k[6 + joint]``). Scalars only."""
    x, y, z = k[joint][0], k[joint][1], k[joint][2]
    t = 1.0 - c
    a00, a01, a02 = c + x * x * t, x * y * t - z * s, x * z * t + y * s
    a10, a11, a12 = y * x * t + z * s, c + y * y * t, y * z * t - x * s
    a20, a21, a22 = z * x * t - y * s, z * y * t + x * s, c + z * z * t
    px, py, pz = k[6 + joint][0], k[6 + joint][1], k[6 + joint][2]
    sx = px - (a00 * px + a01 * py + a02 * pz)
    sy = py - (a10 * px + a11 * py + a12 * pz)
    sz = pz - (a20 * px + a21 * py + a22 * pz)
    return (a00, a01, a02, a10, a11, a12, a20, a21, a22), sx, sy, sz


@inline
def _screw_step(k, joint, c, s, rot, tx, ty, tz):
    """One factor of the product of exponentials: with ``rot`` (9 entries, row by row) and
    (tx, ty, tz) [m] the rotation and translation of ``e1 ⋯ e(j−1)``, those of ``e1 ⋯ ej`` for
    joint j = ``joint`` at cos θ = c, sin θ = s (:func:`_screw_exp`). Scalars only, no scratch
    array."""
    (a00, a01, a02, a10, a11, a12, a20, a21, a22), sx, sy, sz = _screw_exp(k, joint, c, s)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot
    tx += r00 * sx + r01 * sy + r02 * sz
    ty += r10 * sx + r11 * sy + r12 * sz
    tz += r20 * sx + r21 * sy + r22 * sz
    return (
        (
            r00 * a00 + r01 * a10 + r02 * a20,
            r00 * a01 + r01 * a11 + r02 * a21,
            r00 * a02 + r01 * a12 + r02 * a22,
            r10 * a00 + r11 * a10 + r12 * a20,
            r10 * a01 + r11 * a11 + r12 * a21,
            r10 * a02 + r11 * a12 + r12 * a22,
            r20 * a00 + r21 * a10 + r22 * a20,
            r20 * a01 + r21 * a11 + r22 * a21,
            r20 * a02 + r21 * a12 + r22 * a22,
        ),
        tx,
        ty,
        tz,
    )


@inline
def _reaches(k, tool, cs, position, rotation):
    """Whether the configuration of cosines and sines ``cs`` (cos θ1, sin θ1, …, cos θ6,
    sin θ6) puts the tool at the pose within :data:`VERIFY_TOL`: the product of exponentials
    ``e1 ⋯ e6 M``, in scalars."""
    # joint 1 from the identity: its exponential itself (the products by 1 and 0 left out:
    # numba keeps them, x·0 being NaN for an infinite x)
    rot, tx, ty, tz = _screw_exp(k, 0, cs[0], cs[1])
    rot, tx, ty, tz = _screw_step(k, 1, cs[2], cs[3], rot, tx, ty, tz)
    rot, tx, ty, tz = _screw_step(k, 2, cs[4], cs[5], rot, tx, ty, tz)
    rot, tx, ty, tz = _screw_step(k, 3, cs[6], cs[7], rot, tx, ty, tz)
    rot, tx, ty, tz = _screw_step(k, 4, cs[8], cs[9], rot, tx, ty, tz)
    rot, tx, ty, tz = _screw_step(k, 5, cs[10], cs[11], rot, tx, ty, tz)
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = rot
    mx, my, mz = tool[0][3], tool[1][3], tool[2][3]
    miss = (r00 * mx + r01 * my + r02 * mz + tx - position[0]) ** 2
    miss += (r10 * mx + r11 * my + r12 * mz + ty - position[1]) ** 2
    miss += (r20 * mx + r21 * my + r22 * mz + tz - position[2]) ** 2
    spin = 0.0
    for j in range(3):
        t0, t1, t2 = tool[0][j], tool[1][j], tool[2][j]
        spin += (r00 * t0 + r01 * t1 + r02 * t2 - rotation[0][j]) ** 2
        spin += (r10 * t0 + r11 * t1 + r12 * t2 - rotation[1][j]) ** 2
        spin += (r20 * t0 + r21 * t1 + r22 * t2 - rotation[2][j]) ** 2
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
        raw, ok: Written (a row whose ``ok`` is False holds no solution: anything).

    Returns:
        Whether some joint was free (took its ``fill`` value) at a sample or root.
    """
    roots, branch_of = np.empty((SLOTS, 9)), np.empty(SLOTS, dtype=np.int64)
    p, r, f = _one_pose(position, rotation, fill)
    return _branches(geometry(k), _tool(tool), p, r, f, raw, ok, roots, branch_of, workspace())


@jit
def _tool(tool):
    """The tool pose (4, 4) as a tuple of its first three rows (4-tuples)."""
    return (
        (tool[0, 0], tool[0, 1], tool[0, 2], tool[0, 3]),
        (tool[1, 0], tool[1, 1], tool[1, 2], tool[1, 3]),
        (tool[2, 0], tool[2, 1], tool[2, 2], tool[2, 3]),
    )


@inline
def _pose(positions, rotations, fills, n):
    """Pose n of the arrays (N, 3), (N, 3, 3), (N, 6) as tuples: position, rotation (rows),
    the fill values of θ1, θ2 (read by index: a row taken out, ``positions[n]``, would be a new
    array, reference counted)."""
    return (
        (positions[n, 0], positions[n, 1], positions[n, 2]),
        (
            (rotations[n, 0, 0], rotations[n, 0, 1], rotations[n, 0, 2]),
            (rotations[n, 1, 0], rotations[n, 1, 1], rotations[n, 1, 2]),
            (rotations[n, 2, 0], rotations[n, 2, 1], rotations[n, 2, 2]),
        ),
        (fills[n, 0], fills[n, 1]),
    )


@inline
def _one_pose(position, rotation, fill):
    """:func:`_pose` of one pose: position (3,), rotation (3, 3), fill (6,)."""
    return (
        (position[0], position[1], position[2]),
        (
            (rotation[0, 0], rotation[0, 1], rotation[0, 2]),
            (rotation[1, 0], rotation[1, 1], rotation[1, 2]),
            (rotation[2, 0], rotation[2, 1], rotation[2, 2]),
        ),
        (fill[0], fill[1]),
    )


@inline
def _sorted_roots(g, pre, f, roots, branch_of, work):
    """The search's roots of a pose (:func:`~kinplan.ik.wrist_offset_search.search`), sorted
    by branch then θ6 in place: (count, whether a free angle took its fill value, the
    branches' rows of the geometry)."""
    search_k = branch_geometry(g)
    moving = (pre[0], pre[1], pre[2], pre[3], pre[4], pre[5])
    count, singular = search(search_k, moving, f, roots, branch_of, work)
    # sorted by branch then θ6 (insertion sort: stable, ≤ SLOTS roots of 9 columns)
    for i in range(1, count):
        b = branch_of[i]
        key = b * 16.0 + (roots[i, 0] + math.pi) / TAU
        j = i
        while j > 0 and branch_of[j - 1] * 16.0 + (roots[j - 1, 0] + math.pi) / TAU > key:
            j -= 1
        if j == i:
            continue
        held = (
            roots[i, 0], roots[i, 1], roots[i, 2], roots[i, 3], roots[i, 4],
            roots[i, 5], roots[i, 6], roots[i, 7], roots[i, 8],
        )  # fmt: skip
        for m in range(i, j, -1):
            branch_of[m] = branch_of[m - 1]
            for c in range(9):
                roots[m, c] = roots[m - 1, c]
        branch_of[j] = b
        for c in range(9):
            roots[j, c] = held[c]
    return count, singular, search_k


@inline
def _known(roots, i):
    """Columns 1–8 of root i: cos, sin of θ6, −θ1, θ2, θ3 where the search found them."""
    return (
        roots[i, 1], roots[i, 2], roots[i, 3], roots[i, 4],
        roots[i, 5], roots[i, 6], roots[i, 7], roots[i, 8],
    )  # fmt: skip


@jit
def _branches(g, tool, p, r, f, raw, ok, roots, branch_of, work):
    """:func:`branches` of the geometry, the tool and the pose as tuples (:func:`geometry`,
    :func:`_tool`, :func:`_pose`; ``f``: the fill values of θ1, θ2): the search and the
    solutions take them (no array passed per sample, root or solution: no reference
    counts)."""
    pre = pose_terms(g, p, r)
    count, singular, search_k = _sorted_roots(g, pre, f, roots, branch_of, work)
    row = 0
    for i in range(count):
        q, cs = _solution(g, search_k, pre, roots[i, 0], branch_of[i], f, _known(roots, i))
        for j in range(6):
            raw[row, j] = q[j]
        if _reaches(g, tool, cs, p, r):
            ok[row] = True
            row += 1
    for i in range(row, SLOTS):
        ok[i] = False
    return singular


@jit
def raw_many(k, tool, positions, rotations, fills, raw, singular):
    """:func:`branches` of many poses: ``raw`` (N, SLOTS, 6) [rad] with NaN rows where no
    solution, ``singular`` (N,)."""
    ok = np.empty(SLOTS, dtype=np.bool_)
    g, tool_rows = geometry(k), _tool(tool)
    roots, branch_of = np.empty((SLOTS, 9)), np.empty(SLOTS, dtype=np.int64)
    work = workspace()  # allocated once a batch
    for n in range(positions.shape[0]):
        p, r, f = _pose(positions, rotations, fills, n)
        singular[n] = _branches(g, tool_rows, p, r, f, raw[n], ok, roots, branch_of, work)
        for r in range(SLOTS):
            if not ok[r]:
                raw[n, r, :] = np.nan


# ---------------------------------------------------------------------------- the nearest one
@jit
def nearest(k, tool, limits, position, rotation, ref, out):
    """The solution nearest ``ref`` [rad] (6,) written into ``out``, solving only the roots
    that can be nearest (:func:`_lazy_nearest`); returns its root's index among the sorted
    roots, −1 when none is within the limits, :data:`NOT_FINITE` for an input with a NaN or
    inf.

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
    roots, branch_of = np.empty((SLOTS, 9)), np.empty(SLOTS, dtype=np.int64)
    p, r, f = _one_pose(position, rotation, ref)
    refs = (ref[0], ref[1], ref[2], ref[3], ref[4], ref[5])
    return _lazy_nearest(geometry(k), _tool(tool), limits, p, r, f, refs, roots, branch_of,
                         workspace(), np.empty(SLOTS), np.empty((SLOTS, 6)), out)  # fmt: skip


@jit
def nearest_many(k, tool, limits, positions, rotations, refs, q, row, mask):
    """:func:`nearest` of many poses, each with its own reference: ``q`` (N, 6), ``row`` (N,)
    (−1: none) and ``mask`` (N,) (bit r: row r within the limits) written."""
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    out = np.empty(6)
    g, tool_rows = geometry(k), _tool(tool)
    roots, branch_of = np.empty((SLOTS, 9)), np.empty(SLOTS, dtype=np.int64)
    work = workspace()  # allocated once a batch
    for n in range(positions.shape[0]):
        p, r, f = _pose(positions, rotations, refs, n)
        _branches(g, tool_rows, p, r, f, raw, ok, roots, branch_of, work)
        best, bits = nearest_of(raw, ok, limits, refs[n], out)
        row[n] = best
        mask[n] = bits
        for j in range(6):
            q[n, j] = out[j] if best >= 0 else np.nan


@jit
def _lazy_nearest(g, tool, limits, p, r, f, ref, roots, branch_of, work, bounds, raw, out):
    """The solution nearest ``ref`` (written into ``out``) as :func:`nearest_of` chooses it
    among all of :func:`_branches`, solving and checking only the roots that can win: each
    root's cost over θ1, θ2, θ3, θ6 (known from the search: the same angles and the same
    terms as its full cost, in the same order, so never above it) bounds its full cost from
    below; the roots are solved in the order of that bound, until it exceeds the best full
    cost found (ties to the lower root, as to the lower row). Returns the index of the root
    among the sorted roots (its row among the solutions unless a root before it failed the
    FK check), −1 if none is within the limits. ``bounds`` (SLOTS,) and ``raw`` (SLOTS, 6)
    are scratch."""
    pre = pose_terms(g, p, r)
    count, _, search_k = _sorted_roots(g, pre, f, roots, branch_of, work)
    for i in range(count):
        bounds[i] = 0.0  # not known: solved in its turn
        if roots[i, 1] != roots[i, 1]:
            continue
        cm, sm, c2, s2, c3, s3 = (
            roots[i, 3],
            roots[i, 4],
            roots[i, 5],
            roots[i, 6],
            roots[i, 7],
            roots[i, 8],
        )
        partial = (math.atan2(-sm, cm), math.atan2(s2, c2), math.atan2(s3, c3), wrap(roots[i, 0]))
        cost = 0.0
        for j, joint in enumerate((0, 1, 2, 5)):
            value = _choice(partial[j], ref[joint], limits[0, joint], limits[1, joint])
            if value != value:
                cost = np.inf
                break
            cost += limits[2, joint] * (value - ref[joint]) * (value - ref[joint])
        bounds[i] = cost
    best, best_cost = -1, np.inf
    for _ in range(count):
        i = -1
        for m in range(count):  # the least bound left, ties to the lower root
            if bounds[m] == bounds[m] and (i < 0 or bounds[m] < bounds[i]):
                i = m
        if i < 0 or bounds[i] > best_cost or bounds[i] == np.inf:
            break
        bounds[i] = np.nan  # taken
        q, cs = _solution(g, search_k, pre, roots[i, 0], branch_of[i], f, _known(roots, i))
        if not _reaches(g, tool, cs, p, r):
            continue
        for joint in range(6):
            raw[i, joint] = q[joint]
        cost = branch_cost(raw, i, limits, ref, 0.0)
        if cost < best_cost or (cost == best_cost and cost < np.inf and i < best):
            best, best_cost = i, cost
    if best >= 0:
        for joint in range(6):
            out[joint] = _choice(raw[best, joint], ref[joint], limits[0, joint], limits[1, joint])
    return best


@jit
def nearest_lazy_many(k, tool, limits, positions, rotations, refs, q, row, mask):
    """:func:`nearest_many` without the masks (``mask`` written 0), solving only the roots
    that can be nearest (:func:`_lazy_nearest`): the same ``q``; ``row`` the nearest root's
    index among the sorted roots (−1: none)."""
    out = np.empty(6)
    bounds, raw = np.empty(SLOTS), np.empty((SLOTS, 6))
    g, tool_rows = geometry(k), _tool(tool)
    roots, branch_of = np.empty((SLOTS, 9)), np.empty(SLOTS, dtype=np.int64)
    work = workspace()  # allocated once a batch
    for n in range(positions.shape[0]):
        p, r, f = _pose(positions, rotations, refs, n)
        ref = (refs[n, 0], refs[n, 1], refs[n, 2], refs[n, 3], refs[n, 4], refs[n, 5])
        best = _lazy_nearest(g, tool_rows, limits, p, r, f, ref, roots, branch_of, work,
                             bounds, raw, out)  # fmt: skip
        row[n] = best
        mask[n] = 0
        for j in range(6):
            q[n, j] = out[j] if best >= 0 else np.nan
