"""The panda closed form and its θ7 search, compiled (numba): the nearest solution of a pose.

:meth:`kinplan.ik.panda.PandaIK.nearest` tries one θ7 after another and, for each, solves the
six other joints in closed form, keeping the solution nearest the reference (branch and bound
over the θ4, wrist and shoulder branches). In plain Python floats one θ7 costs about 20 µs and
the search around it some more per pose; here both are compiled:

* :func:`nearest_for_q7` (``_solve``): one θ7, a twin of :meth:`PandaIK._solve
  <kinplan.ik.panda.PandaIK>` with ``prune=True``, step for step (the same subproblems, angle
  choices, tolerances and tie-breaking order), tested against it on thousands of random poses,
  θ7 values and references, and on crafted geometries, free angles and limit edges
  (``tests/ik/test_panda_kernel.py``);
* :func:`search` (behind ``PandaIK.nearest``) and :func:`search_many` (behind
  ``PandaIK.nearest_many``, pose after pose): the whole θ7 search, a twin of the Python one —
  the pose's θ7-independent part (:func:`_prepare`), the θ7 intervals where the elbow reaches
  (:func:`_intervals`, bit for bit), the first value, the middle, the ±steps and the grids
  moved into the intervals with the "already tried" rule (:func:`stage_values`: a linear scan
  of the values tried for Python's set of floats), the same θ7 values in the same order
  (``tests/ik/test_panda_search_kernel.py``). Only the input checks' error messages and the
  final check by Pinocchio's forward kinematics stay in Python.

The two agree to the last bit but one: Python squares a distance with ``pow`` and numba with a
product, so two branches whose distances tie to the last bit may be chosen differently (they
then differ by ~1e-15 rad; on 3,200 random cases of the stock panda every answer was the same
to the bit). Without numba (or with ``KINPLAN_JIT=0``) :func:`available` is False and the
Python search runs. Compiled code is cached on disk.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import inline, jit, numba
from kinplan.ik.panda_geometry import matmul, matvec, rotate_cs, rotation_matrix_cs
from kinplan.ik.screws import CLAMP, FREE_TOL, HALF_TURN_SAFE, LIMIT_TOL, TAU

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


def nearest_for_q7(
    arrays: tuple[np.ndarray, ...],
    seen: np.ndarray,
    rotation_tm: np.ndarray,
    q7: float,
    q_ref: np.ndarray,
    out: np.ndarray,
) -> float:
    """The solution for θ7 = ``q7`` nearest ``q_ref`` (weighted Σ wᵢ Δqᵢ²), written into
    ``out`` (7,); returns its distance [rad²], or inf when no branch lies within the limits.

    Args:
        arrays: The solver's geometry and precomputed terms (``PandaIK.kernel_constants``):
            axes (7, 3); vectors (6, 3): p7, w, s − p4, w − p4, e3, unused; elbow terms (4,):
            |s|² + |w|², w·s∥, amplitude and phase of θ4's cosine; axis pairs (2, 11): wrist
            (axes 5, 6) and shoulder (axes 2, 1) as (a, b, a·b, a × b, |a × b|²); limits
            (3, 7): lower, upper, weights.
        seen: ``M T⁻¹ s`` [m] of the pose (the shoulder centre seen from the tool).
        rotation_tm: ``R_T M_Rᵀ`` of the pose (3, 3).
        q7: θ7 [rad], within its limits.
        q_ref: The reference configuration [rad] (7,).
        out: Written with the solution when one is found.
    """
    axes, vectors, elbow, pairs, limits = arrays
    return float(_nearest(axes, vectors, elbow, pairs, limits, seen, rotation_tm, q7, q_ref, out))


# ---------------------------------------------------------------------------- compiled code
# The per-θ7 solve reads the solver's constants and the pose's terms as tuples of numbers
# (:func:`_geometry`, read once a batch), and its helpers take and return numbers (vectors as
# 3-tuples): an array passed to a compiled function, or a row taken out of one, has its
# reference count kept atomically (see kinplan.compiled.inline), which cost a third of this
# kernel's time.


@inline
def _choice(value, ref, clipped, lower, upper, weight):
    """(found, q, w (q − ref)²): the 2π-equivalent of ``value`` within the limits nearest the
    clipped reference (``joint_choice`` and ``near_angle`` of :mod:`kinplan.ik.screws`)."""
    q = value + TAU * np.rint((clipped - value) / TAU)
    if not (lower <= q <= upper and -HALF_TURN_SAFE < q - clipped < HALF_TURN_SAFE):
        k = np.rint((clipped - value) / TAU)
        candidate = value + TAU * k
        if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL and (
            abs(candidate - clipped) < HALF_TURN_SAFE
        ):
            q = min(max(candidate, lower), upper)
        else:
            found = False
            best, best_distance = 0.0, np.inf
            for shift in (k - 1.0, k, k + 1.0):
                candidate = value + TAU * shift
                if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:
                    distance = abs(candidate - clipped)
                    if distance < best_distance:
                        best, best_distance, found = candidate, distance, True
            if not found:
                return False, 0.0, 0.0
            q = min(max(best, lower), upper)
    return True, q, weight * (q - ref) ** 2


#: The Python path's own tuple helpers compiled inline (:mod:`kinplan.ik.panda_geometry`):
#: ``rotate_cs(v, axis, c, s)`` turns v about the unit axis by the angle of cosine c and sine s
#: (Rodrigues), ``rotation_matrix_cs(axis, c, s)`` is that rotation as a row-major 9-tuple,
#: ``matmul`` and ``matvec`` multiply 9-tuples and 3-tuples.
_rotate = inline(rotate_cs)
_rotation = inline(rotation_matrix_cs)
_matmul = inline(matmul)
_matvec = inline(matvec)


@inline
def _pair(pair, u, v, free_a, free_b):
    """Angles (θa, θb) with ``Rb(θb) Ra(θa) u = v`` (Paden–Kahan subproblem 2, as
    ``_AxisPair.solve``) for the axis pair ``pair`` (a, b, a·b, a × b, |a × b|²: 11 numbers;
    u, v: 3-tuples): (how many: 0, 1 or 2, θa and θb of the first, of the second)."""
    ax, ay, az, bx, by, bz, c, nx, ny, nz, n2 = pair
    ux, uy, uz = u
    vx, vy, vz = v
    ka, kb = ux * ax + uy * ay + uz * az, vx * bx + vy * by + vz * bz
    alpha = (ka - c * kb) / n2
    beta = (kb - c * ka) / n2
    length2 = 0.5 * (ux * ux + uy * uy + uz * uz + vx * vx + vy * vy + vz * vz)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c
    if rest < -CLAMP * max(length2, 1e-300):
        return 0, 0.0, 0.0, 0.0, 0.0
    gamma = math.sqrt(max(rest, 0.0) / n2)
    un, ub = ux * nx + uy * ny + uz * nz, ux * bx + uy * by + uz * bz
    vn, va = vx * nx + vy * ny + vz * nz, vx * ax + vy * ay + vz * az
    sin_a, sin_a_g, cos_a = -beta * un, ub - c * ka, alpha * ka + beta * ub - ka * ka
    sin_b, sin_b_g, cos_b = -alpha * vn, va - c * kb, alpha * va + beta * kb - kb * kb
    px, py, pz = ux - ka * ax, uy - ka * ay, uz - ka * az
    a_free = px * px + py * py + pz * pz < FREE_TOL**2
    px, py, pz = vx - kb * bx, vy - kb * by, vz - kb * bz
    b_free = px * px + py * py + pz * pz < FREE_TOL**2
    first_a = free_a if a_free else math.atan2(sin_a + gamma * sin_a_g, cos_a + gamma * un)
    first_b = free_b if b_free else math.atan2(sin_b + gamma * sin_b_g, cos_b + gamma * vn)
    if not gamma > 0.0:
        return 1, first_a, first_b, 0.0, 0.0
    g = -gamma
    second_a = free_a if a_free else math.atan2(sin_a + g * sin_a_g, cos_a + g * un)
    second_b = free_b if b_free else math.atan2(sin_b + g * sin_b_g, cos_b + g * vn)
    return 2, first_a, first_b, second_a, second_b


@inline
def _angle_about(axis, a, b, free):
    """The angle about the unit ``axis`` taking ``a`` towards ``b`` (3-tuples; subproblem 1),
    or ``free`` when either lies on the axis (``_angle_about`` of :mod:`kinplan.ik.panda`)."""
    ux, uy, uz = axis
    x, y, z = a
    u, v, w = b
    k = ux * x + uy * y + uz * z
    x, y, z = x - k * ux, y - k * uy, z - k * uz
    k = ux * u + uy * v + uz * w
    u, v, w = u - k * ux, v - k * uy, w - k * uz
    if x * x + y * y + z * z < FREE_TOL**2 or u * u + v * v + w * w < FREE_TOL**2:
        return free
    return math.atan2(
        ux * (y * w - z * v) + uy * (z * u - x * w) + uz * (x * v - y * u), x * u + y * v + z * w
    )


@inline
def _row3(a, i):
    """Row ``i`` of the array ``a`` as a 3-tuple (also :func:`_row7`, :func:`_row11`)."""
    return a[i, 0], a[i, 1], a[i, 2]


@inline
def _row7(a, i):
    return a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4], a[i, 5], a[i, 6]


@inline
def _row11(a, i):
    return (
        a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4], a[i, 5], a[i, 6], a[i, 7], a[i, 8],
        a[i, 9], a[i, 10],
    )  # fmt: skip


@jit
def _geometry(axes, vectors, elbow, pairs, limits):
    """The solver's constants (``PandaIK.kernel_constants``) as tuples: (axes (7 3-tuples);
    p7, w, s − p4, w − p4, e3 (3-tuples); the elbow terms (4); the wrist and shoulder axis
    pairs (11 each); lower, upper limits and weights (7 each))."""
    return (
        (
            _row3(axes, 0), _row3(axes, 1), _row3(axes, 2), _row3(axes, 3), _row3(axes, 4),
            _row3(axes, 5), _row3(axes, 6),
        ),
        (_row3(vectors, 0), _row3(vectors, 1), _row3(vectors, 2), _row3(vectors, 3),
         _row3(vectors, 4)),
        (elbow[0], elbow[1], elbow[2], elbow[3]),
        (_row11(pairs, 0), _row11(pairs, 1)),
        (_row7(limits, 0), _row7(limits, 1), _row7(limits, 2)),
    )  # fmt: skip


@inline
def _pose_terms(seen, rotation_tm):
    """M T⁻¹ s (3-tuple) and R_T M_Rᵀ (9-tuple, row-major) of :func:`_prepare`'s arrays."""
    m = rotation_tm
    return (seen[0], seen[1], seen[2]), (
        m[0, 0], m[0, 1], m[0, 2], m[1, 0], m[1, 1], m[1, 2], m[2, 0], m[2, 1], m[2, 2]
    )  # fmt: skip


