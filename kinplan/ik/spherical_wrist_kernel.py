"""The spherical-wrist closed form for one pose, compiled (numba): every branch, and the
solution nearest a reference, for :meth:`SphericalWristIK.nearest
<kinplan.ik.spherical_wrist.SphericalWristIK.nearest>` and its batch form ``nearest_many``.

A twin of :meth:`SphericalWristIK._raw <kinplan.ik.spherical_wrist.SphericalWristIK>` (the
same subproblems, tolerances, free-angle rules and branch order, in scalars) followed by the
choice :meth:`kinplan.ik.ClosedFormIK.nearest` makes (per joint the 2π-equivalent within the
limits nearest the reference, then the branch of least weighted distance, ties to the lower
branch index). Tested against the numpy path in ``tests/ik/test_spherical_wrist_ik.py``.
Without numba (or with ``KINPLAN_JIT=0``) :func:`available` is False and the numpy path runs.
The geometry comes packed by :meth:`WristGeometry.constants
<kinplan.ik.spherical_wrist_geometry.WristGeometry.constants>`.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import inline, jit, numba
from kinplan.compiled import turn_into as _turn
from kinplan.ik.screws import CLAMP, DISTINCT_TOL, FREE_TOL, LIMIT_TOL, TAU
from kinplan.ik.subproblems import FREE_ROOM

#: What :func:`nearest` returns for an input with a NaN or inf (the caller reports it).
NOT_FINITE = -2

#: Rows of :func:`branches`' scratch space ``work`` (WORK_ROWS, 3).
WORK_ROWS = 15
#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


@jit
def _rotate(axis, v, angle, out):
    """``out`` = R(axis, angle) v (Rodrigues); ``out`` may be ``v``."""
    _turn(axis, v, math.cos(angle), math.sin(angle), out)


@jit
def _sp1(k, p, q):
    """Subproblem 1: the angle about unit ``k`` turning ``p`` towards ``q`` (0 when free)."""
    kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2]
    kq = k[0] * q[0] + k[1] * q[1] + k[2] * q[2]
    px, py, pz = p[0] - kp * k[0], p[1] - kp * k[1], p[2] - kp * k[2]
    qx, qy, qz = q[0] - kq * k[0], q[1] - kq * k[1], q[2] - kq * k[2]
    sine = k[0] * (py * qz - pz * qy) + k[1] * (pz * qx - px * qz) + k[2] * (px * qy - py * qx)
    return math.atan2(sine, px * qx + py * qy + pz * qz)


@jit
def _sp1_turn(k, p, q):
    """:func:`_sp1` with the cosine and sine of its angle: (θ, cos θ, sin θ) ((0, 1, 0) when
    free)."""
    kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2]
    kq = k[0] * q[0] + k[1] * q[1] + k[2] * q[2]
    px, py, pz = p[0] - kp * k[0], p[1] - kp * k[1], p[2] - kp * k[2]
    qx, qy, qz = q[0] - kq * k[0], q[1] - kq * k[1], q[2] - kq * k[2]
    sine = k[0] * (py * qz - pz * qy) + k[1] * (pz * qx - px * qz) + k[2] * (px * qy - py * qx)
    cosine = px * qx + py * qy + pz * qz
    radius = math.hypot(sine, cosine)
    if radius == 0.0:
        return 0.0, 1.0, 0.0
    return math.atan2(sine, cosine), cosine / radius, sine / radius


@jit
def _wrap(angle):
    return angle - TAU * np.round(angle / TAU)


@jit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def free_wrist(theta6_at_zero, sigma, fill, lower4, upper4, lower6, upper6):
    """θ4 [rad] at the wrist singularity, where only ψ = θ4 + σ·θ6 is fixed.

    θ4 keeps ``fill`` (clipped into its limits) when θ6 = σ·(ψ − θ4) then has an equivalent
    within its limits; else θ4 is the value nearest it (over 2π equivalents, within its own
    limits) that puts θ6 on one of its limits, as the UR solver does for its free θ6.

    Args:
        theta6_at_zero: θ6 [rad] of the pose with θ4 = 0 (so ψ = σ·θ6(0)).
        sigma: ±1, the direction of axis 6 along axis 4 at the singularity.
        fill: The reference value of θ4 [rad].
        lower4, upper4, lower6, upper6: The joints' limits [rad] (±inf allowed).
    """
    psi = sigma * theta6_at_zero
    t4 = min(max(fill, lower4), upper4)
    if not math.isnan(_choice(sigma * (psi - t4), 0.0, lower6, upper6)):  # θ6 fits
        return t4
    best, best_distance = t4, np.inf
    for bound in (lower6, upper6):
        edge = psi - sigma * bound
        turns = np.round((t4 - edge) / TAU)
        for shift in (-1.0, 0.0, 1.0):
            candidate = edge + TAU * (turns + shift)
            if lower4 - LIMIT_TOL <= candidate <= upper4 + LIMIT_TOL:
                if abs(candidate - t4) < best_distance:
                    best, best_distance = candidate, abs(candidate - t4)
    return min(max(best, lower4), upper4)


@jit
def branches(k, position, rotation, fill, raw, ok, work, limits):
    """Every branch of one pose: rows ``4·shoulder + 2·elbow + wrist`` of ``raw`` (8, 6) [rad]
    (wrapped into [−π, π]) with ``ok`` (8,) where the branch has a solution.

    Args:
        k: The packed geometry (22, 3).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        fill: Values [rad] (6,) of joints that are free at a singularity (θ1, θ2, θ4 only).
        raw, ok: Written.
        work: Scratch space, shape (:data:`WORK_ROWS`, 3); rows 10–14 are written with the
            pose's margins from the branches' boundaries and its sensitivities, read by
            :mod:`~kinplan.ik.near_wrist_kernel`:
            row 10 the distances [m] of the wrist centre from a boundary of the shoulder's
            subproblem 4, and from one of the elbow's reach for the first and the second θ1
            (inf where not computed); row 11 (the least shortfall of a wrist without a
            solution: subproblem 2's ``rest`` < 0, inf when none; then 1.0 where the elbow
            reaches for the first and the second θ1, else 0.0: row 10's elbow margin is then
            inside the reach, not outside it); row 12 (for the first and
            the second θ1, how much the arm turns per metre the wrist centre moves, from the
            elbow and from axis 2: r/(l₁·l₂·|sin e|) + 1/r [1/m], r the wrist centre's
            distance from axis 2 and e the elbow's angle; inf where the elbow does not reach);
            rows 13 and 14 (for the first and the second θ1, of the two elbows: the
            determinant of the wrist's axes 4, 5, 6 turned by θ5, the same for both wrists,
            |(h₄ × h₅)/|h₄ × h₅| · R(h₅, θ5) h₆| = √rest of subproblem 2, NaN where the wrist
            has no solution).
        limits: Rows lower, upper [rad] (and weights), shape (3, 6): for θ4 at the wrist
            singularity (:func:`free_wrist`).

    Returns:
        Whether some joint was free (took its ``fill`` value).
    """
    h1, h2, h3, h4, h5, h6 = k[0], k[1], k[2], k[3], k[4], k[5]
    p1, p2 = k[6], k[7]
    cit, e, f, x6 = k[13], k[14], k[15], k[19]
    lateral, sign3 = k[16, 0], k[16, 1]
    for b in range(8):
        ok[b] = False
    singular = False
    v, t1s, q6, qx, n = work[0], work[1], work[2], work[3], work[4]
    seen, w6, wx, z, zz = work[5], work[6], work[7], work[8], work[9]
    for i in range(3):
        v[i] = position[i] - p1[i]
        for j in range(3):
            v[i] += rotation[i, j] * cit[j]
    # 1. θ1: subproblem 4, h2·R(h1, −θ1) v = lateral
    hk = _dot(h2, h1)
    kp = _dot(v, h1)
    a = _dot(v, h2) - hk * kp
    b = (
        v[0] * (h2[1] * h1[2] - h2[2] * h1[1])
        + v[1] * (h2[2] * h1[0] - h2[0] * h1[2])
        + v[2] * (h2[0] * h1[1] - h2[1] * h1[0])
    )
    radius = math.hypot(a, b)
    rhs = lateral - hk * kp
    margins = work[10]
    margins[0] = abs(radius - abs(rhs))
    margins[1] = margins[2] = work[11, 0] = work[12, 0] = work[12, 1] = np.inf
    work[11, 1] = work[11, 2] = 0.0
    if radius < FREE_TOL:
        if abs(rhs) > FREE_ROOM:
            return False
        singular = True
        t1s[0] = fill[0]
        t1s[1] = fill[0]
    else:
        ratio = rhs / radius
        if abs(ratio) > 1.0 + CLAMP:
            return False
        half = math.acos(min(max(ratio, -1.0), 1.0))
        base = math.atan2(b, a)
        t1s[0] = -(base + half)
        t1s[1] = -(base - half)
    l1 = math.hypot(k[17, 0], k[17, 1])
    l2 = math.hypot(k[18, 0], k[18, 1])
    offset_b = math.atan2(k[17, 1], k[17, 0]) - math.atan2(k[18, 1], k[18, 0])
    # the wrist's two vectors: Q h6 and Q x6 with Q = R_T R_Mᵀ
    for i in range(3):
        q6[i] = rotation[i, 0] * k[20, 0] + rotation[i, 1] * k[20, 1] + rotation[i, 2] * k[20, 2]
        qx[i] = rotation[i, 0] * k[21, 0] + rotation[i, 1] * k[21, 1] + rotation[i, 2] * k[21, 2]
    c45 = _dot(h5, h4)
    n[0] = h5[1] * h4[2] - h5[2] * h4[1]
    n[1] = h5[2] * h4[0] - h5[0] * h4[2]
    n[2] = h5[0] * h4[1] - h5[1] * h4[0]
    n2 = _dot(n, n)
    kp5 = _dot(h6, h5)
    for s in range(2):
        t1 = t1s[s]
        c1, s1 = math.cos(t1), -math.sin(t1)  # of −θ1
        # 2. θ2, θ3: the planar elbow
        _turn(h1, v, c1, s1, seen)
        for i in range(3):
            seen[i] += p1[i] - p2[i]
        tx, ty = _dot(seen, e), _dot(seen, f)
        d2 = tx * tx + ty * ty
        reach = math.sqrt(d2)
        margins[1 + s] = min(abs(reach - (l1 + l2)), abs(reach - abs(l1 - l2)))
        cosine = (d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
        if abs(cosine) > 1.0 + CLAMP:
            continue
        work[11, 1 + s] = 1.0  # the elbow reaches: the margin is inside its reach
        sine = math.sqrt(max(1.0 - cosine * cosine, 0.0))
        work[12, s] = reach / (l1 * l2 * sine) + 1.0 / reach
        elbow = math.acos(min(max(cosine, -1.0), 1.0))
        for el in range(2):
            psi_b = (elbow if el == 0 else -elbow) + offset_b
            cb, sb = math.cos(psi_b), math.sin(psi_b)
            vx = k[17, 0] + cb * k[18, 0] - sb * k[18, 1]
            vy = k[17, 1] + sb * k[18, 0] + cb * k[18, 1]
            if d2 < FREE_TOL * FREE_TOL:
                t2 = fill[1]
                singular = True
            else:
                t2 = _wrap(math.atan2(ty, tx) - math.atan2(vy, vx))
            t3 = sign3 * _wrap(psi_b)
            # 3. W h6, W x6 with W = (R1 R2 R3)ᵀ Q
            c2, s2 = math.cos(t2), -math.sin(t2)
            c3, s3 = cb, -sign3 * sb  # cos, sin of −θ3 = −sign3·ψb
            _turn(h1, q6, c1, s1, w6)
            _turn(h2, w6, c2, s2, w6)
            _turn(h3, w6, c3, s3, w6)
            _turn(h1, qx, c1, s1, wx)
            _turn(h2, wx, c2, s2, wx)
            _turn(h3, wx, c3, s3, wx)
            # subproblem 2: R(h5, θ5) h6 = R(h4, −θ4) w6
            kq = _dot(w6, h4)
            alpha = (kp5 - c45 * kq) / n2
            beta = (kq - c45 * kp5) / n2
            length2 = 0.5 * (_dot(h6, h6) + _dot(w6, w6))
            rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c45
            work[13 + s, el] = math.sqrt(rest) if rest >= 0.0 else np.nan
            if rest < 0.0:
                work[11, 0] = min(work[11, 0], -rest)
            if rest < -CLAMP * max(length2, 1e-300):
                continue
            gamma = math.sqrt(max(rest, 0.0) / n2)
            ox, oy, oz = w6[0] - kq * h4[0], w6[1] - kq * h4[1], w6[2] - kq * h4[2]
            free4 = ox * ox + oy * oy + oz * oz < FREE_TOL * FREE_TOL
            if free4:
                singular = True
            for wr in range(2):
                g = gamma if wr == 0 else -gamma
                for i in range(3):  # on the free wrist, z = w6 exactly (as subproblems.sp2)
                    z[i] = w6[i] if free4 else alpha * h5[i] + beta * h4[i] + g * n[i]
                t5, c5, s5 = _sp1_turn(h5, h6, z)
                if free4:
                    t4, c4, s4 = 0.0, 1.0, 0.0  # of −θ4
                else:
                    minus4, c4, s4 = _sp1_turn(h4, w6, z)
                    t4 = -minus4
                # 4. θ6: R(h6, θ6) x6 = R5ᵀ R4ᵀ W x6
                _turn(h4, wx, c4, s4, zz)
                _turn(h5, zz, c5, -s5, zz)
                t6 = _sp1(h6, x6, zz)
                if free4:  # θ4 + σ·θ6 fixed
                    sigma = 1.0 if kq >= 0.0 else -1.0
                    t4 = free_wrist(t6, sigma, fill[3], limits[0, 3], limits[1, 3],
                                    limits[0, 5], limits[1, 5])  # fmt: skip
                    t6 = t6 - sigma * t4
                row = 4 * s + 2 * el + wr
                raw[row, 0] = _wrap(t1)
                raw[row, 1] = _wrap(t2)
                raw[row, 2] = _wrap(t3)
                raw[row, 3] = _wrap(t4)
                raw[row, 4] = _wrap(t5)
                raw[row, 5] = _wrap(t6)
                ok[row] = True
    return singular


@jit
def _choice(value, ref, lower, upper):
    """The 2π-equivalent of ``value`` within [lower, upper] nearest ``ref`` clipped into
    them (ties to the lower one, as :func:`kinplan.ik.screws.wrap_near`), or NaN."""
    clipped = min(max(ref, lower), upper)
    turns = np.round((clipped - value) / TAU)
    best = np.nan
    best_distance = np.inf
    for shift in (-1.0, 0.0, 1.0):
        candidate = value + TAU * (turns + shift)
        if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:
            distance = abs(candidate - clipped)
            if distance < best_distance:
                best, best_distance = candidate, distance
    if best_distance == np.inf:
        return np.nan
    return min(max(best, lower), upper)


@inline
def branch_cost(raw, row, limits, ref, slack):
    """The weighted squared distance Σ wᵢ Δqᵢ² [rad²] from ``ref`` of row ``row`` of ``raw``
    (S, 6), each joint as its 2π-equivalent within the limits (widened by ``slack`` [rad])
    nearest ``ref``; inf when a joint has none."""
    cost = 0.0
    for j in range(6):
        q = _choice(raw[row, j], ref[j], limits[0, j] - slack, limits[1, j] + slack)
        if q != q:
            return np.inf
        cost += limits[2, j] * (q - ref[j]) * (q - ref[j])
    return cost


@jit
def nearest_of(raw, ok, limits, ref, out):
    """The row of ``raw`` (S, 6) nearest ``ref`` (written into ``out``), −1 if none; and the
    mask of rows with an equivalent within the limits (bit r: row r). Shared by the
    spherical-wrist and offset-wrist kernels."""
    best = -1
    best_cost = np.inf
    mask = 0
    for row in range(raw.shape[0]):
        if not ok[row]:
            continue
        cost = branch_cost(raw, row, limits, ref, 0.0)
        if cost == np.inf:
            continue
        mask |= 1 << row
        if cost < best_cost:
            best, best_cost = row, cost
    if best >= 0:
        for j in range(6):
            out[j] = _choice(raw[best, j], ref[j], limits[0, j], limits[1, j])
    return best, mask


@jit
def distinct(raw, middle, lower, upper, out):
    """The rows of ``raw`` (S, n) [rad] that have an equivalent within the limits, each as the
    equivalent nearest ``middle`` (:func:`_choice`), written into the first rows of ``out``
    (S, n), then those equal (within 1e-9 rad per joint, modulo 2π) to an earlier such row
    dropped; returns how many are left. The compiled form of
    :meth:`kinplan.ik.base.ClosedFormIK._distinct` (the same rows to the bit), for
    ``solutions``: numpy's form spent ~90 % of a call on small arrays."""
    rows, n = raw.shape
    count = 0
    for r in range(rows):
        within = True
        for j in range(n):
            out[count, j] = _choice(raw[r, j], middle[j], lower[j], upper[j])
            within = within and out[count, j] == out[count, j]
        if within:
            count += 1
    repeated = np.zeros(count, dtype=np.bool_)
    for r in range(count):
        for earlier in range(r):  # every earlier row, repeated or not (as numpy's triu)
            gap = 0.0
            for j in range(n):
                turn = out[earlier, j] - out[r, j]
                gap = max(gap, abs(turn - TAU * np.round(turn / TAU)))
            if gap <= DISTINCT_TOL:
                repeated[r] = True
                break
    kept = 0
    for r in range(count):
        if not repeated[r]:
            for j in range(n):
                out[kept, j] = out[r, j]
            kept += 1
    return kept


@jit
def pose_finite(position, rotation, ref):
    """Whether a pose (3,), (3, 3) and a reference (6,) hold no NaN or inf (by their sum, as
    the numpy path checks them)."""
    total = 0.0
    for i in range(3):
        total += position[i] + rotation[i, 0] + rotation[i, 1] + rotation[i, 2]
    for j in range(6):
        total += ref[j]
    return math.isfinite(total)


@jit
def solutions(k, limits, middle, position, rotation, fill):
    """Every distinct solution of one pose within the limits, each as its equivalent nearest
    ``middle`` (:meth:`kinplan.ik.base.ClosedFormIK.solutions`: :func:`branches` then
    :func:`distinct`, in one call): (k, 6) [rad], or None for an input with a NaN or inf (the
    caller reports it). ``fill`` [rad] (6,): the values of joints free at a singularity."""
    if not pose_finite(position, rotation, fill):
        return None
    raw, ok = np.empty((8, 6)), np.empty(8, dtype=np.bool_)
    branches(k, position, rotation, fill, raw, ok, np.empty((WORK_ROWS, 3)), limits)
    for b in range(8):
        if not ok[b]:
            raw[b, :] = np.nan
    out = np.empty((8, 6))
    return out[: distinct(raw, middle, limits[0], limits[1], out)]


@jit
def nearest(k, limits, position, rotation, ref, out):
    """The solution nearest ``ref`` [rad] (6,) written into ``out``; returns its branch, −1
    when no branch has a solution within the limits, :data:`NOT_FINITE` for an input with a
    NaN or inf.

    Args:
        k: The packed geometry (22, 3).
        limits: Rows lower, upper [rad] and weights, shape (3, 6).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        ref: Reference configuration; also the value of joints free at a singularity.
        out: Written with the solution.
    """
    if not pose_finite(position, rotation, ref):
        return NOT_FINITE
    raw = np.empty((8, 6))
    ok = np.empty(8, dtype=np.bool_)
    branches(k, position, rotation, ref, raw, ok, np.empty((WORK_ROWS, 3)), limits)
    best, _ = nearest_of(raw, ok, limits, ref, out)
    return best


@jit
def nearest_many(k, limits, positions, rotations, refs, q, branch, mask):
    """:func:`nearest` of many poses, each with its own reference: ``q`` (N, 6), ``branch``
    (N,) (−1: none) and ``mask`` (N,) (bit b: branch b within the limits) written."""
    raw = np.empty((8, 6))
    ok = np.empty(8, dtype=np.bool_)
    out = np.empty(6)
    work = np.empty((WORK_ROWS, 3))
    for i in range(positions.shape[0]):
        branches(k, positions[i], rotations[i], refs[i], raw, ok, work, limits)
        best, bits = nearest_of(raw, ok, limits, refs[i], out)
        branch[i] = best
        mask[i] = bits
        for j in range(6):
            q[i, j] = out[j] if best >= 0 else np.nan
