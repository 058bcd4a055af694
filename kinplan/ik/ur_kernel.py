"""The UR closed form for one pose, compiled (numba): the solution nearest a reference, for
:meth:`URIK.nearest <kinplan.ik.ur.URIK.nearest>` and its batch form ``nearest_many``, one
given branch of many poses for ``URIK.branch_many``, and every branch of one pose for
``URIK.solutions`` (:func:`branches`, :func:`solutions`).

A twin of the fast path of :mod:`~kinplan.ik.ur_single` and :mod:`~kinplan.ik.ur_many` (the
same steps: θ1, θ5, θ6, the planar target, θ2–θ4, in the frames of
:class:`~kinplan.ik.ur_single.URFast`, with the roundings of the plain-float path for a single
pose and those of the array path, which takes the cosines and sines of θ1, θ5, θ6 from their
atan2 / arccos arguments, for many), followed by its nearest-branch choice (per joint the
2π-equivalent within the limits nearest the reference, then the branch of least weighted
distance, ties to the lower branch index). The rotation and position products
(``URFast.matrix @ R.ravel()``, the shoulder axes' coordinates of P) come from the caller, taken
in numpy as those paths take them, so the answers are theirs to the last bit or so.
Poses near a singularity (``FAST_EDGE``, ``FAST_WRIST`` of :mod:`~kinplan.ik.ur_single`) are
left to the vectorised all-branch path exactly as the plain-float and numpy paths leave them:
near the shoulder or wrist singularity always; near a straight or folded elbow, a single pose
(:func:`nearest`) when a (shoulder, wrist) pair its branch and bound visits is there, as
``URIK._nearest_fast``, a pose of a batch (:func:`nearest_many`) when any pair is, as
``fast_nearest_many``. Tested against those paths in ``tests/ik/test_ur_kernel.py``. Without
numba (or with ``KINPLAN_JIT=0``) :func:`available` is False and the plain-float / numpy paths
run. The constants come packed by :func:`constants`.

All angles in radians, lengths in metres, poses in the world frame.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import inline, jit, numba
from kinplan.ik.screws import CLAMP, HALF_TURN_SAFE, LIMIT_TOL, TAU, TINY
from kinplan.ik.spherical_wrist_kernel import distinct
from kinplan.ik.ur_single import FAST_EDGE, FAST_WRIST, URFast

#: What :func:`nearest` returns for an input with a NaN or inf (the caller reports it).
NOT_FINITE = -2
#: What :func:`nearest` returns for a pose near a singularity (the all-branch path decides).
LEFT = -3

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"

# Indices into the packed scalars of :func:`constants`.
_AXES = 0  # u1, a, b1 in world coordinates (9)
_P1 = 9  # shoulder coordinates of p1 (3)
_OFFSET = 12  # shoulder offset [m]
_DELTA5, _COS_D, _SIN_D = 13, 14, 15  # δ and its cosine and sine
_A_WRIST, _D_WRIST, _E_WRIST = 16, 19, 22  # wrist coordinates of a, p4 − c, e (3 each)
_EU, _EB, _FU, _FB = 25, 26, 27, 28  # (u1, b1) coordinates of e and f
_PLANE = 29  # (p1 − p2)·e, (p1 − p2)·f [m]
_R1X, _R1Y = 31, 32  # r23 [m]
_L23, _L34 = 33, 34  # link lengths [m]
_ELBOW_OFFSET, _AX, _AY = 35, 36, 37  # offset [rad] and Rot(offset) r34 [m]
_SIGNS = 38  # directions of axes 2, 3, 4 (3)
_R2X, _R2Y = 41, 42  # r34 [m]
_SIZE = 43

# _pose's and _elbow's outcomes.
_OK, _NONE, _EDGE = 0, 1, 2
# _nearest's modes: a single pose; a batch with the masks; a batch without them.
SINGLE, MASKS, BOUND = 0, 1, 2
# Rows of the (12, 12) work array of _pose, _elbow and _nearest (indexed, never sliced: a slice
# is a new array whose reference count numba updates atomically, ~20 ns each time): per
# shoulder branch (θ1, cos, sin, |sin(θ5 − δ)|) in rows 0–1; per (shoulder, wrist) pair (θ5,
# θ6, cos θ5, sin θ5, cos θ6, sin θ6) in rows 2–5; (θ2, θ3, θ4) of both elbows in row 6; per
# pair the chosen (θ1, θ5, θ6) in rows 7–10; row 11: per pair the θ1, θ5, θ6 part of the
# distance (columns 0–3), the reference clipped into the limits (columns 6–11).
_SHOULDER, _WRIST, _ANGLES, _PICKS, _HEADS, _CLIPPED = 0, 2, 6, 7, 11, 6


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


def constants(k: URFast) -> np.ndarray:
    """The scalars of the single-pose constants packed for the kernel, (43,) at the indices
    ``_AXES`` … ``_R2X`` of this module (``k.matrix`` is applied by the callers, in numpy, as
    the plain-float and array paths apply it). The cosines and sines of the fixed angles are
    taken here, in Python, as :func:`~kinplan.ik.ur_many.fast_nearest_many` takes them."""
    scalars = np.empty(_SIZE)
    scalars[_AXES : _AXES + 9] = k.shoulder_axes
    scalars[_P1 : _P1 + 3] = k.p1_along
    scalars[_OFFSET] = k.shoulder_offset
    scalars[_DELTA5] = k.delta5
    scalars[_COS_D], scalars[_SIN_D] = math.cos(k.delta5), math.sin(k.delta5)
    scalars[_A_WRIST : _A_WRIST + 3] = k.a_wrist
    scalars[_D_WRIST : _D_WRIST + 3] = k.d_wrist
    scalars[_E_WRIST : _E_WRIST + 3] = k.e_wrist
    (scalars[_EU], scalars[_EB]), (scalars[_FU], scalars[_FB]) = k.e_shoulder, k.f_shoulder
    scalars[_PLANE : _PLANE + 2] = k.plane_offset
    scalars[_R1X], scalars[_R1Y] = k.r23
    scalars[_L23], scalars[_L34] = k.l23, k.l34
    co, so = math.cos(k.elbow_offset), math.sin(k.elbow_offset)
    (r2x, r2y) = k.r34
    scalars[_ELBOW_OFFSET] = k.elbow_offset
    scalars[_AX], scalars[_AY] = co * r2x - so * r2y, so * r2x + co * r2y
    scalars[_SIGNS : _SIGNS + 3] = k.signs
    scalars[_R2X], scalars[_R2Y] = r2x, r2y
    return scalars


@jit
def _square(x):
    """x² exactly, as hi + lo (Veltkamp–Dekker splitting)."""
    hi = x * x
    t = x * 134217729.0  # 2**27 + 1
    xh = t - (t - x)
    xl = x - xh
    return hi, ((xh * xh - hi) + 2.0 * xh * xl) + xl * xl


@jit
def _hypot(x, y):
    """√(x² + y²) with the roundings of CPython's ``math.hypot`` (its ``vector_norm``: lossless
    scaled squares and sums, then one differential correction), which the plain-float path
    uses. libm's hypot differs from it in the last bit for about one pair in a thousand, which
    near the wrist singularity (θ6 from components of size |sin(θ5 − δ)|) or the shoulder one
    (θ1 from arccos(d4 / radius)) becomes ~1e-12 rad."""
    x, y = abs(x), abs(y)
    big = max(x, y)
    if big == np.inf:
        return big
    if x != x or y != y:
        return np.nan
    if big == 0.0:
        return big
    _, exponent = math.frexp(big)
    if exponent < -1023:  # subnormal: not met by the fast path's lengths
        return math.hypot(x, y)
    scale = math.ldexp(1.0, -exponent)
    total, frac1, frac2 = 1.0, 0.0, 0.0
    for v in (x * scale, y * scale):
        hi, lo = _square(v)
        added = total + hi
        frac2 += (total - added) + hi
        total = added
        frac1 += lo
    h = math.sqrt(total - 1.0 + (frac1 + frac2))
    hi, lo = _square(h)
    added = total - hi
    frac2 += (total - added) - hi
    total = added
    frac1 -= lo
    h += (total - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return h / scale


@inline
def _pose(c, values, work, plain):
    """θ1 of both shoulder branches and θ5, θ6 of the four (shoulder, wrist) pairs.

    ``plain``: the roundings of the plain-float path (:func:`~kinplan.ik.ur_single.fast_shoulder`,
    ``fast_wrist``: cos θ from θ, CPython's hypot), else those of the array path
    (:func:`~kinplan.ik.ur_many.fast_nearest_many`: cos θ from the arguments of θ's atan2 or
    arccos, no trigonometric call).

    Reads ``values`` (15,): ``URFast.matrix @ R.ravel()`` (0–11), then the shoulder
    coordinates of c − p1 (12–14: along u1, x along a, y along b1) [m] (:func:`_fill`).
    Writes rows ``_SHOULDER`` + s of ``work`` (12, 12): per shoulder branch s (θ1, cos θ1,
    sin θ1, |sin(θ5 − δ)|); rows ``_WRIST`` + pair: per pair ``2·shoulder + wrist`` (θ5, θ6,
    cos θ5, sin θ5, cos θ6, sin θ6). Angles are any 2π representative.

    Returns:
        ``_NONE`` when no θ1 keeps the shoulder offset (nothing else written), ``_EDGE`` when
        the ratio is within ``FAST_EDGE`` of ±1 (computed with the ratio clipped), else ``_OK``.
    """
    x, y = values[13], values[14]
    radius = max(_hypot(x, y) if plain else math.sqrt(x * x + y * y), TINY)
    ratio = c[_OFFSET] / radius
    size = abs(ratio)
    if size > 1.0 + CLAMP + FAST_EDGE or ratio != ratio:
        return _NONE
    status = _EDGE if size > 1.0 - FAST_EDGE else _OK
    ratio = min(max(ratio, -1.0), 1.0)
    # θ1 = base ± half: base = atan2(y, x), cos(half) = ratio
    base, half = math.atan2(y, x), math.acos(ratio)
    cos_base, sin_base = x / radius, y / radius
    sin_half = math.sqrt(max(1.0 - ratio * ratio, 0.0))
    cos_d, sin_d = c[_COS_D], c[_SIN_D]
    a5, a6, a7 = c[_A_WRIST], c[_A_WRIST + 1], c[_A_WRIST + 2]
    for s in range(2):
        sign = 1.0 if s == 0 else -1.0
        t1 = base + sign * half
        if plain:
            c1, s1 = math.cos(t1), math.sin(t1)
        else:
            p, m = cos_base * ratio, sin_base * sin_half
            c1 = p - sign * m
            p, m = sin_base * ratio, cos_base * sin_half
            s1 = p + sign * m
        work[_SHOULDER + s, 0], work[_SHOULDER + s, 1], work[_SHOULDER + s, 2] = t1, c1, s1
        # the wrist: θ5 = δ ± half5, cos/sin of half5 from its atan2 arguments
        b5 = c1 * values[3] + s1 * values[6]
        b6 = c1 * values[4] + s1 * values[7]
        b7 = c1 * values[5] + s1 * values[8]
        sine = _hypot(b5, b7) if plain else math.sqrt(b5 * b5 + b7 * b7)
        work[_SHOULDER + s, 3] = sine
        half5 = math.atan2(sine, b6)
        norm = max(math.sqrt(sine * sine + b6 * b6), TINY)
        cos_half5, sin_half5 = b6 / norm, sine / norm
        for w in range(2):
            sign5 = 1.0 if w == 0 else -1.0
            t5 = c[_DELTA5] + sign5 * half5
            if plain:
                c5, s5 = math.cos(t5), math.sin(t5)
            else:
                p, m = cos_d * cos_half5, sin_d * sin_half5
                c5 = p - sign5 * m
                p, m = sin_d * cos_half5, cos_d * sin_half5
                s5 = p + sign5 * m
            g5, g7 = c5 * a5, c5 * a7 - s5 * a6
            sin6, cos6 = b7 * g5 - b5 * g7, b5 * g5 + b7 * g7
            t6 = math.atan2(sin6, cos6)
            row = 2 * s + w
            (
                work[_WRIST + row, 0],
                work[_WRIST + row, 1],
                work[_WRIST + row, 2],
                work[_WRIST + row, 3],
            ) = t5, t6, c5, s5
            if plain:
                work[_WRIST + row, 4], work[_WRIST + row, 5] = math.cos(t6), math.sin(t6)
            else:
                norm6 = max(math.sqrt(sin6 * sin6 + cos6 * cos6), TINY)
                work[_WRIST + row, 4], work[_WRIST + row, 5] = cos6 / norm6, sin6 / norm6
    return status


@inline
def _elbow(c, values, work, pair, plain, full):
    """θ2, θ3, θ4 of both elbow branches of one (shoulder, wrist) ``pair``: the planar target
    (:func:`~kinplan.ik.ur_single.fast_plane_axes`, ``fast_planar_target``) and the elbow
    (``fast_elbow``), from the rows of ``work`` that :func:`_pose` wrote, written into row
    ``_ANGLES`` of ``work`` (its first 6 columns) as (θ2, θ3, θ4) of elbow +1, then −1;
    ``plain`` as :func:`_pose` (``fast_elbow``'s two atan2 for ψ2, else one). ``full`` False:
    only the outcome (row ``_ANGLES`` untouched), for a pair whose edge flag alone is needed.

    Returns:
        ``_NONE`` when the elbow cannot reach (row ``_ANGLES`` NaN), ``_EDGE`` when |cos ψ3| is
        within ``FAST_EDGE`` of 1 (computed with the cosine clipped), else ``_OK``.
    """
    s = pair >> 1
    c1, s1 = work[_SHOULDER + s, 1], work[_SHOULDER + s, 2]
    c5, s5, c6, s6 = (
        work[_WRIST + pair, 2],
        work[_WRIST + pair, 3],
        work[_WRIST + pair, 4],
        work[_WRIST + pair, 5],
    )
    m5 = c1 * values[6] - s1 * values[3]
    m6 = c1 * values[7] - s1 * values[4]
    m7 = c1 * values[8] - s1 * values[5]
    eu, eb, fu, fb = c[_EU], c[_EB], c[_FU], c[_FB]
    ge5, ge6, ge7 = eu * values[0] + eb * m5, eu * values[1] + eb * m6, eu * values[2] + eb * m7
    gf5, gf6, gf7 = fu * values[0] + fb * m5, fu * values[1] + fb * m6, fu * values[2] + fb * m7
    turned = c1 * values[14] - s1 * values[13]
    offset_e = (c[_PLANE] + eu * values[12]) + eb * turned
    offset_f = (c[_PLANE + 1] + fu * values[12]) + fb * turned
    d5, d6, d7 = c[_D_WRIST], c[_D_WRIST + 1], c[_D_WRIST + 2]
    x6, x7 = c5 * d6 + s5 * d7, c5 * d7 - s5 * d6
    z5, z7 = c6 * d5 - s6 * x7, s6 * d5 + c6 * x7
    e5, e6, e7 = c[_E_WRIST], c[_E_WRIST + 1], c[_E_WRIST + 2]
    y6, y7 = c5 * e6 + s5 * e7, c5 * e7 - s5 * e6
    v5, v7 = c6 * e5 - s6 * y7, s6 * e5 + c6 * y7
    tx = offset_e + z5 * ge5 + x6 * ge6 + z7 * ge7
    ty = offset_f + z5 * gf5 + x6 * gf6 + z7 * gf7
    # ψ3 = offset ± bend; ψ2 = atan2(v × target, v · target), v = r23 + Rot(ψ3) r34
    l23, l34 = c[_L23], c[_L34]
    if plain:
        cosine = (tx * tx + ty * ty - l23 * l23 - l34 * l34) / (2.0 * l23 * l34)
    else:
        cosine = (tx * tx + ty * ty - (l23 * l23 + l34 * l34)) / (2.0 * l23 * l34)
    size = abs(cosine)
    if size > 1.0 + CLAMP + FAST_EDGE or cosine != cosine:
        if full:
            for j in range(6):
                work[_ANGLES, j] = np.nan
        return _NONE
    status = _EDGE if size > 1.0 - FAST_EDGE else _OK
    if not full:
        return status
    phi = math.atan2(v5 * gf5 + y6 * gf6 + v7 * gf7, v5 * ge5 + y6 * ge6 + v7 * ge7)
    cosine = min(max(cosine, -1.0), 1.0)
    bend = math.acos(cosine)
    sin_bend = math.sqrt(max(1.0 - cosine * cosine, 0.0))
    ax, ay = c[_AX], c[_AY]
    vx, vy = c[_R1X] + ax * cosine, c[_R1Y] + ay * cosine
    dx, dy = ay * sin_bend, ax * sin_bend
    cross0, cross1 = vx * ty - vy * tx, dx * ty + dy * tx
    dot0, dot1 = vx * tx + vy * ty, dy * ty - dx * tx
    offset = c[_ELBOW_OFFSET]
    direction = math.atan2(ty, tx) if plain else 0.0
    for e in range(2):
        sign = 1.0 if e == 0 else -1.0
        psi3 = offset + sign * bend
        if plain:  # ψ2 = atan2(target) − atan2(v)
            cb, sb = math.cos(psi3), math.sin(psi3)
            r2x, r2y = c[_R2X], c[_R2Y]
            psi2 = direction - math.atan2(
                c[_R1Y] + sb * r2x + cb * r2y, c[_R1X] + cb * r2x - sb * r2y
            )
        else:
            psi2 = math.atan2(cross0 - sign * cross1, dot0 + sign * dot1)
        work[_ANGLES, 3 * e] = c[_SIGNS] * psi2
        work[_ANGLES, 3 * e + 1] = c[_SIGNS + 1] * psi3
        work[_ANGLES, 3 * e + 2] = c[_SIGNS + 2] * (phi - psi2 - psi3)
    return status


@jit
def _joint(value, refs, r, work, limits, j):
    """:func:`_choice` of joint ``j`` for reference ``refs[r]`` (its clipped value in the
    work array's row ``_HEADS``, its limits and weight in ``limits``)."""
    return _choice(
        value, refs[r, j], work[_HEADS, _CLIPPED + j], limits[0, j], limits[1, j], limits[2, j]
    )


@jit
def _choice(value, ref, clipped, lower, upper, weight):
    """One joint's value for the nearest solution and its share of the distance, as
    :func:`~kinplan.ik.screws.joint_choice`: (q, w·(q − ref)²), cost inf (q NaN) when no
    2π-equivalent is within the limits. ``clipped`` is ``ref`` clipped into them."""
    turns = np.round((clipped - value) / TAU)
    q = value + TAU * turns
    if not (lower <= q <= upper and -HALF_TURN_SAFE < q - clipped < HALF_TURN_SAFE):
        # near a limit or half a turn away: kinplan.ik.screws.near_angle
        if not (lower - LIMIT_TOL <= q <= upper + LIMIT_TOL and abs(q - clipped) < HALF_TURN_SAFE):
            best_distance = np.inf
            for shift in (-1.0, 0.0, 1.0):  # ties go to the first, as near_angle
                candidate = value + TAU * (turns + shift)
                if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:
                    distance = abs(candidate - clipped)
                    if distance < best_distance:
                        q, best_distance = candidate, distance
            if best_distance == np.inf:
                return np.nan, np.inf
        q = min(max(q, lower), upper)
    return q, weight * (q - ref) ** 2


@inline
def _nearest(c, limits, values, refs, q, r, mode, work, order):
    """The branch nearest the reference ``refs[r]`` of one pose, its solution written into
    ``q[r]`` (rows indexed, never sliced: see ``_SHOULDER``).

    Args:
        c: The packed constants (:func:`constants`).
        limits: Rows lower, upper [rad] and weights, shape (3, 6).
        values: The pose's terms (15,), see :func:`_pose`.
        refs: Reference configurations [rad] (M, 6); row ``r`` is this pose's.
        q: Solutions (M, 6); row ``r`` written with this pose's (NaN when none).
        r: The row of ``refs`` and ``q``.
        mode: :data:`SINGLE`: as ``URIK._nearest_fast``, its roundings (``plain`` of
            :func:`_pose`) and its branch and bound (the (shoulder, wrist) pairs in increasing
            order of their θ1, θ5, θ6 distance, the planar step only while they can beat the
            best; left only for a visited pair near the elbow edge; mask not computed).
            :data:`MASKS`: as ``fast_nearest_many``, every branch (the mask of all; left when
            any pair is near the elbow edge). :data:`BOUND`: the roundings and left flags of
            ``fast_nearest_many``, the branch and bound of ``_nearest_fast`` (the same branch
            and q; mask partial: not for the caller).
        work, order: Scratch, shapes (12, 12) float (rows ``_SHOULDER`` …) and (4,) int.

    Returns:
        (branch (−1: none within the limits, :data:`LEFT`: near a singularity), mask).
    """
    for j in range(6):
        q[r, j] = np.nan
        work[_HEADS, _CLIPPED + j] = min(max(refs[r, j], limits[0, j]), limits[1, j])
    single, bound = mode == SINGLE, mode != MASKS
    status = _pose(c, values, work, single)
    if status == _NONE:
        return -1, 0
    if status == _EDGE or work[_SHOULDER, 3] < FAST_WRIST or work[_SHOULDER + 1, 3] < FAST_WRIST:
        return LEFT, 0
    # the θ1, θ5, θ6 parts of the distance, per pair
    first = _joint(work[_SHOULDER, 0], refs, r, work, limits, 0)
    second = _joint(work[_SHOULDER + 1, 0], refs, r, work, limits, 0)
    for pair in range(4):
        q1, cost1 = first if pair < 2 else second
        q5, cost5 = _joint(work[_WRIST + pair, 0], refs, r, work, limits, 4)
        q6, cost6 = _joint(work[_WRIST + pair, 1], refs, r, work, limits, 5)
        work[_HEADS, pair] = (cost1 + cost5) + cost6
        work[_PICKS + pair, 0], work[_PICKS + pair, 1], work[_PICKS + pair, 2] = q1, q5, q6
        order[pair] = pair
    if bound:  # by head, then pair index (an insertion sort of four)
        for i in range(1, 4):
            j = i
            while j > 0 and work[_HEADS, order[j]] < work[_HEADS, order[j - 1]]:
                order[j], order[j - 1] = order[j - 1], order[j]
                j -= 1
    best, best_cost, mask = -1, np.inf, 0
    for i in range(4):
        pair = order[i]
        head = work[_HEADS, pair]
        # once a head cannot beat the best, neither can the later ones (sorted, best fixed)
        beaten = bound and (head == np.inf or head > best_cost)
        if beaten and single:
            break
        status = _elbow(c, values, work, pair, single, not beaten)
        if status == _EDGE:
            return LEFT, 0
        if beaten or status == _NONE or head == np.inf:
            continue
        for e in range(2):
            q2, cost2 = _joint(work[_ANGLES, 3 * e], refs, r, work, limits, 1)
            if cost2 == np.inf or (bound and head + cost2 > best_cost):
                continue
            q3, cost3 = _joint(work[_ANGLES, 3 * e + 1], refs, r, work, limits, 2)
            q4, cost4 = _joint(work[_ANGLES, 3 * e + 2], refs, r, work, limits, 3)
            cost = ((head + cost2) + cost3) + cost4
            if cost == np.inf:
                continue
            index = 2 * pair + e
            mask |= 1 << index
            if cost < best_cost or (cost == best_cost and index < best):
                best, best_cost = index, cost
                q[r, 0], q[r, 1], q[r, 2] = work[_PICKS + pair, 0], q2, q3
                q[r, 3], q[r, 4], q[r, 5] = q4, work[_PICKS + pair, 1], work[_PICKS + pair, 2]
    return best, mask


@inline
def _finite(values, refs, r):
    """Whether the pose's terms and the reference ``refs[r]`` are all finite (a NaN or inf
    anywhere in the pose reaches some term: ``URFast.matrix`` has no zero column)."""
    total = 0.0
    for i in range(15):
        total += values[i]
    for j in range(6):
        total += refs[r, j]
    return math.isfinite(total)


@inline
def _fill(c, terms, along, i, values):
    """``values`` (15,) of pose ``i`` from the array path's products: ``terms`` (12, N) =
    ``URFast.matrix @ R.ravel()`` and ``along`` (3, N) = shoulder axes @ P, per pose (the
    products of :func:`~kinplan.ik.ur_many.shoulder_terms`)."""
    for r in range(12):
        values[r] = terms[r, i]
    for r in range(3):
        values[12 + r] = terms[9 + r, i] + along[r, i] - c[_P1 + r]


@inline
def _fill_single(c, terms, position, values):
    """``values`` (15,) of one pose, as :func:`_fill`, with the shoulder axes' products summed
    in the order of :func:`~kinplan.ik.ur_single.fast_shoulder` (the plain-float path's
    roundings). ``terms``: ``URFast.matrix @ R.ravel()`` (12,); ``position`` [m] (3,)."""
    px, py, pz = position[0], position[1], position[2]
    for r in range(12):
        values[r] = terms[r]
    for r in range(3):
        a = 3 * r
        values[12 + r] = terms[9 + r] + c[a] * px + c[a + 1] * py + c[a + 2] * pz - c[_P1 + r]


@jit
def branches(c, terms, position, raw):
    """Every branch of one pose, as ``URIK._fast_all_branches`` (its plain-float roundings):
    row ``4·shoulder + 2·wrist + elbow`` of ``raw`` (8, 6) [rad] (any 2π representative, NaN
    where the branch has no solution). Returns 0, :data:`LEFT` for a pose near a singularity
    (the shoulder's or the wrist's, or any elbow straight or folded, within ``FAST_EDGE`` /
    ``FAST_WRIST``: the all-branch path decides), :data:`NOT_FINITE` for a NaN or inf.
    ``terms``, ``position``: as :func:`nearest`."""
    values = np.empty(15)
    _fill_single(c, terms, position, values)
    total = 0.0
    for i in range(15):
        total += values[i]
    if not math.isfinite(total):
        return NOT_FINITE
    for b in range(8):
        for j in range(6):
            raw[b, j] = np.nan
    work = np.empty((12, 12))
    status = _pose(c, values, work, True)
    if status == _NONE:
        return 0
    if status == _EDGE or work[_SHOULDER, 3] < FAST_WRIST or work[_SHOULDER + 1, 3] < FAST_WRIST:
        return LEFT
    for pair in range(4):
        status = _elbow(c, values, work, pair, True, True)
        if status == _EDGE:
            return LEFT
        if status == _NONE:
            continue
        s = pair >> 1
        for e in range(2):
            row = 2 * pair + e
            raw[row, 0] = work[_SHOULDER + s, 0]
            for j in range(3):
                raw[row, 1 + j] = work[_ANGLES, 3 * e + j]
            raw[row, 4], raw[row, 5] = work[_WRIST + pair, 0], work[_WRIST + pair, 1]
    return 0


@jit
def solutions(c, terms, position, middle, lower, upper):
    """Every distinct solution of one pose within the limits (``URIK.solutions`` on an
    orthonormal geometry: :func:`branches`, then
    :func:`~kinplan.ik.spherical_wrist_kernel.distinct`), (k, 6) [rad] each as its equivalent
    nearest ``middle``; None near a singularity or for a NaN or inf (the all-branch path
    decides or reports it). ``terms``, ``position``: as :func:`nearest`."""
    raw = np.empty((8, 6))
    if branches(c, terms, position, raw) != 0:
        return None
    out = np.empty((8, 6))
    return out[: distinct(raw, middle, lower, upper, out)]


@jit
def nearest(c, limits, terms, position, ref, out):
    """The solution nearest ``ref`` [rad] (6,) written into ``out`` (6,), as
    ``URIK._nearest_fast``; returns its branch, −1 when no branch has a solution within the
    limits, :data:`NOT_FINITE` for an input with a NaN or inf, :data:`LEFT` for a pose near a
    singularity (the all-branch path decides).

    Args:
        c, limits: As :func:`_nearest`.
        terms: ``URFast.matrix @ R.ravel()`` (12,) of the tool rotation R (numpy's product, as
            the plain-float path takes it).
        position: Tool position [m] (3,).
        ref, out: As :func:`_nearest`.
    """
    values = np.empty(15)
    _fill_single(c, terms, position, values)
    refs, q = ref.reshape((1, 6)), out.reshape((1, 6))
    if not _finite(values, refs, 0):
        return NOT_FINITE
    work, order = np.empty((12, 12)), np.empty(4, dtype=np.int64)
    branch, _ = _nearest(c, limits, values, refs, q, 0, SINGLE, work, order)
    return branch


@jit
def nearest_many(c, limits, terms, along, refs, q, branch, mask, left, masks):
    """:func:`nearest` of N poses, each with its own reference (N, 6), as
    :func:`~kinplan.ik.ur_many.fast_nearest_many`: ``q`` (N, 6) [rad] (NaN rows: none),
    ``branch`` (N,) (−1: none within the limits or a NaN / inf input), ``mask`` (N,) (bit b:
    branch b within the limits) and ``left`` (N,) (near a singularity: the all-branch path
    decides; the other outputs are then meaningless) written. ``terms``, ``along``: see
    :func:`_fill`. ``masks`` False: ``mask`` is 0 and the pairs that cannot beat the best are
    not solved (the same q, branch and left)."""
    mode = MASKS if masks else BOUND
    values = np.empty(15)
    work, order = np.empty((12, 12)), np.empty(4, dtype=np.int64)
    for i in range(refs.shape[0]):
        _fill(c, terms, along, i, values)
        if _finite(values, refs, i):
            best, bits = _nearest(c, limits, values, refs, q, i, mode, work, order)
        else:
            best, bits = -1, 0
            q[i, :] = np.nan
        left[i] = best == LEFT
        branch[i] = -1 if best == LEFT else best
        mask[i] = bits if masks else 0


@jit
def branch_many(c, terms, along, branches, q, edge):
    """One branch ``branches[i]`` (``4·shoulder + 2·wrist + elbow``) of each of N poses, as
    :func:`~kinplan.ik.ur_many.fast_branch_many`: ``q`` (N, 6) [rad] (any 2π representative;
    NaN where the branch has no solution) and ``edge`` (N,) (near a singularity of the branch,
    q ill-conditioned, or the elbow out of reach) written. ``terms``, ``along``: see
    :func:`_fill`."""
    values = np.empty(15)
    work = np.empty((12, 12))
    for i in range(branches.shape[0]):
        b = branches[i]
        pair, s = b >> 1, b >> 2
        _fill(c, terms, along, i, values)
        status = _pose(c, values, work, False)
        if status == _NONE:
            q[i, :] = np.nan
            edge[i] = False
            continue
        elbow = _elbow(c, values, work, pair, False, True)
        # as fast_branch_many: an elbow out of reach counts as an edge too (q NaN there)
        near = status == _EDGE or work[_SHOULDER + s, 3] < FAST_WRIST or elbow != _OK
        e = 3 * (b & 1)
        q[i, 0], q[i, 1], q[i, 2] = work[_SHOULDER + s, 0], work[_ANGLES, e], work[_ANGLES, e + 1]
        q[i, 3], q[i, 4] = work[_ANGLES, e + 2], work[_WRIST + pair, 0]
        q[i, 5] = work[_WRIST + pair, 1]
        edge[i] = near