@inline
def _clipped(q_ref, lower, upper):
    """The reference (7,) as a 7-tuple and clipped into the limits, as
    ``np.minimum(np.maximum(q_ref, lower), upper)``."""
    r = (q_ref[0], q_ref[1], q_ref[2], q_ref[3], q_ref[4], q_ref[5], q_ref[6])
    return r, (
        np.minimum(np.maximum(r[0], lower[0]), upper[0]),
        np.minimum(np.maximum(r[1], lower[1]), upper[1]),
        np.minimum(np.maximum(r[2], lower[2]), upper[2]),
        np.minimum(np.maximum(r[3], lower[3]), upper[3]),
        np.minimum(np.maximum(r[4], lower[4]), upper[4]),
        np.minimum(np.maximum(r[5], lower[5]), upper[5]),
        np.minimum(np.maximum(r[6], lower[6]), upper[6]),
    )


@jit
def _nearest(axes, vectors, elbow, pairs, limits, seen, rotation_tm, q7, q_ref, out):
    """:func:`nearest_for_q7` (compiled)."""
    geometry = _geometry(axes, vectors, elbow, pairs, limits)
    ref, clipped = _clipped(q_ref, geometry[4][0], geometry[4][1])
    seen_t, rotation_t = _pose_terms(seen, rotation_tm)
    return _solve(geometry, seen_t, rotation_t, q7, ref, clipped, out, np.empty((4, 6)))


