"""The first three joints of a spherical-wrist arm with axes 2 ∦ 3, compiled (numba): the
positions ``(θ1, θ2, θ3)`` that put the wrist centre at the target's, ``e1 e2 e3 c = c_T``, by
the mode's Paden–Kahan subproblems, and their Newton polish, for
:mod:`~kinplan.ik.spherical_general_kernel`.

* axes 1, 2 meeting at ``o`` (:func:`meeting_12`): θ3 by subproblem 3,
  ``‖R3 (c − p3) − (o − p3)‖ = ‖c_T − o‖``, then ``R(h2, θ2) x = R(h1, −θ1)(c_T − o)`` with
  ``x = e3 c − o`` by subproblem 2; position ``2·first + second``;
* axes 2, 3 meeting at ``o`` (:func:`meeting_23`): −θ1 by subproblem 3,
  ``‖R(h1, −θ1)(c_T − p1) − (o − p1)‖ = ‖c − o‖``, then
  ``R(h3, θ3)(c − o) = R(h2, −θ2)(e1⁻¹ c_T − o)`` by subproblem 2;
* general (:func:`general_shoulder`): subproblem 5. With ``o`` on axis 2,
  ``z = e1⁻¹ c_T − o`` runs on a circle about axis 1 (θ1) and ``y = e3 c − o`` on a circle
  about axis 3 (θ3); ``R(h2, θ2) y = z`` needs the same height ``H = h2·z = h2·y`` and the same
  norm. On each circle the height fixes the point up to a mirror, and the norm is
  ``Pᵢ(H) ± √Qᵢ(H)`` (P linear, Q quadratic), so ``P1 ± √Q1 = P3 ± √Q3``: the quartic
  ``E = D⁴ − 2 D² (Q1 + Q3) + (Q1 − Q3)²`` with ``D = P3 − P1``, the product of the four sign
  choices. Its real roots on the heights both circles reach
  (:func:`~kinplan.ik.spherical_general_quartic.real_roots`) give the positions in the order
  of H, each root with the mirror choices whose norms agree (where an axis pair nearly
  meets, two positions share a nearly double root, one on each mirror).

Where the wrist centre lies on axis 1, θ1 is free for the position; it is then the
reference's when the wrist can still match the rotation, else the nearest value at the edge of
the wrist's reach (:func:`free_shoulder`). A free θ2 (e3 c − o on axis 2) takes the
reference's value. :func:`polish` then takes Newton steps on ``e1 e2 e3 c = c_T`` (3×3,
halved where they overshoot) so that rounding near a singularity does not cost the 1e-9 check.

Without numba, or with ``KINPLAN_JIT=0`` at import, the functions run as plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.ik.screws import CLAMP, FREE_TOL
from kinplan.ik.spherical_general_quartic import real_roots
from kinplan.ik.subproblems import FREE_ROOM
from kinplan.ik.wrist_offset_branches import _pair, angle_to, inline, jit, turn, wrap

#: Positions per pose at most (subproblem 5's quartic has four roots).
POSITIONS = 4
#: Position candidates of subproblem 5 before the check (a root with both mirror choices).
CANDIDATES = 8
#: The relative mismatch of the norms below which a mirror choice is tried beside the best.
MATCH = 1e-6
#: Newton steps at most on the position, and the miss [m per m of arm] below which none is
#: taken (fresh closed-form positions are exact to rounding, ~1e-16).
POLISH_STEPS = 8
POLISH_FROM = 1e-14
#: Halvings of a Newton step that does not shrink the miss, at most.
HALVINGS = 4
#: Largest Newton step [rad] on a joint: a longer one would leave the position for another.
MAX_STEP = 0.05


@inline
def _sp3(k, row, px, py, pz, qx, qy, qz, dd):
    """Subproblem 3, ``‖R(h, θ) P − Q‖² = dd`` about the unit axis h = ``k[row]``, as
    ``a cos θ + b sin θ = ratio`` with (a, b) a unit vector: (a, b, ratio, r), r = 0 where
    every θ gives the same distance (P or Q on the axis; ratio is then the mismatch
    ``K − dd/2``)."""
    hx, hy, hz = k[row, 0], k[row, 1], k[row, 2]
    hp = hx * px + hy * py + hz * pz
    hq = hx * qx + hy * qy + hz * qz
    a = qx * px + qy * py + qz * pz - hq * hp
    b = qx * (hy * pz - hz * py) + qy * (hz * px - hx * pz) + qz * (hx * py - hy * px)
    rest = 0.5 * (px * px + py * py + pz * pz + qx * qx + qy * qy + qz * qz - dd) - hq * hp
    radius = math.sqrt(a * a + b * b)
    if radius < FREE_TOL:
        return 1.0, 0.0, rest, 0.0
    return a / radius, b / radius, rest / radius, radius


@inline
def _cone(k, ra, rb, px, py, pz, qx, qy, qz, second):
    """Subproblem 2's common vector z of ``R(ha, θa) p = R(hb, θb) q`` (ha = ``k[ra]``,
    hb = ``k[rb]``): ``z = α ha + β hb ± γ ha × hb`` (``second``: −γ), and whether the cones
    meet (within ``CLAMP`` of tangency)."""
    ax, ay, az = k[ra, 0], k[ra, 1], k[ra, 2]
    bx, by, bz = k[rb, 0], k[rb, 1], k[rb, 2]
    cab = ax * bx + ay * by + az * bz
    nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    n2 = nx * nx + ny * ny + nz * nz
    hp = ax * px + ay * py + az * pz
    hq = bx * qx + by * qy + bz * qz
    alpha = (hp - cab * hq) / n2
    beta = (hq - cab * hp) / n2
    length2 = 0.5 * (px * px + py * py + pz * pz + qx * qx + qy * qy + qz * qz)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * cab
    gamma = math.sqrt(max(rest, 0.0) / n2) * (1.0 if second == 0 else -1.0)
    return (
        alpha * ax + beta * bx + gamma * nx,
        alpha * ay + beta * by + gamma * ny,
        alpha * az + beta * bz + gamma * nz,
        rest >= -CLAMP * max(length2, 1e-300),
    )


@inline
def _store(cand, valid, row, c1, s1, c2, s2, c3, s3):
    """Position ``row`` of ``cand``: (θ1, θ2, θ3) [rad] from cosines and sines, then those."""
    cand[row, 0] = math.atan2(s1, c1)
    cand[row, 1] = math.atan2(s2, c2)
    cand[row, 2] = math.atan2(s3, c3)
    cand[row, 3], cand[row, 4], cand[row, 5] = c1, s1, c2
    cand[row, 6], cand[row, 7], cand[row, 8] = s2, c3, s3
    valid[row] = True


@inline
def off_axis2(k, row, x, y, z):
    """|v⊥|² of v = (x, y, z) across the unit axis ``k[row]``, from the perpendicular itself
    (|v|² − (h·v)² would lose a small |v⊥| to cancellation)."""
    a = k[row, 0] * x + k[row, 1] * y + k[row, 2] * z
    x, y, z = x - a * k[row, 0], y - a * k[row, 1], z - a * k[row, 2]
    return x * x + y * y + z * z


@jit
def free_shoulder(k, rotation, c2, s2, c3, s3, fill):
    """(cos, sin) of −θ1 where θ1 is free for the position (the wrist centre on axis 1): the
    reference's θ1 ``fill`` when the wrist can then turn h6 onto ``W h6``, else the nearest θ1
    (mod 2π) at the edge of the wrist's reach (``h4·R5 h6`` spans [lo, hi], geometry row 23),
    for θ2, θ3 of cosines and sines ``c2, s2, c3, s3``."""
    qx, qy, qz = rotated(rotation, k, 14)  # R_T R_Mᵀ h6
    gx, gy, gz = turn(k, 2, k[3, 0], k[3, 1], k[3, 2], c3, s3)
    gx, gy, gz = turn(k, 1, gx, gy, gz, c2, s2)  # R2 R3 h4
    # h4·W h6 = g·R(h1, φ) q6 = c + a cos φ + b sin φ, φ = −θ1
    hg = k[0, 0] * gx + k[0, 1] * gy + k[0, 2] * gz
    hq = k[0, 0] * qx + k[0, 1] * qy + k[0, 2] * qz
    a = gx * qx + gy * qy + gz * qz - hg * hq
    b = gx * (k[0, 1] * qz - k[0, 2] * qy) + gy * (k[0, 2] * qx - k[0, 0] * qz)
    b += gz * (k[0, 0] * qy - k[0, 1] * qx)
    c = hg * hq
    phi = -fill
    lo, hi = k[23, 1], k[23, 2]
    value = c + a * math.cos(phi) + b * math.sin(phi)
    radius = math.sqrt(a * a + b * b)
    if lo - CLAMP <= value <= hi + CLAMP or radius < FREE_TOL:
        return math.cos(phi), math.sin(phi)
    base = math.atan2(b, a)
    best, best_gap = phi, np.inf
    for edge in (lo, hi):
        half = math.acos(min(max((edge - c) / radius, -1.0), 1.0))
        for candidate in (base + half, base - half):
            gap = abs(wrap(candidate - phi))
            if gap < best_gap:
                best, best_gap = candidate, gap
    return math.cos(best), math.sin(best)


# ---------------------------------------------------------------------------- positions
@jit
def meeting_12(k, ctx, cty, ctz, rotation, fill, cand, valid):
    """Axes 1, 2 meeting at ``o``: positions ``2·first + second`` into ``cand``; returns
    whether θ1 or θ2 was free (θ2 takes its ``fill`` value, θ1 :func:`free_shoulder`'s)."""
    singular = False
    yx, yy, yz = ctx - k[19, 0], cty - k[19, 1], ctz - k[19, 2]  # c_T − o
    dd = yx * yx + yy * yy + yz * yz
    px, py, pz = k[12, 0] - k[8, 0], k[12, 1] - k[8, 1], k[12, 2] - k[8, 2]  # c − p3
    qx, qy, qz = k[19, 0] - k[8, 0], k[19, 1] - k[8, 1], k[19, 2] - k[8, 2]  # o − p3
    a, b, ratio, radius = _sp3(k, 2, px, py, pz, qx, qy, qz, dd)
    if radius == 0.0 or abs(ratio) > 1.0 + CLAMP:  # (r = 0: refused by the geometry)
        return False
    free1 = off_axis2(k, 0, yx, yy, yz) < FREE_TOL * FREE_TOL  # c_T on axis 1
    for first in range(2):
        c3, s3 = _pair(a, b, ratio, first)
        xx, xy, xz = turn(k, 2, px, py, pz, c3, s3)
        xx, xy, xz = xx - qx, xy - qy, xz - qz  # e3 c − o
        free2 = off_axis2(k, 1, xx, xy, xz) < FREE_TOL * FREE_TOL  # e3 c on axis 2
        for second in range(2):
            if free1 or free2:  # the cone of the free axis is one vector: z is it
                singular = True
                zx, zy, zz = (yx, yy, yz) if free1 else (xx, xy, xz)
            else:
                zx, zy, zz, meet = _cone(k, 1, 0, xx, xy, xz, yx, yy, yz, second)
                if not meet:
                    break
            if free2:
                c2, s2 = math.cos(fill[1]), math.sin(fill[1])
            else:
                c2, s2, _ = angle_to(k, 1, xx, xy, xz, zx, zy, zz)
            if free1:  # (R2 x = y then holds for every θ1)
                cm, sm = free_shoulder(k, rotation, c2, s2, c3, s3, fill[0])
            else:
                cm, sm, _ = angle_to(k, 0, yx, yy, yz, zx, zy, zz)
            _store(cand, valid, 2 * first + second, cm, -sm, c2, s2, c3, s3)
    return singular


@jit
def meeting_23(k, ctx, cty, ctz, rotation, fill, cand, valid):
    """Axes 2, 3 meeting at ``o``: positions ``2·first + second`` into ``cand``; returns
    whether θ1 or θ2 was free (θ2 takes its ``fill`` value, θ1 :func:`free_shoulder`'s)."""
    singular = False
    px, py, pz = ctx - k[6, 0], cty - k[6, 1], ctz - k[6, 2]  # c_T − p1
    qx, qy, qz = k[19, 0] - k[6, 0], k[19, 1] - k[6, 1], k[19, 2] - k[6, 2]  # o − p1
    gx, gy, gz = k[12, 0] - k[19, 0], k[12, 1] - k[19, 1], k[12, 2] - k[19, 2]  # c − o
    a, b, ratio, radius = _sp3(k, 0, px, py, pz, qx, qy, qz, gx * gx + gy * gy + gz * gz)
    free1 = radius == 0.0  # c_T on axis 1 (o is not: refused by the geometry)
    if free1:
        if abs(ratio) > FREE_ROOM:
            return False
    elif abs(ratio) > 1.0 + CLAMP:
        return False
    for first in range(2):
        if free1:  # e1⁻¹ c_T = c_T for every θ1
            singular = True
            cm, sm = 1.0, 0.0
        else:
            cm, sm = _pair(a, b, ratio, first)  # of −θ1
        wx, wy, wz = turn(k, 0, px, py, pz, cm, sm)
        wx, wy, wz = wx - qx, wy - qy, wz - qz  # e1⁻¹ c_T − o
        free2 = off_axis2(k, 1, wx, wy, wz) < FREE_TOL * FREE_TOL  # on axis 2
        for second in range(2):
            if free2:
                singular = True
                zx, zy, zz = wx, wy, wz
                c2, s2 = math.cos(fill[1]), math.sin(fill[1])
            else:
                zx, zy, zz, meet = _cone(k, 2, 1, gx, gy, gz, wx, wy, wz, second)
                if not meet:
                    break
                c2, s2, _ = angle_to(k, 1, wx, wy, wz, zx, zy, zz)  # of −θ2
                s2 = -s2
            c3, s3, _ = angle_to(k, 2, gx, gy, gz, zx, zy, zz)
            if free1:
                cm, sm = free_shoulder(k, rotation, c2, s2, c3, s3, fill[0])
            _store(cand, valid, 2 * first + second, cm, -sm, c2, s2, c3, s3)
    return singular


@inline
def _circle(hx, hy, hz, cx, cy, cz, ux, uy, uz, vx, vy, vz):
    """The terms of one circle ``C + cos φ u + sin φ v`` of subproblem 5 along h2 = (hx, hy,
    hz): (a, b, ρ², H0, K, g, e) with height ``H0 + a cos φ + b sin φ`` (ρ² = a² + b²) and
    squared norm ``K + 2 (g cos φ + e sin φ)``."""
    a = hx * ux + hy * uy + hz * uz
    b = hx * vx + hy * vy + hz * vz
    return (
        a,
        b,
        a * a + b * b,
        hx * cx + hy * cy + hz * cz,
        cx * cx + cy * cy + cz * cz + ux * ux + uy * uy + uz * uz,
        cx * ux + cy * uy + cz * uz,
        cx * vx + cy * vy + cz * vz,
    )


@inline
def _mirror(a, b, rho2, h, side):
    """(cos φ, sin φ) of the point of height ``h`` (above the centre) on a circle of
    :func:`_circle`'s (a, b, ρ²), on ``side`` (±1) of the plane through the axis and h2."""
    half = math.sqrt(max(rho2 - h * h, 0.0))
    c = h * a - side * half * b
    s = h * b + side * half * a
    norm = math.sqrt(c * c + s * s)
    if norm == 0.0:
        return 1.0, 0.0
    return c / norm, s / norm


@jit
def _quartic(d0, d0_size, d1, q1, q3, poly):
    """``E = D⁴ − 2 D² (Q1 + Q3) + (Q1 − Q3)²`` of ``D = d0 + d1 t`` and the quadratics
    ``q1``, ``q3`` (constant first): coefficients into ``poly[0]``, the sizes of the terms
    they sum into ``poly[1]`` (the rounding scale of :func:`real_roots`; ``d0_size`` that of
    d0)."""
    dd = (d0 * d0, 2.0 * d0 * d1, d1 * d1)
    big = (d0_size * d0_size, 2.0 * d0_size * abs(d1), d1 * d1)
    for i in range(5):
        poly[0, i] = 0.0
        poly[1, i] = 0.0
    for i in range(3):
        for j in range(3):
            total = q1[j] + q3[j]
            poly[0, i + j] += (
                dd[i] * dd[j] - 2.0 * dd[i] * total + (q1[i] - q3[i]) * (q1[j] - q3[j])
            )
            sizes = abs(q1[j]) + abs(q3[j])
            poly[1, i + j] += big[i] * (big[j] + 2.0 * sizes) + (abs(q1[i]) + abs(q3[i])) * sizes


@inline
def _finish(k, zx, zy, zz, cm, sm, c3, s3, fill, cand, valid, n):
    """Subproblem 5's θ2, turning ``y = e3 c − o`` onto ``z`` about axis 2, and the position
    (−θ1 of cosine ``cm``, sine ``sm``; θ3 of ``c3``, ``s3``) written into row ``n``; returns
    (n + 1, whether θ2 was free: y or z on axis 2, θ2 = ``fill[1]``)."""
    yx = k[20, 0] + c3 * k[21, 0] + s3 * k[22, 0]
    yy = k[20, 1] + c3 * k[21, 1] + s3 * k[22, 1]
    yz = k[20, 2] + c3 * k[21, 2] + s3 * k[22, 2]
    c2, s2, spread = angle_to(k, 1, yx, yy, yz, zx, zy, zz)
    free = spread < FREE_TOL * FREE_TOL
    if free:
        c2, s2 = math.cos(fill[1]), math.sin(fill[1])
    _store(cand, valid, n, cm, -sm, c2, s2, c3, s3)
    return n + 1, free


@jit
def general_shoulder(k, ctx, cty, ctz, rotation, fill, cand, valid, poly):
    """Subproblem 5: up to :data:`CANDIDATES` positions into ``cand`` (in the order of the
    height H); returns (how many rows were written, whether θ1 or θ2 was free). ``poly``:
    scratch (8, 10)."""
    h2x, h2y, h2z = k[1, 0], k[1, 1], k[1, 2]
    # circle 1: z = (p1 − o) + R(h1, −θ1)(c_T − p1)
    vx, vy, vz = ctx - k[6, 0], cty - k[6, 1], ctz - k[6, 2]
    along = vx * k[0, 0] + vy * k[0, 1] + vz * k[0, 2]
    u1x, u1y, u1z = vx - along * k[0, 0], vy - along * k[0, 1], vz - along * k[0, 2]
    c1x = k[6, 0] - k[19, 0] + along * k[0, 0]
    c1y = k[6, 1] - k[19, 1] + along * k[0, 1]
    c1z = k[6, 2] - k[19, 2] + along * k[0, 2]
    v1x = k[0, 1] * u1z - k[0, 2] * u1y
    v1y = k[0, 2] * u1x - k[0, 0] * u1z
    v1z = k[0, 0] * u1y - k[0, 1] * u1x
    a1, b1, rho1, base1, k1, g1, e1 = _circle(
        h2x, h2y, h2z, c1x, c1y, c1z, u1x, u1y, u1z, v1x, v1y, v1z
    )
    a3, b3, rho3, base3, k3, g3, e3 = _circle(
        h2x, h2y, h2z, k[20, 0], k[20, 1], k[20, 2], k[21, 0], k[21, 1], k[21, 2],
        k[22, 0], k[22, 1], k[22, 2],
    )  # fmt: skip
    size = k[23, 0]
    n = 0
    singular = False
    if u1x * u1x + u1y * u1y + u1z * u1z < FREE_TOL * FREE_TOL:  # c_T on axis 1: θ1 free
        h = base1 - base3
        if h * h > rho3 * (1.0 + CLAMP):
            return 0, True
        for side in (1.0, -1.0):
            c3, s3 = _mirror(a3, b3, rho3, h, side)
            n, _ = _finish(k, c1x, c1y, c1z, 1.0, 0.0, c3, s3, fill, cand, valid, n)
            cm, sm = free_shoulder(k, rotation, cand[n - 1, 5], cand[n - 1, 6], c3, s3, fill[0])
            _store(cand, valid, n - 1, cm, -sm, cand[n - 1, 5], cand[n - 1, 6], c3, s3)
        return n, True
    r1, r3 = math.sqrt(rho1), math.sqrt(rho3)
    lo = max(base1 - r1, base3 - r3)
    hi = min(base1 + r1, base3 + r3)
    if lo > hi + CLAMP * size:  # the circles share no height
        return 0, False
    mid = 0.5 * (lo + hi)
    half = max(0.5 * (hi - lo), 1e-12 * size)
    # P_i = K_i + 2 λ_i h_i, Q_i = μ_i² (ρ_i² − h_i²) with h_i = mid + half·t − base_i
    lam1, lam3 = (g1 * a1 + e1 * b1) / rho1, (g3 * a3 + e3 * b3) / rho3
    mu1, mu3 = 2.0 * (a1 * e1 - b1 * g1) / rho1, 2.0 * (a3 * e3 - b3 * g3) / rho3
    m1, m3 = mid - base1, mid - base3
    d0 = k3 - k1 + 2.0 * (lam3 * m3 - lam1 * m1)
    d0_size = k3 + k1 + 2.0 * (abs(lam3 * m3) + abs(lam1 * m1))
    d1 = 2.0 * half * (lam3 - lam1)
    w1, w3 = mu1 * mu1, mu3 * mu3
    q1 = (w1 * (rho1 - m1 * m1), -2.0 * w1 * m1 * half, -w1 * half * half)
    q3 = (w3 * (rho3 - m3 * m3), -2.0 * w3 * m3 * half, -w3 * half * half)
    _quartic(d0, d0_size, d1, q1, q3, poly)
    roots, misses = poly[2], poly[3]
    found = real_roots(poly[0], poly[1], -1.0 - 1e-6, 1.0 + 1e-6, roots, poly[4:7])
    for i in range(found):
        height = mid + half * roots[i]
        h1, h3 = height - base1, height - base3
        best, best_miss = 0, np.inf
        for choice in range(4):
            cz1, sz1 = _mirror(a1, b1, rho1, h1, 1.0 if choice < 2 else -1.0)
            cy3, sy3 = _mirror(a3, b3, rho3, h3, 1.0 if choice % 2 == 0 else -1.0)
            norm1 = k1 + 2.0 * (g1 * cz1 + e1 * sz1)
            norm3 = k3 + 2.0 * (g3 * cy3 + e3 * sy3)
            misses[choice] = abs(norm1 - norm3) / max(abs(norm1) + abs(norm3), 1e-300)
            if misses[choice] < best_miss:
                best, best_miss = choice, misses[choice]
        for choice in range(4):
            if n >= CANDIDATES or not (choice == best or misses[choice] <= MATCH):
                continue
            cz1, sz1 = _mirror(a1, b1, rho1, h1, 1.0 if choice < 2 else -1.0)
            cy3, sy3 = _mirror(a3, b3, rho3, h3, 1.0 if choice % 2 == 0 else -1.0)
            zx = c1x + cz1 * u1x + sz1 * v1x
            zy = c1y + cz1 * u1y + sz1 * v1y
            zz = c1z + cz1 * u1z + sz1 * v1z
            n, free = _finish(k, zx, zy, zz, cz1, sz1, cy3, sy3, fill, cand, valid, n)
            singular = singular or free
    return n, singular


# ---------------------------------------------------------------------------- polish
@inline
def _place(k, c1, s1, c2, s2, c3, s3):
    """``e1 e2 e3 c`` at the cosines and sines of θ1, θ2, θ3 and its derivatives: (x,
    ∂x/∂θ1, ∂x/∂θ2, ∂x/∂θ3), twelve floats."""
    # R3 (c − p3) and h3 × it, then about axis 2 (x2 − p2, h2 × it) and axis 1
    rx, ry, rz = turn(k, 2, k[12, 0] - k[8, 0], k[12, 1] - k[8, 1], k[12, 2] - k[8, 2], c3, s3)
    jx, jy, jz = _cross(k, 2, rx, ry, rz)
    rx, ry, rz = rx + k[8, 0] - k[7, 0], ry + k[8, 1] - k[7, 1], rz + k[8, 2] - k[7, 2]
    rx, ry, rz = turn(k, 1, rx, ry, rz, c2, s2)
    jx, jy, jz = turn(k, 1, jx, jy, jz, c2, s2)
    ix, iy, iz = _cross(k, 1, rx, ry, rz)
    rx, ry, rz = rx + k[7, 0] - k[6, 0], ry + k[7, 1] - k[6, 1], rz + k[7, 2] - k[6, 2]
    rx, ry, rz = turn(k, 0, rx, ry, rz, c1, s1)
    jx, jy, jz = turn(k, 0, jx, jy, jz, c1, s1)
    ix, iy, iz = turn(k, 0, ix, iy, iz, c1, s1)
    gx, gy, gz = _cross(k, 0, rx, ry, rz)
    return rx + k[6, 0], ry + k[6, 1], rz + k[6, 2], gx, gy, gz, ix, iy, iz, jx, jy, jz


@inline
def _cross(k, row, x, y, z):
    """``k[row] × (x, y, z)``."""
    return (
        k[row, 1] * z - k[row, 2] * y,
        k[row, 2] * x - k[row, 0] * z,
        k[row, 0] * y - k[row, 1] * x,
    )


@inline
def polish(k, ctx, cty, ctz, t):
    """Newton steps on ``e1 e2 e3 c = c_T`` from (θ1, θ2, θ3) = ``t`` (3,) [rad], in place,
    while they shrink the miss (none once it is below ``POLISH_FROM`` per metre of arm): a
    step that does not is halved, up to :data:`HALVINGS` times (near a singularity the full
    step overshoots along the valley), and none is longer than :data:`MAX_STEP`; returns the
    miss [m]."""
    x, y, z, ax, ay, az, bx, by, bz, cx, cy, cz = _place(k, t[3], t[4], t[5], t[6], t[7], t[8])
    rx, ry, rz = x - ctx, y - cty, z - ctz
    miss = math.sqrt(rx * rx + ry * ry + rz * rz)
    floor = POLISH_FROM * k[23, 0]
    for _ in range(POLISH_STEPS):
        if miss <= floor:
            break
        # J d = −r by Cramer's rule, J = [a b c] (columns)
        det = ax * (by * cz - bz * cy) - bx * (ay * cz - az * cy) + cx * (ay * bz - az * by)
        d1 = -(rx * (by * cz - bz * cy) - bx * (ry * cz - rz * cy) + cx * (ry * bz - rz * by))
        d2 = -(ax * (ry * cz - rz * cy) - rx * (ay * cz - az * cy) + cx * (ay * rz - az * ry))
        d3 = -(ax * (by * rz - bz * ry) - bx * (ay * rz - az * ry) + rx * (ay * bz - az * by))
        if not max(abs(d1), abs(d2), abs(d3)) <= MAX_STEP * abs(det):
            break  # singular, or a jump towards another position
        d1, d2, d3 = d1 / det, d2 / det, d3 / det
        improved = False
        for _ in range(HALVINGS + 1):
            n1, n2, n3 = t[0] + d1, t[1] + d2, t[2] + d3
            c1, s1, c2, s2 = math.cos(n1), math.sin(n1), math.cos(n2), math.sin(n2)
            c3, s3 = math.cos(n3), math.sin(n3)
            x, y, z, pax, pay, paz, pbx, pby, pbz, pcx, pcy, pcz = _place(k, c1, s1, c2, s2, c3, s3)
            sx, sy, sz = x - ctx, y - cty, z - ctz
            after = math.sqrt(sx * sx + sy * sy + sz * sz)
            if after < miss:
                improved = True
                break
            d1, d2, d3 = 0.5 * d1, 0.5 * d2, 0.5 * d3
        if not improved:
            break
        t[0], t[1], t[2] = wrap(n1), wrap(n2), wrap(n3)
        t[3], t[4], t[5], t[6], t[7], t[8] = c1, s1, c2, s2, c3, s3
        rx, ry, rz, miss = sx, sy, sz, after
        ax, ay, az, bx, by, bz, cx, cy, cz = pax, pay, paz, pbx, pby, pbz, pcx, pcy, pcz
    return miss


@inline
def rotated(rotation, k, row):
    """``rotation @ k[row]``."""
    return (
        rotation[0, 0] * k[row, 0] + rotation[0, 1] * k[row, 1] + rotation[0, 2] * k[row, 2],
        rotation[1, 0] * k[row, 0] + rotation[1, 1] * k[row, 1] + rotation[1, 2] * k[row, 2],
        rotation[2, 0] * k[row, 0] + rotation[2, 1] * k[row, 1] + rotation[2, 2] * k[row, 2],
    )
