"""The UR single-pose formulas of :mod:`~kinplan.ik.ur_single` on arrays, many poses at once:
the nearest branch of each pose (:func:`fast_nearest_many`, behind ``URIK.nearest_many`` and
``Robot.ik_batch``) and one given branch of each pose (:func:`fast_branch_many`, behind
``URIK.branch_many`` and :mod:`cartesian.batch_track`).

Third of the UR modules, which import only those before them: :mod:`~kinplan.ik.ur_geometry` →
:mod:`~kinplan.ik.ur_single` → ``ur_many`` → :mod:`~kinplan.ik.ur`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from kinplan.ik.screws import CLAMP, TINY, joint_choice_many
from kinplan.ik.ur_single import FAST_EDGE, FAST_WRIST, URFast


def stack_pair(first: np.ndarray, second: np.ndarray, axis: int) -> np.ndarray:
    """``first`` and ``second`` (same shape) stacked as index 0 and 1 of a new ``axis``."""
    return np.stack((first, second), axis=axis)


def shoulder_terms(
    k: URFast, positions: np.ndarray, rotations: np.ndarray
) -> tuple[np.ndarray, ...]:
    """The terms of many poses that θ1 comes from: the rotation and position terms (12, N),
    the wrist centre along the shoulder axis and across it (x, y), its distance from the axis
    (radius) and the shoulder offset over it (ratio, |ratio| > 1: no θ1); each (N,)."""
    n = len(positions)
    values = k.matrix @ rotations.reshape(n, 9).T  # (12, N)
    along = np.reshape(k.shoulder_axes, (3, 3)) @ positions.T  # (3, N)
    along_u = values[9] + along[0] - k.p1_along[0]
    x = values[10] + along[1] - k.p1_along[1]
    y = values[11] + along[2] - k.p1_along[2]
    radius = np.maximum(np.sqrt(x * x + y * y), TINY)
    return values, along_u, x, y, radius, k.shoulder_offset / radius


def planar_targets(
    k: URFast,
    values: np.ndarray,
    shoulder: tuple[np.ndarray, ...],
    wrist: tuple[np.ndarray, ...],
    expand: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The target of the planar joints 2–4 and the angle φ = ψ2 + ψ3 + ψ4 they must sum to,
    on arrays (the formulas of :func:`fast_plane_axes` and :func:`fast_planar_target`).

    Args:
        k: The arm's constants.
        values: The pose's rotation and position terms, (12, N).
        shoulder: (cos θ1, sin θ1, x, y, along u) of each shoulder solution.
        wrist: (cos θ5, sin θ5, cos θ6, sin θ6) of each wrist solution.
        expand: Makes a per-shoulder array broadcast against the wrist arrays (an axis for
            the wrist branches when both are solved, the identity for one branch).

    Returns:
        (target x, target y, φ), in the wrist arrays' shape.
    """
    c1, s1, x, y, along_u = shoulder
    c5, s5, c6, s6 = wrist
    m5 = c1 * values[6] - s1 * values[3]
    m6 = c1 * values[7] - s1 * values[4]
    m7 = c1 * values[8] - s1 * values[5]
    (eu, eb), (fu, fb) = k.e_shoulder, k.f_shoulder
    ge5, ge6, ge7 = (eu * values[j] + eb * mj for j, mj in enumerate((m5, m6, m7)))
    gf5, gf6, gf7 = (fu * values[j] + fb * mj for j, mj in enumerate((m5, m6, m7)))
    turned = c1 * y - s1 * x
    offset_e = (k.plane_offset[0] + eu * along_u) + eb * turned
    offset_f = (k.plane_offset[1] + fu * along_u) + fb * turned
    d5, d6, d7 = k.d_wrist
    x6, x7 = c5 * d6 + s5 * d7, c5 * d7 - s5 * d6
    z5, z7 = c6 * d5 - s6 * x7, s6 * d5 + c6 * x7
    e5, e6, e7 = k.e_wrist
    y6, y7 = c5 * e6 + s5 * e7, c5 * e7 - s5 * e6
    v5, v7 = c6 * e5 - s6 * y7, s6 * e5 + c6 * y7
    ge5, ge6, ge7, gf5, gf6, gf7 = (expand(g) for g in (ge5, ge6, ge7, gf5, gf6, gf7))
    target_x = expand(offset_e) + z5 * ge5 + x6 * ge6 + z7 * ge7
    target_y = expand(offset_f) + z5 * gf5 + x6 * gf6 + z7 * gf7
    phi = np.arctan2(v5 * gf5 + y6 * gf6 + v7 * gf7, v5 * ge5 + y6 * ge6 + v7 * ge7)
    return target_x, target_y, phi