@jit
def _solve(geometry, seen, rotation_tm, q7, q_ref, clipped, out, wrists):
    """:func:`_nearest` of the constants as tuples (:func:`_geometry`), the pose's terms as
    tuples (:func:`_pose_terms`), the reference and its clipped values as 7-tuples, and a work
    array (4, 6) for the wrist part of each branch; ``out`` (7,) is written only with a
    solution. Returns the solution's distance [rad²] (inf: none)."""
    axes, vectors, elbow, pairs, limits = geometry
    a1, a2, a3, a4, a5, a6, a7 = axes
    p7, w, s4, w4, e3 = vectors
    wrist_pair, shoulder_pair = pairs
    lower, upper, weights = limits
    # y = exp(S7 θ7) M T⁻¹ s, v = y − w
    c7, s7 = math.cos(q7), math.sin(q7)
    y = _rotate((seen[0] - p7[0], seen[1] - p7[1], seen[2] - p7[2]), a7, c7, s7)
    v = ((y[0] + p7[0]) - w[0], (y[1] + p7[1]) - w[1], (y[2] + p7[2]) - w[2])
    base = weights[6] * (q7 - q_ref[6]) ** 2
    # θ4 (up to two): |exp(−S4 θ4) s − w|² = |v|²
    lengths, const, amplitude, phase = elbow
    target = 0.5 * (lengths - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])) - const
    ratio = target / amplitude
    if abs(ratio) > 1.0 + CLAMP:
        return np.inf
    spread = math.acos(min(max(ratio, -1.0), 1.0))
    raw_count = 1 if spread == 0.0 else 2
    # the wrist part of every branch: distance so far, θ4, θ5, θ6, cos and sin of −θ4
    count = 0
    for i in range(raw_count):
        if raw_count == 1:
            raw4 = -phase
        else:
            raw4 = -(phase + spread) if i == 0 else -(phase - spread)
        ok4, q4, cost4 = _choice(raw4, q_ref[3], clipped[3], lower[3], upper[3], weights[3])
        if not ok4:
            continue
        cost4 += base
        cos4, sin4 = math.cos(q4), -math.sin(q4)
        u = _rotate(s4, a4, cos4, sin4)
        u = (u[0] - w4[0], u[1] - w4[1], u[2] - w4[2])
        found, n5a, n6a, n5b, n6b = _pair(wrist_pair, u, v, -clipped[4], -clipped[5])
        for j in range(found):
            ok5, q5, cost5 = _choice(
                -(n5a if j == 0 else n5b), q_ref[4], clipped[4], lower[4], upper[4], weights[4],
            )  # fmt: skip
            if not ok5:
                continue
            ok6, q6, cost6 = _choice(
                -(n6a if j == 0 else n6b), q_ref[5], clipped[5], lower[5], upper[5], weights[5],
            )  # fmt: skip
            if ok6:
                wrists[count, 0] = cost4 + cost5 + cost6
                wrists[count, 1] = q4
                wrists[count, 2] = q5
                wrists[count, 3] = q6
                wrists[count, 4] = cos4
                wrists[count, 5] = sin4
                count += 1
    # nearest first (a stable insertion sort, as Python's sort)
    for i in range(1, count):
        r0, r1, r2 = wrists[i, 0], wrists[i, 1], wrists[i, 2]
        r3, r4, r5 = wrists[i, 3], wrists[i, 4], wrists[i, 5]
        j = i - 1
        while j >= 0 and wrists[j, 0] > r0:
            for k in range(6):
                wrists[j + 1, k] = wrists[j, k]
            j -= 1
        wrists[j + 1, 0], wrists[j + 1, 1], wrists[j + 1, 2] = r0, r1, r2
        wrists[j + 1, 3], wrists[j + 1, 4], wrists[j + 1, 5] = r3, r4, r5
    if count == 0:
        return np.inf
    rotation_p = _matmul(rotation_tm, _rotation(a7, c7, -s7))  # R_P = R_T M_Rᵀ Rot(ω7, −θ7)
    bound = np.inf
    for i in range(count):
        cost6, q4, q5, q6 = wrists[i, 0], wrists[i, 1], wrists[i, 2], wrists[i, 3]
        cos4, sin4 = wrists[i, 4], wrists[i, 5]
        if cost6 >= bound:
            break
        cos5, sin5, cos6, sin6 = math.cos(q5), -math.sin(q5), math.cos(q6), -math.sin(q6)
        h4 = _rotate(a3, a4, cos4, sin4)
        g3 = _matvec(rotation_p, _rotate(_rotate(h4, a5, cos5, sin5), a6, cos6, sin6))
        h4 = _rotate(e3, a4, cos4, sin4)
        ge = _matvec(rotation_p, _rotate(_rotate(h4, a5, cos5, sin5), a6, cos6, sin6))
        found, t2a, t1a, t2b, t1b = _pair(shoulder_pair, a3, g3, clipped[1], clipped[0])
        for j in range(found):
            t2, t1 = (t2a, t1a) if j == 0 else (t2b, t1b)
            ok1, q1, cost1 = _choice(t1, q_ref[0], clipped[0], lower[0], upper[0], weights[0])
            ok2, q2, cost2 = _choice(t2, q_ref[1], clipped[1], lower[1], upper[1], weights[1])
            if not (ok1 and ok2):
                continue
            total = cost6 + cost1 + cost2
            if total >= bound:
                continue
            h = _rotate(ge, a1, math.cos(-t1), math.sin(-t1))
            h = _rotate(h, a2, math.cos(-t2), math.sin(-t2))
            t3 = _angle_about(a3, e3, h, clipped[2])
            ok3, q3, cost3 = _choice(t3, q_ref[2], clipped[2], lower[2], upper[2], weights[2])
            if not ok3:
                continue
            total += cost3
            if total >= bound:
                continue
            out[0], out[1], out[2], out[3] = q1, q2, q3, q4
            out[4], out[5], out[6] = q5, q6, q7
            bound = total
    return bound


