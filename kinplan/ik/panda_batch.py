"""The panda's θ7 search over many poses at once in numpy (:class:`PandaBatch`, the base class
whose ``nearest_many`` :class:`~kinplan.ik.panda.PandaIK` runs when the compiled search is not
available: without numba or with ``KINPLAN_JIT=0``): each stage of ``PandaIK.nearest``'s search
solves the closed form on arrays, for every (pose, θ7 value) pair still open.

Fourth of the panda modules, which import only those before them:
:mod:`~kinplan.ik.panda_geometry` → :mod:`~kinplan.ik.panda_subproblems` →
:mod:`~kinplan.ik.panda_intervals` → ``panda_batch`` → :mod:`~kinplan.ik.panda`.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.ik.panda_geometry import (
    Mat,
    PandaGeometry,
    Vec,
    cross_many,
    dot_many,
    map_floats,
    matmul_many,
    matvec_many,
    rotate_cs_many,
    rotation_matrix_cs,
    sub_many,
)
from kinplan.ik.panda_intervals import Q7_STEPS, project_many
from kinplan.ik.panda_subproblems import NEAR_FREE, AxisPair
from kinplan.ik.screws import CLAMP, FREE_TOL, TAU, joint_choice_many


class PandaBatch:
    """The vectorised half of :class:`~kinplan.ik.panda.PandaIK`: :meth:`nearest_many`.

    A base class: ``PandaIK.__init__`` computes the solver's constants; those this half reads
    are declared below.
    """

    geometry: PandaGeometry
    lower: np.ndarray
    upper: np.ndarray
    _lo: list[float]
    _hi: list[float]
    _limits: tuple[tuple[float, float, float], ...]
    _q7_grids: list[list[float]]
    _tool_rotation_t: Mat
    _p7_from_wrist: Vec
    _elbow_distance2: tuple[float, ...]
    _s4: Vec
    _w4: Vec
    _e3: Vec
    _q4_lengths: float
    _q4_const: float
    _q4_amplitude: float
    _q4_phase: float
    _wrist_pair: AxisPair
    _shoulder_pair: AxisPair

    # ------------------------------------------------------------ many poses at once
    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference, vectorised (inputs
        unchecked).

        The θ7 search runs stage by stage on all poses at once: each stage solves the closed
        form for every (pose, θ7 value) pair still open (:meth:`_solve_rows`) and closes the
        poses it solves, so a pose takes the first stage with a solution and, within it, the
        nearest one (the first θ7 value on ties), as :meth:`nearest`. (``nearest`` skips θ7
        values it tried before; they had no solution then, nor do they now.)

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 7).

        Returns:
            (q (N, 7) [rad], found (N,), left (N,)): ``left`` marks poses where some vector
            comes within :data:`NEAR_FREE` of an axis it turns about (a free angle), which
            the caller solves with :meth:`nearest`; their other outputs are meaningless.
        """
        count = len(positions)
        q = np.zeros((count, 7))
        found = np.zeros(count, dtype=bool)
        left = np.zeros(count, dtype=bool)
        span = self._hi[6] - self._lo[6]
        if count == 0 or not math.isfinite(span):
            left[:] = count > 0
            return q, found, left
        refs = np.ascontiguousarray(np.asarray(q_ref, dtype=float).T)
        clipped = np.clip(refs, self.lower[:, None], self.upper[:, None])
        seen, rotation_tm = self._prepare_many(positions, rotations)
        starts, ends = self._elbow_q7_intervals_many(seen)
        q7_ref = clipped[6]
        distance = np.maximum(starts - q7_ref[:, None], q7_ref[:, None] - ends)
        nearest = np.argmin(np.nan_to_num(distance, nan=np.inf), axis=1)
        rows = np.arange(count)
        start, end = starts[rows, nearest], ends[rows, nearest]
        inside = (start <= q7_ref) & (q7_ref <= end)
        quarter = np.where(q7_ref < start, start + 0.25 * (end - start), end - 0.25 * (end - start))
        first = np.where(inside, q7_ref, quarter)
        middle = 0.5 * (start + end)
        lo7, hi7 = self._lo[6], self._hi[6]
        stages: list[np.ndarray] = [first[:, None], middle[:, None]]
        for step in Q7_STEPS:
            stages.append(np.stack((q7_ref + step, q7_ref - step), axis=1))
        grids = [np.array(grid) for grid in self._q7_grids]
        pending = np.flatnonzero(np.isfinite(start))  # no interval: no solution
        tried = np.stack((first, middle), axis=1)[pending]  # θ7 values tried, per pending pose
        for index, stage in enumerate(stages + grids):
            if pending.size == 0:
                break
            if stage.ndim == 1:  # a grid: the same values for every pose
                values = np.broadcast_to(stage, (pending.size, stage.size))
            else:
                values = stage[pending]
            if index >= 2:
                values = project_many(np.clip(values, lo7, hi7), starts[pending], ends[pending])
                # values tried before (in this stage or earlier) had no solution: skipped
                width = values.shape[1]
                same = np.any(values[:, :, None] == tried[:, None, :], axis=2)
                same |= np.any(
                    (values[:, :, None] == values[:, None, :]) & np.tri(width, k=-1, dtype=bool),
                    axis=2,
                )
                fresh = ~same
                tried = np.concatenate((tried, values), axis=1)
            else:
                fresh = np.ones(values.shape, dtype=bool)
            width = values.shape[1]
            cost = np.full(values.shape, np.inf)
            chosen = np.zeros(values.shape + (7,))
            row_singular = np.zeros(values.shape, dtype=bool)
            at, which = np.nonzero(fresh)
            if at.size:
                poses = pending[at]
                chosen[at, which], cost[at, which], row_singular[at, which] = self._solve_rows(
                    tuple(x[poses] for x in seen),
                    tuple(x[poses] for x in rotation_tm),
                    values[at, which],
                    refs[:, poses],
                    clipped[:, poses],
                )
            singular = row_singular.any(axis=1)
            best = np.argmin(cost, axis=1)  # ties: the first θ7 value, as _best
            solved = np.isfinite(cost[np.arange(len(best)), best]) & ~singular
            chosen = chosen[np.arange(len(best)), best]
            q[pending[solved]] = chosen[solved]
            found[pending[solved]] = True
            left[pending[singular]] = True
            tried = tried[~solved & ~singular]
            pending = pending[~solved & ~singular]
        return q, found, left

    def _prepare_many(self, positions: np.ndarray, rotations: np.ndarray):
        """:meth:`_prepare` of many poses: (``M T⁻¹ s`` as 3 arrays [m], ``R_T M_Rᵀ`` as 9
        arrays, row-major), each of shape (N,)."""
        g = self.geometry
        r = tuple(np.ascontiguousarray(rotations.reshape(-1, 9).T))
        p = tuple(np.ascontiguousarray(positions.T))
        d = (g.shoulder[0] - p[0], g.shoulder[1] - p[1], g.shoulder[2] - p[2])
        local = (
            r[0] * d[0] + r[3] * d[1] + r[6] * d[2],
            r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
            r[2] * d[0] + r[5] * d[1] + r[8] * d[2],
        )
        moved = matvec_many(g.tool_rotation, local)
        t = g.tool_translation
        seen = (moved[0] + t[0], moved[1] + t[1], moved[2] + t[2])
        return seen, matmul_many(r, self._tool_rotation_t)

    def _elbow_q7_intervals_many(self, seen) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_elbow_q7_intervals` of many poses: (starts, ends), each (N, M) [rad], sorted
        and disjoint per row, NaN where a row has fewer than M intervals."""
        a, c = self.geometry.axes[6], self._p7_from_wrist
        d = sub_many(seen, self.geometry.points[6])
        ad, ac = dot_many(a, d), dot_many(a, c)
        cos_part, sin_part = dot_many(c, d) - ac * ad, dot_many(c, cross_many(a, d))
        mean = dot_many(d, d) + dot_many(c, c) + 2.0 * ac * ad
        # as _elbow_q7_intervals (a correctly rounded sqrt, the math module's transcendental
        # functions): the intervals' ends must agree to the last bit (pieces that touch at ±π
        # merge or not by it)
        amplitude = 2.0 * np.sqrt(cos_part * cos_part + sin_part * sin_part)
        low, high = self._elbow_distance2
        lo7, hi7 = self._lo[6], self._hi[6]
        with np.errstate(divide="ignore", invalid="ignore"):
            c_low, c_high = (low - mean) / amplitude, (high - mean) / amplitude
        near = map_floats(math.acos, np.clip(c_high, -1.0, 1.0))
        far = map_floats(math.acos, np.clip(c_low, -1.0, 1.0))
        phi = map_floats(math.atan2, sin_part, cos_part)
        pieces = [(phi + near, phi + far), (phi - far, phi - near)]
        # intervals_within: each piece shifted by whole turns into [lo7, hi7]
        shifts = int((hi7 - lo7 + math.pi) // TAU) + 2
        found_a, found_b = [], []
        for piece_start, piece_end in pieces:
            k0 = np.ceil((lo7 - piece_end) / TAU)
            k_last = np.floor((hi7 - piece_start) / TAU)
            for extra in range(shifts):
                k = k0 + extra
                a_k = np.maximum(piece_start + k * TAU, lo7)
                b_k = np.minimum(piece_end + k * TAU, hi7)
                keep = (k <= k_last) & (a_k <= b_k)
                found_a.append(np.where(keep, a_k, np.inf))
                found_b.append(np.where(keep, b_k, np.inf))
        starts, ends = np.stack(found_a, axis=1), np.stack(found_b, axis=1)
        empty = ~((c_low <= 1.0) & (c_high >= -1.0))
        flat = amplitude < FREE_TOL  # θ7 does not change the distance
        whole = flat & (low <= mean) & (mean <= high)
        starts[empty | flat], ends[empty | flat] = np.inf, np.inf
        starts[whole, 0], ends[whole, 0] = lo7, hi7
        order = np.lexsort((ends, starts), axis=1)
        starts = np.take_along_axis(starts, order, axis=1)
        ends = np.take_along_axis(ends, order, axis=1)
        # merge as intervals_within: a new interval where one starts past every end so far
        reach = np.maximum.accumulate(ends, axis=1)
        new = np.ones_like(starts, dtype=bool)
        new[:, 1:] = starts[:, 1:] > reach[:, :-1]
        new &= np.isfinite(starts)
        group = np.cumsum(new, axis=1) - 1
        merged_a = np.full(starts.shape, np.nan)
        merged_b = np.full(starts.shape, np.nan)
        rows = np.arange(len(starts))
        for j in range(starts.shape[1]):
            valid = np.isfinite(starts[:, j])
            r, gj = rows[valid], group[valid, j]
            merged_a[r, gj] = np.where(new[valid, j], starts[valid, j], merged_a[r, gj])
            merged_b[r, gj] = reach[valid, j]
        return merged_a, merged_b

    def _solve_rows(self, seen, rotation_tm, q7, refs, clipped):
        """:meth:`_solve` (the nearest solution) for many rows (pose, θ7) at once.

        Args:
            seen, rotation_tm: :meth:`_prepare_many` of each row's pose.
            q7: θ7 of each row [rad], within its limits, shape (R,).
            refs, clipped: References and references clipped into the limits (7, R).

        Returns:
            (q (R, 7) [rad], cost (R,) (inf: no solution within the limits), singular (R,)).
            Lanes run (θ4 branch, wrist branch, shoulder branch, row); cosines and sines of
            angles that come out of arccos or atan2 are taken from their arguments.
        """
        g = self.geometry
        a4, a5, a6, a7, p7 = g.axes[3], g.axes[4], g.axes[5], g.axes[6], g.points[6]
        limits = self._limits

        def choose(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            lower, upper, weight = limits[joint]
            return joint_choice_many(values, refs[joint], clipped[joint], lower, upper, weight)

        with np.errstate(invalid="ignore", divide="ignore"):
            c7, s7 = np.cos(q7), np.sin(q7)
            y = rotate_cs_many(sub_many(seen, p7), a7, c7, s7)
            w = g.wrist
            v = (y[0] + p7[0] - w[0], y[1] + p7[1] - w[1], y[2] + p7[2] - w[2])
            base = limits[6][2] * (q7 - refs[6]) ** 2
            # θ4 (_elbow): two branches −(phase ± spread)
            ratio = (
                0.5 * (self._q4_lengths - dot_many(v, v)) - self._q4_const
            ) / self._q4_amplitude
            ratio = np.where(np.abs(ratio) <= 1.0 + CLAMP, np.clip(ratio, -1.0, 1.0), np.nan)
            spread = np.arccos(ratio)
            sin_spread = np.sqrt(1.0 - ratio * ratio)
            phase = self._q4_phase
            q4, cost4 = choose(3, np.stack((-(phase + spread), -(phase - spread))))
            cost4 = base + cost4
            cp, sp = math.cos(phase), math.sin(phase)
            cos4 = np.stack((cp * ratio - sp * sin_spread, cp * ratio + sp * sin_spread))
            sin4 = np.stack((sp * ratio + cp * sin_spread, sp * ratio - cp * sin_spread))  # −sin
            u = sub_many(rotate_cs_many(self._s4, a4, cos4, sin4), self._w4)
            turned3 = rotate_cs_many(g.axes[2], a4, cos4, sin4)
            turned_e = rotate_cs_many(self._e3, a4, cos4, sin4)
            # θ5, θ6 (wrist pair): lanes (θ4 branch, wrist branch, row)
            (y5, x5), (y6, x6), ok, singular = self._wrist_pair.solve_many(u, v)
            q5, cost5 = choose(4, -np.arctan2(y5, x5))
            q6, cost6 = choose(5, -np.arctan2(y6, x6))
            cost6 = (cost4[:, None] + cost5) + cost6
            cost6 = np.where(ok, cost6, np.inf)
            n5, n6 = np.sqrt(x5 * x5 + y5 * y5), np.sqrt(x6 * x6 + y6 * y6)
            cos5, sin5, cos6, sin6 = x5 / n5, y5 / n5, x6 / n6, y6 / n6  # of −q5, −q6
            # the shoulder, only on the (θ4, wrist) lanes with a solution so far (compacted)
            count = len(q7)
            lanes = np.flatnonzero(np.isfinite(cost6).ravel())
            row = lanes % count
            pair = lanes // count  # 2·θ4 branch + wrist branch

            def pick(x, per_lane: bool = True):
                return x.reshape(-1)[lanes] if per_lane else x[row]

            cos5, sin5, cos6, sin6 = (pick(x) for x in (cos5, sin5, cos6, sin6))
            turned3 = tuple(x[pair >> 1, row] for x in turned3)
            turned_e = tuple(x[pair >> 1, row] for x in turned_e)
            # G = R_P R6(−θ6) R5(−θ5) R4(−θ4) = R1 R2 R3, applied to ω3 and e
            rotation_p = matmul_many(
                tuple(pick(x, False) for x in rotation_tm),
                rotation_matrix_cs(a7, c7[row], -s7[row]),
            )
            g3 = matvec_many(
                rotation_p,
                rotate_cs_many(rotate_cs_many(turned3, a5, cos5, sin5), a6, cos6, sin6),
            )
            ge = matvec_many(
                rotation_p,
                rotate_cs_many(rotate_cs_many(turned_e, a5, cos5, sin5), a6, cos6, sin6),
            )
            # θ1, θ2 (shoulder pair): (shoulder branch, lane)
            (y2, x2), (y1, x1), ok, near_free = self._shoulder_pair.solve_many(g.axes[2], g3)
            lane_refs, lane_clipped = refs[:, row], clipped[:, row]

            def choose_lanes(joint: int, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                lower, upper, weight = limits[joint]
                return joint_choice_many(
                    values, lane_refs[joint], lane_clipped[joint], lower, upper, weight
                )

            q1, cost1 = choose_lanes(0, np.arctan2(y1, x1))
            q2, cost2 = choose_lanes(1, np.arctan2(y2, x2))
            cost2 = (pick(cost6) + cost1) + cost2
            cost2 = np.where(ok, cost2, np.inf)
            n1, n2 = np.sqrt(x1 * x1 + y1 * y1), np.sqrt(x2 * x2 + y2 * y2)
            # θ3: R3(θ3) e = R2(−θ2) R1(−θ1) G e
            h = rotate_cs_many(
                rotate_cs_many(ge, g.axes[0], x1 / n1, -y1 / n1), g.axes[1], x2 / n2, -y2 / n2
            )
            axis3, (ex, ey, ez) = g.axes[2], self._e3
            k = dot_many(axis3, h)
            hx, hy, hz = h[0] - k * axis3[0], h[1] - k * axis3[1], h[2] - k * axis3[2]
            k = dot_many(axis3, self._e3)
            ex, ey, ez = ex - k * axis3[0], ey - k * axis3[1], ez - k * axis3[2]
            near_free = near_free | (hx * hx + hy * hy + hz * hz < NEAR_FREE**2)
            t3 = np.arctan2(
                dot_many(axis3, cross_many((ex, ey, ez), (hx, hy, hz))),
                ex * hx + ey * hy + ez * hz,
            )
            q3, cost3 = choose_lanes(2, t3)
            # back to (θ4, wrist, shoulder, row) lanes, inf where the wrist had no solution
            cost = np.full((8, count), np.inf)
            shoulder_q = np.zeros((3, 8, count))
            for branch in range(2):
                cost[2 * pair + branch, row] = cost2[branch] + cost3[branch]
                for j, values in enumerate((q1, q2, q3)):
                    shoulder_q[j, 2 * pair + branch, row] = values[branch]
            flagged = np.zeros(count, dtype=bool)
            flagged[row[np.any(near_free, axis=0)]] = True
        singular = np.any(singular.reshape(-1, count), axis=0) | flagged
        lane = np.argmin(cost, axis=0)  # ties: the first lane
        columns = np.arange(len(q7))
        out = np.empty((len(q7), 7))
        out[:, 0] = shoulder_q[0, lane, columns]
        out[:, 1] = shoulder_q[1, lane, columns]
        out[:, 2] = shoulder_q[2, lane, columns]
        out[:, 3] = q4[lane >> 2, columns]
        out[:, 4] = q5.reshape(4, -1)[lane >> 1, columns]
        out[:, 5] = q6.reshape(4, -1)[lane >> 1, columns]
        out[:, 6] = q7
        return out, cost[lane, columns], singular
