"""The FK check of many configurations of a serial revolute arm, compiled (numba): what
:meth:`BatchKinematics.errors <kinplan.ik.batch_kinematics.BatchKinematics.errors>` runs when
numba is available (``ik_batch`` checks every closed-form solution with it).

The same chain as the numpy pass of :class:`~kinplan.ik.batch_kinematics.BatchKinematics`
(per joint its placement in the parent joint's frame, then a rotation about its axis; then the
tool frame), one configuration at a time: about 4× faster than the numpy pass at 20,000
configurations, the same errors to rounding (relative ~1e-15 of the FK). Without numba (or with
``KINPLAN_JIT=0``) :func:`available` is False and the numpy pass runs.
"""

from __future__ import annotations

import math
import os

from kinplan.compiled import jit, numba

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"


def available() -> bool:
    """Whether the compiled check can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


@jit
def errors_many(q, placements, offsets, axes, columns, tool, positions, rotations, out):
    """Squared tool position errors [m²] and ‖R* − R‖²_F of joint rows ``q`` (N, nq) [rad] at
    targets ``positions`` (N, 3) [m] and ``rotations`` (N, 3, 3) (base frame), written into
    ``out`` (2, N); ``rotations`` of shape (0, 3, 3): position only (the second row 0).

    Args:
        placements, offsets: Per joint in chain order, the rotation (J, 3, 3) and translation
            (J, 3) [m] of its frame in its parent joint's frame.
        axes: Unit rotation axes (J, 3) in the joints' frames.
        columns: Per joint, its column of ``q`` (J,).
        tool: The tool frame in the last joint's frame (4, 4) [m].
    """
    with_rotation = rotations.shape[0] > 0
    for n in range(q.shape[0]):
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
        px = py = pz = 0.0
        for k in range(placements.shape[0]):
            o, m = offsets[k], placements[k]
            px += r00 * o[0] + r01 * o[1] + r02 * o[2]
            py += r10 * o[0] + r11 * o[1] + r12 * o[2]
            pz += r20 * o[0] + r21 * o[1] + r22 * o[2]
            # R·R_j
            a00 = r00 * m[0, 0] + r01 * m[1, 0] + r02 * m[2, 0]
            a01 = r00 * m[0, 1] + r01 * m[1, 1] + r02 * m[2, 1]
            a02 = r00 * m[0, 2] + r01 * m[1, 2] + r02 * m[2, 2]
            a10 = r10 * m[0, 0] + r11 * m[1, 0] + r12 * m[2, 0]
            a11 = r10 * m[0, 1] + r11 * m[1, 1] + r12 * m[2, 1]
            a12 = r10 * m[0, 2] + r11 * m[1, 2] + r12 * m[2, 2]
            a20 = r20 * m[0, 0] + r21 * m[1, 0] + r22 * m[2, 0]
            a21 = r20 * m[0, 1] + r21 * m[1, 1] + r22 * m[2, 1]
            a22 = r20 * m[0, 2] + r21 * m[1, 2] + r22 * m[2, 2]
            # ·Rot(axis, θ) (Rodrigues)
            angle = q[n, columns[k]]
            c, s = math.cos(angle), math.sin(angle)
            x, y, z = axes[k, 0], axes[k, 1], axes[k, 2]
            t = 1.0 - c
            s00, s01, s02 = c + x * x * t, x * y * t - z * s, x * z * t + y * s
            s10, s11, s12 = y * x * t + z * s, c + y * y * t, y * z * t - x * s
            s20, s21, s22 = z * x * t - y * s, z * y * t + x * s, c + z * z * t
            r00 = a00 * s00 + a01 * s10 + a02 * s20
            r01 = a00 * s01 + a01 * s11 + a02 * s21
            r02 = a00 * s02 + a01 * s12 + a02 * s22
            r10 = a10 * s00 + a11 * s10 + a12 * s20
            r11 = a10 * s01 + a11 * s11 + a12 * s21
            r12 = a10 * s02 + a11 * s12 + a12 * s22
            r20 = a20 * s00 + a21 * s10 + a22 * s20
            r21 = a20 * s01 + a21 * s11 + a22 * s21
            r22 = a20 * s02 + a21 * s12 + a22 * s22
        tx, ty, tz = tool[0, 3], tool[1, 3], tool[2, 3]
        dx = positions[n, 0] - (px + r00 * tx + r01 * ty + r02 * tz)
        dy = positions[n, 1] - (py + r10 * tx + r11 * ty + r12 * tz)
        dz = positions[n, 2] - (pz + r20 * tx + r21 * ty + r22 * tz)
        out[0, n] = dx * dx + dy * dy + dz * dz
        total = 0.0
        if with_rotation:
            for j in range(3):
                m0, m1, m2 = tool[0, j], tool[1, j], tool[2, j]
                d0 = rotations[n, 0, j] - (r00 * m0 + r01 * m1 + r02 * m2)
                d1 = rotations[n, 1, j] - (r10 * m0 + r11 * m1 + r12 * m2)
                d2 = rotations[n, 2, j] - (r20 * m0 + r21 * m1 + r22 * m2)
                total += d0 * d0 + d1 * d1 + d2 * d2
        out[1, n] = total


@jit
def split_poses(matrices, positions, rotations):
    """The positions (N, 3) [m] and rotations (N, 3, 3) of homogeneous matrices (N, 4, 4)
    written, each checked as :func:`~kinplan.ik.batch_kinematics.parse_targets` checks it
    (finite, last row 0 0 0 1, ‖RᵀR − I‖_F² ≤ 1e-12 and det R ≥ 0, the same arithmetic in the
    same order as :func:`~kinplan.ik.batch_kinematics._rotation_defects`): returns the index
    of the first matrix that fails, or −1 (one pass over the targets instead of numpy's
    several)."""
    for n in range(matrices.shape[0]):
        m = matrices[n]
        total = 0.0
        for i in range(4):
            for j in range(4):
                total += m[i, j]
        if not math.isfinite(total):
            return n
        if not (m[3, 0] == 0.0 and m[3, 1] == 0.0 and m[3, 2] == 0.0 and m[3, 3] == 1.0):
            return n
        x0, y0, z0 = m[0, 0], m[1, 0], m[2, 0]  # the columns c0, c1, c2 of R
        x1, y1, z1 = m[0, 1], m[1, 1], m[2, 1]
        x2, y2, z2 = m[0, 2], m[1, 2], m[2, 2]
        d0 = (x0 * x0 + y0 * y0 + z0 * z0) - 1.0
        d1 = (x1 * x1 + y1 * y1 + z1 * z1) - 1.0
        d2 = (x2 * x2 + y2 * y2 + z2 * z2) - 1.0
        o01 = x0 * x1 + y0 * y1 + z0 * z1
        o02 = x0 * x2 + y0 * y2 + z0 * z2
        o12 = x1 * x2 + y1 * y2 + z1 * z2
        defect = (d0 * d0 + d1 * d1) + d2 * d2
        defect += 2.0 * ((o01 * o01 + o02 * o02) + o12 * o12)
        cx, cy, cz = y1 * z2 - z1 * y2, z1 * x2 - x1 * z2, x1 * y2 - y1 * x2
        determinant = (x0 * cx + y0 * cy) + z0 * cz
        if not defect <= 1e-12 or determinant < 0.0:
            return n
        for i in range(3):
            positions[n, i] = m[i, 3]
            for j in range(3):
                rotations[n, i, j] = m[i, j]
    return -1