# ---------------------------------------------------------------------------- the θ7 search
#: What :func:`search` returns: a solution written, none found, an input with a NaN or inf.
FOUND, NONE, NOT_FINITE = 1, 0, -2


@inline
def _prepare(frame, position, rotation, seen, rotation_tm):
    """``M T⁻¹ s`` [m] into ``seen`` (3,) and ``R_T M_Rᵀ`` into ``rotation_tm`` (3, 3): the
    θ7-independent part of a pose (``PandaIK._prepare``, the same operations in the same
    order)."""
    d0 = frame[0, 0] - position[0]
    d1 = frame[0, 1] - position[1]
    d2 = frame[0, 2] - position[2]
    x = rotation[0, 0] * d0 + rotation[1, 0] * d1 + rotation[2, 0] * d2  # R_Tᵀ (s − p_T)
    y = rotation[0, 1] * d0 + rotation[1, 1] * d1 + rotation[2, 1] * d2
    z = rotation[0, 2] * d0 + rotation[1, 2] * d1 + rotation[2, 2] * d2
    for i in range(3):  # row 1 + i of frame: row i of M_R
        seen[i] = (frame[1 + i, 0] * x + frame[1 + i, 1] * y + frame[1 + i, 2] * z) + frame[4, i]
        for j in range(3):  # (R_T M_Rᵀ)[i, j], M_Rᵀ in rows 5–7
            rotation_tm[i, j] = (
                rotation[i, 0] * frame[5, j] + rotation[i, 1] * frame[6, j]
            ) + rotation[i, 2] * frame[7, j]