def fast_nearest_many(
    k: URFast,
    joints: tuple[tuple[float, float, float], ...],
    positions: np.ndarray,
    rotations: np.ndarray,
    refs: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:meth:`URIK._nearest_fast` of many poses at once: the same formulas on arrays.

    Arrays run branch-major: (2, N) per shoulder branch, (2, 2, N) per (shoulder, wrist) pair,
    (2, 2, 2, N) per branch, so each step is a few numpy passes over contiguous rows. The
    cosine and sine of an angle that comes out of atan2 or arccos are taken from its arguments
    (no trigonometric call): atan2 and arccos are the only transcendental passes.

    Args:
        k: The arm's constants.
        joints: Per joint (lower, upper, weight).
        positions: Tool positions (N, 3) [m]; rotations: tool rotations (N, 3, 3).
        refs: References (6, N) [rad], one column per pose.

    Returns:
        (q (N, 6) [rad], branch (N,) int (−1: none within the limits), mask (N,) uint16 with
        bit b set when branch b has a solution within the limits, left (N,) bool: the poses
        :meth:`URIK.nearest` leaves to the batch path (near a singularity), whose other
        outputs are meaningless).
    """
    n = len(positions)
    values, along_u, x, y, radius, ratio = shoulder_terms(k, positions, rotations)
    size = np.abs(ratio)
    no_shoulder = size > 1.0 + CLAMP + FAST_EDGE
    left = (size > 1.0 - FAST_EDGE) & ~no_shoulder
    np.copyto(ratio, np.nan, where=no_shoulder)  # NaN lanes: no solution, no tie to decide
    np.clip(ratio, -1.0, 1.0, out=ratio)
    # θ1 = base ± half: base = atan2(y, x), cos(half) = ratio
    base, half = np.arctan2(y, x), np.arccos(ratio)
    t1 = stack_pair(base + half, base - half, 0)  # (2, N)
    cos_base, sin_base = x / radius, y / radius
    sin_half = np.sqrt(np.maximum(1.0 - ratio * ratio, 0.0))
    p, m = cos_base * ratio, sin_base * sin_half
    c1 = stack_pair(p - m, p + m, 0)
    p, m = sin_base * ratio, cos_base * sin_half
    s1 = stack_pair(p + m, p - m, 0)
    # wrist (fast_wrist): θ5 = δ ± half5, cos/sin of half5 from its atan2 arguments
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = np.sqrt(b5 * b5 + b7 * b7)
    left |= np.any(sine < FAST_WRIST, axis=0) & ~no_shoulder
    half5 = np.arctan2(sine, b6)
    t5 = stack_pair(k.delta5 + half5, k.delta5 - half5, 1)  # (2, 2, N)
    norm = np.maximum(np.sqrt(sine * sine + b6 * b6), TINY)
    cos_half5, sin_half5 = b6 / norm, sine / norm
    cos_d, sin_d = math.cos(k.delta5), math.sin(k.delta5)
    p, m = cos_d * cos_half5, sin_d * sin_half5
    c5 = stack_pair(p - m, p + m, 1)
    p, m = sin_d * cos_half5, cos_d * sin_half5
    s5 = stack_pair(p + m, p - m, 1)
    a5, a6, a7 = k.a_wrist
    g5, g7 = c5 * a5, c5 * a7 - s5 * a6
    b5, b7 = b5[:, None], b7[:, None]
    sin6, cos6 = b7 * g5 - b5 * g7, b5 * g5 + b7 * g7
    t6 = np.arctan2(sin6, cos6)
    norm = np.maximum(np.sqrt(sin6 * sin6 + cos6 * cos6), TINY)
    c6, s6 = cos6 / norm, sin6 / norm
    # fast_plane_axes per shoulder branch, fast_planar_target per (shoulder, wrist) pair
    target_x, target_y, phi = planar_targets(
        k, values, (c1, s1, x, y, along_u), (c5, s5, c6, s6), lambda a: a[:, None]
    )
    # fast_elbow: ψ3 = offset ± bend; ψ2 = atan2(target) − atan2(v), v = r23 + Rot(ψ3) r34,
    # taken as one atan2
    l23, l34 = k.l23, k.l34
    cosine = (target_x * target_x + target_y * target_y - (l23 * l23 + l34 * l34)) / (
        2.0 * l23 * l34
    )
    size = np.abs(cosine)
    no_elbow = size > 1.0 + CLAMP + FAST_EDGE  # (2, 2, N)
    near_edge = (size > 1.0 - FAST_EDGE) & ~no_elbow
    left |= np.any(near_edge.reshape(4, n), axis=0) & ~no_shoulder
    np.copyto(cosine, np.nan, where=no_elbow)
    np.clip(cosine, -1.0, 1.0, out=cosine)
    bend = np.arccos(cosine)
    sin_bend = np.sqrt(np.maximum(1.0 - cosine * cosine, 0.0))
    offset = k.elbow_offset
    psi3 = stack_pair(offset + bend, offset - bend, 2)  # (2, 2, 2, N)
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    co, so = math.cos(offset), math.sin(offset)
    ax, ay = co * r2x - so * r2y, so * r2x + co * r2y  # Rot(offset) r34
    # v = r23 + cos(bend)·(ax, ay) ± sin(bend)·(−ay, ax) for ψ3 = offset ± bend
    vx, vy = r1x + ax * cosine, r1y + ay * cosine
    dx, dy = ay * sin_bend, ax * sin_bend
    # ψ2 = atan2(v × target, v · target) with v = (vx ∓ dx, vy ± dy)
    cross0, cross1 = vx * target_y - vy * target_x, dx * target_y + dy * target_x
    dot0, dot1 = vx * target_x + vy * target_y, dy * target_y - dx * target_x
    psi2 = np.arctan2(
        stack_pair(cross0 - cross1, cross0 + cross1, 2), stack_pair(dot0 + dot1, dot0 - dot1, 2)
    )
    sign2, sign3, sign4 = k.signs
    t4 = phi[:, :, None] - psi2 - psi3
    # the nearest branch (_nearest_fast): per joint the equivalent nearest the reference
    ref_clipped = np.clip(refs, [[j[0]] for j in joints], [[j[1]] for j in joints])

    def choose(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lower, upper, weight = joints[joint]
        return joint_choice_many(values, refs[joint], ref_clipped[joint], lower, upper, weight)

    q1, cost1 = choose(0, t1)
    q5, cost5 = choose(4, t5)
    q6, cost6 = choose(5, t6)
    head = (cost1[:, None] + cost5) + cost6  # the order of _nearest_fast's sums
    q2, cost2 = choose(1, sign2 * psi2)
    q3, cost3 = choose(2, sign3 * psi3)
    q4, cost4 = choose(3, sign4 * t4)
    cost = (((head[:, :, None] + cost2) + cost3) + cost4).reshape(8, n)
    branch = np.argmin(cost, axis=0)  # ties: the lower branch index, as _nearest_fast
    columns = np.arange(n)
    found = cost[branch, columns] < np.inf
    mask = np.zeros(n, dtype=np.uint16)
    for b in range(8):
        mask |= (cost[b] < np.inf).astype(np.uint16) << b
    q = np.empty((n, 6))
    pair = branch >> 1
    q[:, 0] = q1[branch >> 2, columns]
    q[:, 1] = q2.reshape(8, n)[branch, columns]
    q[:, 2] = q3.reshape(8, n)[branch, columns]
    q[:, 3] = q4.reshape(8, n)[branch, columns]
    q[:, 4] = q5.reshape(4, n)[pair, columns]
    q[:, 5] = q6.reshape(4, n)[pair, columns]
    return q, np.where(found, branch, -1), mask, left


def fast_branch_many(
    k: URFast, positions: np.ndarray, rotations: np.ndarray, branch: np.ndarray | int
) -> tuple[np.ndarray, np.ndarray]:
    """One branch of many poses: the formulas of :func:`fast_nearest_many` for a single
    (shoulder, wrist, elbow) sign triple per pose, with no nearest-branch choice.

    Args:
        k: The arm's constants.
        positions: Tool positions (N, 3) [m]; rotations: tool rotations (N, 3, 3).
        branch: Branch index ``4·shoulder + 2·wrist + elbow`` (as :class:`URIK`), one for all
            poses or one per pose (N,).

    Returns:
        (q (N, 6) [rad], raw angles (any 2π representative), NaN rows where the branch has no
        solution; edge (N,) bool: the poses :meth:`URIK.nearest` leaves to the batch path near
        a singularity on this branch, whose q is ill-conditioned).
    """
    n = len(positions)
    branch = np.asarray(branch)
    sign1 = 1.0 - 2.0 * (branch >> 2)  # +1: θ1 = base + half, −1: base − half
    sign5 = 1.0 - 2.0 * ((branch >> 1) & 1)
    sign3 = 1.0 - 2.0 * (branch & 1)
    values, along_u, x, y, radius, ratio = shoulder_terms(k, positions, rotations)
    size = np.abs(ratio)
    no_shoulder = size > 1.0 + CLAMP + FAST_EDGE
    edge = size > 1.0 - FAST_EDGE
    np.copyto(ratio, np.nan, where=no_shoulder)
    np.clip(ratio, -1.0, 1.0, out=ratio)
    t1 = np.arctan2(y, x) + sign1 * np.arccos(ratio)
    cos_base, sin_base = x / radius, y / radius
    sin_half = sign1 * np.sqrt(np.maximum(1.0 - ratio * ratio, 0.0))
    c1 = cos_base * ratio - sin_base * sin_half
    s1 = sin_base * ratio + cos_base * sin_half
    # wrist: θ5 = δ ± half5
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = np.sqrt(b5 * b5 + b7 * b7)
    edge |= sine < FAST_WRIST
    t5 = k.delta5 + sign5 * np.arctan2(sine, b6)
    norm = np.maximum(np.sqrt(sine * sine + b6 * b6), TINY)
    cos_half5, sin_half5 = b6 / norm, sign5 * sine / norm
    cos_d, sin_d = math.cos(k.delta5), math.sin(k.delta5)
    c5 = cos_d * cos_half5 - sin_d * sin_half5
    s5 = sin_d * cos_half5 + cos_d * sin_half5
    a5, a6, a7 = k.a_wrist
    g5, g7 = c5 * a5, c5 * a7 - s5 * a6
    sin6, cos6 = b7 * g5 - b5 * g7, b5 * g5 + b7 * g7
    t6 = np.arctan2(sin6, cos6)
    norm = np.maximum(np.sqrt(sin6 * sin6 + cos6 * cos6), TINY)
    c6, s6 = cos6 / norm, sin6 / norm
    # the plane of joints 2–4 and the planar target
    target_x, target_y, phi = planar_targets(
        k, values, (c1, s1, x, y, along_u), (c5, s5, c6, s6), lambda a: a
    )
    # the elbow: ψ3 = offset ± bend, ψ2 = atan2(v × target, v · target), v = r23 + Rot(ψ3) r34
    l23, l34 = k.l23, k.l34
    cosine = (target_x * target_x + target_y * target_y - (l23 * l23 + l34 * l34)) / (
        2.0 * l23 * l34
    )
    size = np.abs(cosine)
    no_elbow = size > 1.0 + CLAMP + FAST_EDGE
    edge |= size > 1.0 - FAST_EDGE
    np.copyto(cosine, np.nan, where=no_elbow)
    np.clip(cosine, -1.0, 1.0, out=cosine)
    psi3 = k.elbow_offset + sign3 * np.arccos(cosine)
    sin_bend = sign3 * np.sqrt(np.maximum(1.0 - cosine * cosine, 0.0))
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    co, so = math.cos(k.elbow_offset), math.sin(k.elbow_offset)
    ax, ay = co * r2x - so * r2y, so * r2x + co * r2y  # Rot(offset) r34
    vx, vy = r1x + ax * cosine - ay * sin_bend, r1y + ay * cosine + ax * sin_bend
    psi2 = np.arctan2(vx * target_y - vy * target_x, vx * target_x + vy * target_y)
    sign2, sign3_axis, sign4 = k.signs
    q = np.empty((n, 6))
    q[:, 0], q[:, 1], q[:, 2] = t1, sign2 * psi2, sign3_axis * psi3
    q[:, 3], q[:, 4], q[:, 5] = sign4 * (phi - psi2 - psi3), t5, t6
    return q, edge & ~no_shoulder