@inline
def _intervals(axes, vectors, frame, lo7, hi7, seen, starts, ends):
    """The θ7 intervals [rad] within [lo7, hi7] where the elbow reaches, sorted and disjoint,
    into ``starts``/``ends``; returns how many (``PandaIK._elbow_q7_intervals`` and
    ``intervals_within``, the same operations in the same order)."""
    a0, a1, a2 = axes[6, 0], axes[6, 1], axes[6, 2]  # ω7
    c0, c1, c2 = frame[8, 0], frame[8, 1], frame[8, 2]  # p7 − w
    d0, d1, d2 = seen[0] - vectors[0, 0], seen[1] - vectors[0, 1], seen[2] - vectors[0, 2]
    ad = a0 * d0 + a1 * d1 + a2 * d2
    ac = a0 * c0 + a1 * c1 + a2 * c2
    cos_part = (c0 * d0 + c1 * d1 + c2 * d2) - ac * ad
    x, y, z = a1 * d2 - a2 * d1, a2 * d0 - a0 * d2, a0 * d1 - a1 * d0  # a × d
    sin_part = c0 * x + c1 * y + c2 * z
    mean = ((d0 * d0 + d1 * d1 + d2 * d2) + (c0 * c0 + c1 * c1 + c2 * c2)) + (2.0 * ac) * ad
    amplitude = 2.0 * math.sqrt(cos_part * cos_part + sin_part * sin_part)
    low, high = frame[9, 0], frame[9, 1]
    if amplitude < FREE_TOL:  # θ7 does not change the distance
        if low <= mean <= high:
            starts[0], ends[0] = lo7, hi7
            return 1
        return 0
    c_low, c_high = (low - mean) / amplitude, (high - mean) / amplitude
    if c_low > 1.0 or c_high < -1.0:
        return 0
    near = math.acos(1.0 if 1.0 < c_high else c_high)
    far = math.acos(-1.0 if -1.0 > c_low else c_low)
    phi = math.atan2(sin_part, cos_part)
    count = 0
    for piece in range(2):
        start = phi + near if piece == 0 else phi - far
        end = phi + far if piece == 0 else phi - near
        for k in range(math.ceil((lo7 - end) / TAU), math.floor((hi7 - start) / TAU) + 1):
            a_k, b_k = start + k * TAU, end + k * TAU
            a_k = lo7 if lo7 > a_k else a_k
            b_k = hi7 if hi7 < b_k else b_k
            if a_k <= b_k:  # sorted by (start, end) as it goes in
                i = count
                while i > 0 and (
                    starts[i - 1] > a_k or (starts[i - 1] == a_k and ends[i - 1] > b_k)
                ):
                    starts[i], ends[i] = starts[i - 1], ends[i - 1]
                    i -= 1
                starts[i], ends[i] = a_k, b_k
                count += 1
    merged = 0
    for i in range(count):
        if merged > 0 and starts[i] <= ends[merged - 1]:
            if ends[i] > ends[merged - 1]:
                ends[merged - 1] = ends[i]
        else:
            starts[merged], ends[merged] = starts[i], ends[i]
            merged += 1
    return merged


@inline
def _project(value, starts, ends, count, margin):
    """``panda_intervals.project``: ``value`` if one of the ``count`` intervals holds it, else
    the nearest edge moved ``margin`` inside (the middle of a narrower interval)."""
    best, best_distance = value, np.inf
    for i in range(count):
        a, b = starts[i], ends[i]
        if a <= value <= b:
            return value
        half = 0.5 * (b - a)
        m = half if half < margin else margin
        edge = a + m if value < a else b - m
        distance = abs(edge - value)
        if distance < best_distance:
            best, best_distance = edge, distance
    return best


@inline
def stage_values(stage, bounds, stages, sizes, starts, ends, count, tried, n_tried, values):
    """The θ7 values [rad] of one stage after the first value and the middle
    (``PandaIK._q7_stages``): each clipped into the limits and moved into the intervals, those
    equal to a value tried before (``tried[:n_tried]``, this stage's own included) skipped.

    Args:
        stage: 0, 1, …: q7_ref ± each step in turn, then each grid.
        bounds: (q7_ref (clipped into the limits), lower, upper limit, edge margin) [rad].
        stages, sizes: As :func:`search`.
        starts, ends, count: The intervals (:func:`_intervals`).
        tried: The values tried so far, ``n_tried`` of them: the fresh ones are appended.
        values: Written with the fresh values.

    Returns:
        (how many fresh values, ``n_tried`` after them).
    """
    q7_ref, lo7, hi7, margin = bounds[0], bounds[1], bounds[2], bounds[3]
    steps = sizes[0]
    if stage < steps:
        width, offset = 2, 0
    else:
        width, offset = sizes[stage - steps + 1], steps
        for grid in range(1, stage - steps + 1):
            offset += sizes[grid]
    fresh = 0
    for i in range(width):
        if stage < steps:
            raw = q7_ref + stages[stage] if i == 0 else q7_ref - stages[stage]
        else:
            raw = stages[offset + i]
        raw = lo7 if lo7 > raw else raw  # min(max(raw, lo7), hi7), as Python's
        raw = hi7 if hi7 < raw else raw
        value = _project(raw, starts, ends, count, margin)
        old = False
        for j in range(n_tried):  # Python's "value in tried" of a set of floats
            if tried[j] == value:
                old = True
                break
        if not old:
            tried[n_tried] = value
            n_tried += 1
            values[fresh] = value
            fresh += 1
    return fresh, n_tried


@inline
def _try(geometry, seen, rotation_tm, values, count, q_ref, clipped, solution, wrists, out):
    """The nearest solution over the first ``count`` θ7 ``values`` (the first on ties), into
    ``out`` (``solution``, ``wrists``: scratch; the other arguments as :func:`_solve`'s);
    returns whether there is one (``PandaIK._best``)."""
    best = np.inf
    for i in range(count):
        cost = _solve(geometry, seen, rotation_tm, values[i], q_ref, clipped, solution, wrists)
        if cost < best:
            best = cost
            for j in range(7):
                out[j] = solution[j]
    return best < np.inf


@jit
def _workspace(limits, stages, sizes):
    """The work arrays of :func:`_search`: (seen (3,), R_T M_Rᵀ (3, 3), interval starts and
    ends (2, room), a stage's values, the values tried, a solution (7,), :func:`_solve`'s
    work array (4, 6), the search's settings (4,))."""
    lo7, hi7 = limits[0, 6], limits[1, 6]
    room = 2 * (int((hi7 - lo7 + math.pi) / TAU) + 3)  # pieces of ≤ π, each shifted by turns
    widest = 2
    for stage in range(1, sizes.size):
        widest = max(widest, sizes[stage])
    return (
        np.empty(3), np.empty((3, 3)), np.empty((2, room)), np.empty(widest),
        np.empty(2 + sizes[0] + stages.size), np.empty(7), np.empty((4, 6)),
        np.empty(4),
    )  # fmt: skip


@inline
def _finite(position, rotation, q_ref):
    """Whether the pose and the reference pass the Python path's checks: the sums of the
    position, then the rotation (row-major), then the reference are finite, added as there."""
    p = 0.0
    for i in range(3):
        p += position[i]
    r = 0.0
    for i in range(3):
        for j in range(3):
            r += rotation[i, j]
    q = 0.0
    for j in range(7):
        q += q_ref[j]
    return math.isfinite(q) and math.isfinite(p + r)


@jit
def search(
    axes, vectors, elbow, pairs, limits, frame, stages, sizes, position, rotation, q_ref, out
):
    """``PandaIK.nearest`` of one pose, compiled: the θ7 search with its per-θ7 solve.

    The same θ7 values in the same order as the Python search, the same "already tried" rule
    (a value equal to one tried before is skipped), the same tie-breaking.

    Args:
        axes, vectors, elbow, pairs, limits: ``PandaIK.kernel_constants`` (see
            :func:`nearest_for_q7`).
        frame: ``PandaIK.search_constants``' first array (10, 3): rows s; M_R (3 rows); M_t;
            M_Rᵀ (3 rows); p7 − w; (low, high) of |y − w|² [m²] and the edge margin [rad].
        stages: The ±steps [rad] then the grids' θ7 values [rad], one after the other (1-D).
        sizes: How many of ``stages`` each stage takes: the steps, then each grid (int64).
        position: Tool position in the world frame [m] (3,).
        rotation: Tool rotation in the world frame (3, 3).
        q_ref: Reference configuration [rad] (7,).
        out: Written with the solution when one is found (7,).

    Returns:
        :data:`FOUND`, :data:`NONE` or :data:`NOT_FINITE`.
    """
    if not _finite(position, rotation, q_ref):
        return NOT_FINITE
    seen, rotation_tm, bounds, values, tried, solution, wrists, settings = _workspace(
        limits, stages, sizes
    )
    return _search(
        _geometry(axes, vectors, elbow, pairs, limits), axes, vectors, frame, stages, sizes,
        position, rotation, q_ref, out, seen, rotation_tm, bounds[0], bounds[1], values, tried,
        solution, wrists, settings,
    )  # fmt: skip


@jit
def _search(
    geometry, axes, vectors, frame, stages, sizes, position, rotation, q_ref, out, seen,
    rotation_tm, starts, ends, values, tried, solution, wrists, settings,
):  # fmt: skip
    """:func:`search` of finite input, the constants also as tuples (:func:`_geometry`), its
    work arrays given (:func:`_workspace`)."""
    lower, upper = geometry[4][0], geometry[4][1]
    lo7, hi7 = lower[6], upper[6]
    _prepare(frame, position, rotation, seen, rotation_tm)
    count = _intervals(axes, vectors, frame, lo7, hi7, seen, starts, ends)
    if count == 0:
        return NONE
    ref7 = q_ref[6]
    q7_ref = lo7 if lo7 > ref7 else ref7  # min(max(ref, lo), hi), as Python's
    q7_ref = hi7 if hi7 < q7_ref else q7_ref
    nearest, key = 0, np.inf
    for i in range(count):
        a, b = starts[i] - q7_ref, q7_ref - ends[i]
        distance = b if b > a else a
        if distance < key:
            nearest, key = i, distance
    start, end = starts[nearest], ends[nearest]
    if start <= q7_ref <= end:
        first = q7_ref
    elif q7_ref < start:
        first = start + 0.25 * (end - start)
    else:
        first = end - 0.25 * (end - start)
    middle = 0.5 * (start + end)
    ref, clipped = _clipped(q_ref, lower, upper)
    seen_t, rotation_t = _pose_terms(seen, rotation_tm)
    values[0] = first
    if _try(geometry, seen_t, rotation_t, values, 1, ref, clipped, solution, wrists, out):
        return FOUND
    values[0] = middle
    if middle != first and _try(
        geometry, seen_t, rotation_t, values, 1, ref, clipped, solution, wrists, out
    ):
        return FOUND
    # then q7_ref ± each step, then each grid: the values not tried before, moved into the set
    tried[0], tried[1] = first, middle  # then every fresh value
    n_tried = 2
    settings[0], settings[1], settings[2], settings[3] = q7_ref, lo7, hi7, frame[9, 2]
    for stage in range(sizes[0] + sizes.size - 1):
        fresh, n_tried = stage_values(
            stage, settings, stages, sizes, starts, ends, count, tried, n_tried, values
        )
        if fresh and _try(
            geometry, seen_t, rotation_t, values, fresh, ref, clipped, solution, wrists, out
        ):
            return FOUND
    return NONE


@jit
def search_many(
    axes, vectors, elbow, pairs, limits, frame, stages, sizes, positions, rotations, refs, q, found
):
    """:func:`search` of many poses, each with its own reference: ``q`` (N, 7) [rad] and
    ``found`` (N,) written (rows of ``q`` without a solution are left as they are)."""
    out = np.empty(7)
    seen, rotation_tm, bounds, values, tried, solution, wrists, settings = _workspace(
        limits, stages, sizes
    )
    starts, ends = bounds[0], bounds[1]
    geometry = _geometry(axes, vectors, elbow, pairs, limits)  # read once: see _geometry
    for n in range(positions.shape[0]):
        position, rotation, ref = positions[n], rotations[n], refs[n]
        if not _finite(position, rotation, ref):
            found[n] = False
            continue
        status = _search(
            geometry, axes, vectors, frame, stages, sizes, position, rotation, ref, out, seen,
            rotation_tm, starts, ends, values, tried, solution, wrists, settings,
        )  # fmt: skip
        found[n] = status == FOUND
        if status == FOUND:
            for j in range(7):
                q[n, j] = out[j]
