"""Semi-analytic inverse kinematics for 7-joint arms of the Franka Emika panda type.

With the last joint angle θ7 fixed, the remaining six joints have a closed form (the idea of He &
Liu, *Analytical Inverse Kinematics for Franka Emika Panda – a Geometrical Solver for 7-DOF
Manipulators with Unconventional Design*, 2021). It is derived here in the screw form of
:mod:`kinplan.ik.ur`, on the model's own frames: at q = 0 every joint i is a rotation about
a unit axis ``ωᵢ`` through a point ``pᵢ`` (world frame), and the tool pose is
``T(q) = exp(S1 θ1) ⋯ exp(S7 θ7) M``. The structure this needs, checked on the model:

* axes 1, 2, 3 meet in one point ``s`` (the shoulder centre; 1 ∦ 2, 2 ∦ 3);
* axes 5 and 6 meet in one point ``w`` (5 ∦ 6);
* ``s`` and ``w`` both lie off axis 4 (the elbow changes their distance).

Axis 7 and the tool frame are arbitrary (the panda's 0.088 m offset of axis 7 from the wrist is
the reason θ7 cannot be solved with the others). For a target pose ``T`` and a given θ7:

1. ``P = T M⁻¹ exp(−S7 θ7) = exp(S1 θ1) ⋯ exp(S6 θ6)``; joints 1–3 do not move ``s``, so
   ``y = P⁻¹ s = exp(−S6 θ6) exp(−S5 θ5) exp(−S4 θ4) s``.
2. θ4 (two branches): joints 5 and 6 do not change distances to ``w``, so
   ``|exp(−S4 θ4) s − w| = |y − w|`` (Paden–Kahan subproblem 3).
3. θ5, θ6 (two branches): rotate ``u = exp(−S4 θ4) s − w`` onto ``v = y − w`` about axes 5
   then 6 (subproblem 2).
4. θ1, θ2, θ3 (two branches): the shoulder rotation ``G = R1 R2 R3 = R_P R6ᵀ R5ᵀ R4ᵀ`` is
   split like an Euler-angle triple: ``R1 R2 ω3 = G ω3`` (subproblem 2), then θ3 from ``G e``
   for a unit ``e ⊥ ω3`` (subproblem 1).

Up to 8 solutions per θ7. Joint angles are equivalent modulo 2π: :meth:`PandaIK.solutions_q7`
lists each solution once, as its equivalent within the limits closest to mid-range;
:meth:`PandaIK.nearest` picks per joint the equivalent within the limits closest to the
reference. When θ7 of the reference admits no solution within the limits, θ7 is searched
coarse to fine over its range.

Everything per pose is plain Python floats (numpy's per-call overhead would dominate a 3-vector
computation): vectors are 3-tuples, rotation matrices row-major 9-tuples.

:class:`PandaIK` is the solver; its parts live in the modules before it, each importing only
those before it: :mod:`~kinplan.ik.panda_geometry` (the arm read from the model, the float
arithmetic) → :mod:`~kinplan.ik.panda_subproblems` (subproblems 1 and 2) →
:mod:`~kinplan.ik.panda_intervals` (the θ7 search's intervals) → :mod:`~kinplan.ik.panda_batch`
(the search over many poses, a base class of :class:`PandaIK`) → ``panda`` (the per-θ7 closed
form, the θ7 search, :func:`panda_solver_for`). The compiled per-θ7 solve and θ7 search are
:mod:`~kinplan.ik.panda_kernel`. Every name this module had before that split is still
importable from it, the helpers under their former private names (bound below), which are also
the names :class:`PandaIK` calls them by.
"""

from __future__ import annotations

import logging
import math
from operator import itemgetter
from typing import Any

import numpy as np

from kinplan.errors import InputError
from kinplan.ik.base import self_check
from kinplan.ik.panda_batch import PandaBatch
from kinplan.ik.panda_geometry import (
    Mat,
    PandaGeometry,
    Vec,
    cross,
    cross_many,
    distance_to_line,
    dot,
    dot_many,
    floats,
    line_intersection,
    map_floats,
    matmul,
    matmul_many,
    matrix_floats,
    matvec,
    matvec_many,
    panda_geometry,
    rotate,
    rotate_cs,
    rotate_cs_many,
    rotation_matrix,
    rotation_matrix_cs,
    sub,
    sub_many,
)
from kinplan.ik.panda_intervals import (
    Q7_EDGE_MARGIN,
    Q7_GRIDS,
    Q7_STEPS,
    cos_range,
    intervals_within,
    project,
    project_many,
)
from kinplan.ik.panda_subproblems import NEAR_FREE, AxisPair, angle_about
from kinplan.ik.screws import (
    CLAMP,
    FREE_TOL,
    LIMIT_TOL,
    joint_choice,
    plane_basis,
)
from kinplan.ik.screws import STRUCTURE_TOL as STRUCTURE_TOL
from kinplan.ik.screws import TAU as TAU
from kinplan.ik.screws import joint_choice_many as joint_choice_many
from kinplan.ik.screws import screws_at_zero as screws_at_zero
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)

# The former names of the helpers, before the split (PandaIK below calls them by these).
_dot, _cross, _sub, _matvec, _matmul = dot, cross, sub, matvec, matmul
_rotate, _rotate_cs, _rotation_matrix = rotate, rotate_cs, rotation_matrix
_sub_many, _dot_many, _cross_many = sub_many, dot_many, cross_many
_matvec_many, _matmul_many, _rotate_cs_many = matvec_many, matmul_many, rotate_cs_many
_map, _rotation_matrix_cs = map_floats, rotation_matrix_cs
_floats, _matrix_floats = floats, matrix_floats
_line_intersection, _distance_to_line = line_intersection, distance_to_line
_cos_range, _intervals_within = cos_range, intervals_within
_project, _project_many = project, project_many
_Q7_STEPS, _Q7_GRIDS, _Q7_EDGE_MARGIN = Q7_STEPS, Q7_GRIDS, Q7_EDGE_MARGIN
_angle_about, _AxisPair, _NEAR_FREE = angle_about, AxisPair, NEAR_FREE

#: Solutions this close [rad, max-norm] are the same solution (they meet at singularities).
_SAME_TOL = 1e-9

#: Per joint: (reference, reference clipped into the limits, lower, upper, weight) [rad, –].
_Joint = tuple[float, float, float, float, float]


_KERNEL: list[Any] = []  # kinplan.ik.panda_kernel once imported (numba loads on first use)


def _panda_kernel() -> Any:
    """The module :mod:`kinplan.ik.panda_kernel`, imported on the first call."""
    if not _KERNEL:
        from kinplan.ik import panda_kernel

        _KERNEL.append(panda_kernel)
    return _KERNEL[0]


# ---------------------------------------------------------------------------- solver
class PandaIK(PandaBatch):
    """Closed-form IK of a panda-type arm for a fixed θ7, with a θ7 search for :meth:`nearest`.

    The same search over many poses at once (:meth:`nearest_many`) runs compiled pose by pose,
    or without numba vectorised over the poses (the base class
    :class:`~kinplan.ik.panda_batch.PandaBatch`).

    Args:
        geometry: The arm at q = 0 (:func:`panda_geometry`).
        lower: Lower joint limits [rad], shape (7,).
        upper: Upper joint limits [rad], shape (7,).
        weights: Joint weights w of the distance Σ wᵢ Δqᵢ² by which :meth:`nearest` chooses
            (default: all ones), shape (7,).
    """

    nq = 7
    needs_rotation = True
    #: The solution nearest the seed is sought at the seed's θ7, else within the θ7 intervals
    #: where the elbow reaches; where those solutions break another joint's limits a solution
    #: at another θ7 may still exist (Yaskawa's SIA20D: 0.2 % of random reachable targets):
    #: ``ik`` and ``ik_batch`` then solve numerically.
    complete = False

    def __init__(
        self,
        geometry: PandaGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        self.geometry = geometry
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.weights = np.ones(7) if weights is None else np.asarray(weights, dtype=float)
        self._lo = [float(x) for x in self.lower]
        self._hi = [float(x) for x in self.upper]
        self._w = [float(x) for x in self.weights]
        self._limits = tuple(zip(self._lo, self._hi, self._w))
        self._mid_joints = self._joints(0.5 * (self.lower + self.upper))
        self._constants: tuple[np.ndarray, ...] | None = None  # of the compiled solve
        self._search: tuple[np.ndarray, ...] | None = None  # of the compiled search, on first use
        g = geometry
        self._wrist_pair = _AxisPair.of(g.axes[4], g.axes[5])  # Ra = axis 5, Rb = axis 6
        self._shoulder_pair = _AxisPair.of(g.axes[1], g.axes[0])  # Ra = axis 2, Rb = axis 1
        self._e3 = _floats(plane_basis(np.array(g.axes[2]))[0])  # ⟂ axis 3, for θ3
        # θ4: s and w relative to a point of axis 4, split along / across the axis
        a4, p4 = g.axes[3], g.points[3]
        s, w = _sub(g.shoulder, p4), _sub(g.wrist, p4)
        self._s4, self._w4 = s, w
        s_along = _dot(a4, s)
        s_perp = (s[0] - s_along * a4[0], s[1] - s_along * a4[1], s[2] - s_along * a4[2])
        self._q4_const = _dot(w, a4) * s_along  # w·s_par
        self._q4_cos = _dot(w, s_perp)  # coefficient of cos(−θ4)
        self._q4_sin = _dot(w, _cross(a4, s))  # coefficient of sin(−θ4)
        self._q4_amplitude = math.hypot(self._q4_cos, self._q4_sin)
        self._q4_phase = math.atan2(self._q4_sin, self._q4_cos)
        self._q4_lengths = _dot(s, s) + _dot(w, w)
        # |y − w|² (y as in _solve) for which θ4 has a value within its limits: cos(θ4 + phase)
        # is the ratio of _elbow, which falls as |y − w|² grows
        low, high = _cos_range(self._lo[3] + self._q4_phase, self._hi[3] + self._q4_phase)
        self._elbow_distance2 = tuple(
            self._q4_lengths - 2.0 * (self._q4_const + self._q4_amplitude * ratio)
            for ratio in (high, low)
        )
        self._p7_from_wrist = _sub(g.points[6], g.wrist)
        m = g.tool_rotation
        self._tool_rotation_t: Mat = (m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8])
        span = self._hi[6] - self._lo[6]
        self._q7_grids = [
            [self._lo[6] + (i + 0.5) * span / cells for i in range(cells)] for cells in _Q7_GRIDS
        ]

    # ------------------------------------------------------------ input checks
    def _pose(self, position, rotation) -> tuple[Vec, Mat]:
        """(position, row-major rotation) as floats; InputError when malformed."""
        p = np.asarray(position, dtype=float)
        r = np.asarray(rotation, dtype=float)
        if p.shape != (3,) or r.shape != (3, 3):
            raise InputError(
                f"a pose needs a 3-vector position [m] and a 3×3 rotation, got shapes "
                f"{p.shape} and {r.shape}"
            )
        p_list, r_list = p.tolist(), r.reshape(-1).tolist()
        if not math.isfinite(sum(p_list) + sum(r_list)):
            raise InputError(f"the pose must be finite, got {p_list} and {r_list}")
        return tuple(p_list), tuple(r_list)

    def _joints(self, q_ref) -> list[_Joint]:
        """Per joint: (reference, reference clipped into the limits, lower, upper, weight)."""
        q = np.asarray(q_ref, dtype=float)
        if q.shape != (7,):
            raise InputError(f"q_ref must be a vector of 7 joint values, got shape {q.shape}")
        ref = q.tolist()
        if not math.isfinite(sum(ref)):
            raise InputError(f"q_ref must be finite, got {ref}")
        return [(r, min(max(r, lo), hi), lo, hi, w) for r, (lo, hi, w) in zip(ref, self._limits)]

    # ------------------------------------------------------------ the closed form
    def _prepare(self, position: Vec, rotation: Mat) -> tuple[Vec, Mat]:
        """The θ7-independent part of a pose (world frame).

        Returns:
            ``M T⁻¹ s`` [m] (the shoulder centre seen from the tool frame, placed at the tool's
            zero pose) and ``R_T M_Rᵀ`` (row-major).
        """
        g = self.geometry
        r = rotation
        d = _sub(g.shoulder, position)
        local = (  # R_Tᵀ (s − p_T)
            r[0] * d[0] + r[3] * d[1] + r[6] * d[2],
            r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
            r[2] * d[0] + r[5] * d[1] + r[8] * d[2],
        )
        moved = _matvec(g.tool_rotation, local)
        t = g.tool_translation
        seen = (moved[0] + t[0], moved[1] + t[1], moved[2] + t[2])
        return seen, _matmul(rotation, self._tool_rotation_t)

    def _solve(
        self, prepared: tuple[Vec, Mat], q7: float, joints: list[_Joint], prune: bool
    ) -> list[tuple[list[float], float]]:
        """The solutions within the limits for one θ7.

        Joint by joint (θ4, then θ5 and θ6, then the shoulder), each branch's value is replaced
        by its 2π-equivalent within the limits nearest the reference (the branch is dropped when
        there is none), and the weighted squared distance Σ wᵢ Δqᵢ² to the reference is summed.

        Args:
            prepared: :meth:`_prepare` of the pose.
            q7: θ7 [rad], within its limits.
            joints: :meth:`_joints` of the reference; free joints (singularities) take the
                reference values.
            prune: Only keep a solution nearer than every earlier one (branch and bound): the
                last entry is then the nearest.

        Returns:
            (configuration [rad], distance [rad²]) pairs.
        """
        g = self.geometry
        seen, rotation_tm = prepared
        a4, a5, a6, a7, p7 = g.axes[3], g.axes[4], g.axes[5], g.axes[6], g.points[6]
        # y = exp(S7 θ7) M T⁻¹ s: the shoulder centre as the wrist joints see it
        y = _rotate(_sub(seen, p7), a7, q7)
        v = (y[0] + p7[0] - g.wrist[0], y[1] + p7[1] - g.wrist[1], y[2] + p7[2] - g.wrist[2])
        rotation_p = None  # R_P, computed when a branch gets as far as the shoulder
        base = joints[6][4] * (q7 - joints[6][0]) ** 2
        bound = math.inf
        out: list[tuple[list[float], float]] = []
        # the wrist part of every branch first: (distance so far, θ4, θ5, θ6, cos and sin of −θ4)
        wrists = []
        free5, free6 = -joints[4][1], -joints[5][1]
        for raw4 in self._elbow(_dot(v, v)):
            c4 = joint_choice(raw4, joints[3])
            if c4 is None:
                continue
            q4, cost4 = c4[0], base + c4[1]
            cos4, sin4 = math.cos(q4), -math.sin(q4)  # rotations by −θ4
            u = _sub(_rotate_cs(self._s4, a4, cos4, sin4), self._w4)  # exp(−S4 θ4) s − w
            for t5, t6 in self._wrist_pair.solve(u, v, free5, free6):
                c5 = joint_choice(-t5, joints[4])
                if c5 is None:
                    continue
                c6 = joint_choice(-t6, joints[5])
                if c6 is not None:
                    wrists.append((cost4 + c5[1] + c6[1], q4, c5[0], c6[0], cos4, sin4))
        if prune:  # nearest first: its bound then cuts the most
            wrists.sort(key=itemgetter(0))
        for cost6, q4, q5, q6, cos4, sin4 in wrists:
            if prune and cost6 >= bound:
                break
            if rotation_p is None:
                rotation_p = _matmul(rotation_tm, _rotation_matrix(a7, -q7))
            # G = R_P R6(−θ6) R5(−θ5) R4(−θ4) = R1 R2 R3, applied to ω3 and e
            cos5, sin5, cos6, sin6 = math.cos(q5), -math.sin(q5), math.cos(q6), -math.sin(q6)
            g3 = _rotate_cs(_rotate_cs(g.axes[2], a4, cos4, sin4), a5, cos5, sin5)
            ge = _rotate_cs(_rotate_cs(self._e3, a4, cos4, sin4), a5, cos5, sin5)
            g3 = _matvec(rotation_p, _rotate_cs(g3, a6, cos6, sin6))
            ge = _matvec(rotation_p, _rotate_cs(ge, a6, cos6, sin6))
            for t2, t1 in self._shoulder_pair.solve(g.axes[2], g3, joints[1][1], joints[0][1]):
                c1, c2 = joint_choice(t1, joints[0]), joint_choice(t2, joints[1])
                if c1 is None or c2 is None:
                    continue
                cost2 = cost6 + c1[1] + c2[1]
                if prune and cost2 >= bound:
                    continue
                # R3(θ3) e = R2(−θ2) R1(−θ1) G e
                h = _rotate(_rotate(ge, g.axes[0], -t1), g.axes[1], -t2)
                t3 = _angle_about(g.axes[2], self._e3, h, joints[2][1])
                c3 = joint_choice(t3, joints[2])
                if c3 is None:
                    continue
                cost = cost2 + c3[1]
                if prune and cost >= bound:
                    continue
                out.append(([c1[0], c2[0], c3[0], q4, q5, q6, q7], cost))
                if prune:
                    bound = cost
        return out

    def _elbow_q7_intervals(self, prepared: tuple[Vec, Mat]) -> list[tuple[float, float]]:
        """The θ7 values [rad] within its limits for which θ4 has a solution within its limits.

        With d = ``M T⁻¹ s`` − p7 and c = p7 − w, |y − w|² = |Rot(ω7, θ7) d + c|²
        = K + 2 (A cos θ7 + B sin θ7) (Rodrigues); θ4 exists within its limits exactly when
        this lies in the range precomputed from those limits (see ``__init__``).

        Returns:
            Sorted disjoint intervals (possibly none: then no θ7 gives a solution).
        """
        a, c = self.geometry.axes[6], self._p7_from_wrist
        d = _sub(prepared[0], self.geometry.points[6])
        ad, ac = _dot(a, d), _dot(a, c)
        cos_part, sin_part = _dot(c, d) - ac * ad, _dot(c, _cross(a, d))
        mean = _dot(d, d) + _dot(c, c) + 2.0 * ac * ad
        # sqrt of the sum of squares (not math.hypot, whose last bit is CPython's own): the
        # compiled search (panda_kernel.search) and nearest_many compute it bit for bit alike
        amplitude = 2.0 * math.sqrt(cos_part * cos_part + sin_part * sin_part)
        low, high = self._elbow_distance2
        lo7, hi7 = self._lo[6], self._hi[6]
        if amplitude < FREE_TOL:  # θ7 does not change the distance
            return [(lo7, hi7)] if low <= mean <= high else []
        c_low, c_high = (low - mean) / amplitude, (high - mean) / amplitude
        if c_low > 1.0 or c_high < -1.0:
            return []
        near = math.acos(min(c_high, 1.0))  # cos(θ7 − φ) ∈ [c_low, c_high]
        far = math.acos(max(c_low, -1.0))
        phi = math.atan2(sin_part, cos_part)
        return _intervals_within([(phi + near, phi + far), (phi - far, phi - near)], lo7, hi7)

    def _elbow(self, distance2: float) -> list[float]:
        """θ4 [rad] (up to two) with |exp(−S4 θ4) s − w|² = ``distance2`` [m²]."""
        # |R(φ)s − w|² = |s|² + |w|² − 2 w·R(φ)s, w·R(φ)s = w·s_par + A cos φ + B sin φ, φ = −θ4
        target = 0.5 * (self._q4_lengths - distance2) - self._q4_const
        ratio = target / self._q4_amplitude
        if abs(ratio) > 1.0 + CLAMP:
            return []
        spread = math.acos(min(max(ratio, -1.0), 1.0))
        if spread == 0.0:
            return [-self._q4_phase]
        return [-(self._q4_phase + spread), -(self._q4_phase - spread)]

    # ------------------------------------------------------------ public API
    def solutions_q7(self, position: np.ndarray, rotation: np.ndarray, q7: float) -> np.ndarray:
        """All solutions within the joint limits with the last joint at ``q7``.

        Each solution appears once, as its 2π-equivalent within the limits closest to
        mid-range. At a singularity a free joint takes its mid-range value.

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame.
            q7: The last joint's angle [rad]; outside its limits there is no solution.

        Returns:
            Joint configurations [rad], shape (k, 7), 0 ≤ k ≤ 8.
        """
        q7 = float(q7)
        prepared = self._prepare(*self._pose(position, rotation))
        if not self._lo[6] - LIMIT_TOL <= q7 <= self._hi[6] + LIMIT_TOL:
            return np.empty((0, 7))
        q7 = min(max(q7, self._lo[6]), self._hi[6])
        found: list[list[float]] = []
        for q, _ in self._solve(prepared, q7, self._mid_joints, prune=False):
            if not any(max(abs(a - b) for a, b in zip(q, other)) <= _SAME_TOL for other in found):
                found.append(q)
        return np.array(found).reshape(-1, 7)

    def elbow_q7_intervals(
        self, position: np.ndarray, rotation: np.ndarray
    ) -> list[tuple[float, float]]:
        """The θ7 values [rad] within its limits for which the elbow (θ4) has a value within
        its limits at this tool pose (position [m], 3×3 rotation, world frame): sorted disjoint
        intervals, possibly none. Outside them no θ7 has a solution within the limits."""
        return self._elbow_q7_intervals(self._prepare(*self._pose(position, rotation)))

    def kernel_constants(self) -> tuple[np.ndarray, ...]:
        """The geometry and precomputed terms the compiled solve reads
        (:func:`kinplan.ik.panda_kernel.nearest_for_q7`), as arrays."""
        g = self.geometry
        vectors = [g.points[6], g.wrist, self._s4, self._w4, self._e3, (0.0, 0.0, 0.0)]
        elbow = [self._q4_lengths, self._q4_const, self._q4_amplitude, self._q4_phase]
        pairs = [
            [*pair.a, *pair.b, pair.c, *pair.normal, pair.normal2]
            for pair in (self._wrist_pair, self._shoulder_pair)
        ]
        limits = [self.lower, self.upper, self.weights]
        return tuple(np.array(x, dtype=float) for x in (g.axes, vectors, elbow, pairs, limits))

    def search_constants(self) -> tuple[np.ndarray, ...]:
        """What the compiled θ7 search (:func:`kinplan.ik.panda_kernel.search`) reads besides
        :meth:`kernel_constants`: the frame rows (10, 3) (shoulder centre s [m]; the tool's
        zero-pose rotation M_R, row by row; its translation M_t [m]; M_Rᵀ row by row; p7 − w
        [m]; the range of |y − w|² [m²] where θ4 fits and the edge margin [rad]), the stages'
        θ7 values (the ±steps [rad], then every grid's values [rad]) and their sizes (the
        number of steps, then each grid's, int64)."""
        g = self.geometry
        m, t = g.tool_rotation, self._tool_rotation_t
        frame = [
            g.shoulder,
            m[0:3],
            m[3:6],
            m[6:9],
            g.tool_translation,
            t[0:3],
            t[3:6],
            t[6:9],
            self._p7_from_wrist,
            (*self._elbow_distance2, _Q7_EDGE_MARGIN),
        ]
        stages = [*_Q7_STEPS, *(x for grid in self._q7_grids for x in grid)]
        sizes = [len(_Q7_STEPS), *(len(grid) for grid in self._q7_grids)]
        return (
            np.array(frame, dtype=float),
            np.array(stages, dtype=float),
            np.array(sizes, dtype=np.int64),
        )

    def _search_inputs(self) -> tuple[np.ndarray, ...] | None:
        """:meth:`kernel_constants` + :meth:`search_constants` when the compiled search can
        run (numba available and switched on, the limits finite), else None."""
        if not _panda_kernel().available():
            return None
        if self._search is None:  # () for limits the search cannot take (not finite)
            finite = bool(np.isfinite(self.lower).all() and np.isfinite(self.upper).all())
            self._search = self.kernel_constants() + self.search_constants() if finite else ()
        return self._search or None

    def _compiled_inputs(
        self, prepared: tuple[Vec, Mat], q_ref: np.ndarray
    ) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray, np.ndarray] | None:
        """What the compiled solve of this pose needs (constants, ``M T⁻¹ s``, ``R_T M_Rᵀ``,
        the reference), or None when it is not available (then the Python solve runs)."""
        from kinplan.ik import panda_kernel  # numba loads on first use

        if not panda_kernel.available():
            return None
        if self._constants is None:
            self._constants = self.kernel_constants()
        seen, rotation_tm = prepared
        return (
            self._constants,
            np.array(seen),
            np.array(rotation_tm).reshape(3, 3),
            np.asarray(q_ref, dtype=float),
        )

    def _best(
        self, prepared: tuple[Vec, Mat], q7_values: list[float], joints: list[_Joint]
    ) -> list[float] | None:
        """The solution nearest the reference over the given θ7 values [rad] (the first on
        ties), or None."""
        best, best_cost = None, math.inf
        for q7 in q7_values:
            found = self._solve(prepared, q7, joints, prune=True)
            if found and found[-1][1] < best_cost:
                best, best_cost = found[-1]
        return best

    def _q7_stages(self, q7_ref: float, intervals: list[tuple[float, float]], tried: set[float]):
        """θ7 values [rad] to try after ``tried``, stage by stage: ±steps around ``q7_ref``, then
        finer grids over the range, each value moved into the set where the elbow can reach
        (``intervals``, see :meth:`_elbow_q7_intervals`); values tried before are skipped."""
        stages = [[q7_ref + step, q7_ref - step] for step in _Q7_STEPS]
        for stage in stages + self._q7_grids:
            values = []
            for value in stage:
                value = _project(min(max(value, self._lo[6]), self._hi[6]), intervals)
                if value not in tried:
                    tried.add(value)
                    values.append(value)
            if values:
                yield values

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref`` (weighted distance Σ wᵢ Δqᵢ²), or None.

        θ7 is searched stage by stage; the nearest solution of the first stage that has one
        is returned. The search runs within the set of θ7 values for which θ4 exists within its
        limits (:meth:`_elbow_q7_intervals`, closed form; when it is empty there is no
        solution). Stages: ``q_ref[6]`` (clipped into its limits) when that set holds it, else
        the point a quarter of the way into the set's nearest interval; then the middle of that
        interval; then ``q_ref[6]`` ± 0.05, 0.1, 0.2, … rad, then grids of 16, 64, 256, 1024
        cells over the range, each value moved to the nearest point of the set. (On random
        pairs of targets and references, the middle of the interval has a solution twice as
        often as its edge.)

        The whole search runs compiled (:func:`kinplan.ik.panda_kernel.search`: the same θ7
        values in the same order, the same answer) when numba is available; without it (or
        with ``KINPLAN_JIT=0``) in Python, as written here.

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame, or None (then None: a redundant
                arm's position-only IK is left to the numerical solver).
            q_ref: Reference configuration [rad], shape (7,).

        Returns:
            The configuration [rad], shape (7,), or None when the search finds no solution.
        """
        if rotation is None:
            return None
        constants = self._search_inputs()
        if constants is not None:
            return self._nearest_compiled(constants, position, rotation, q_ref)
        return self._nearest_python(position, rotation, q_ref)

    def _nearest_python(self, position, rotation, q_ref) -> np.ndarray | None:
        """:meth:`nearest` in Python (``rotation`` given): the fallback and the reference."""
        joints = self._joints(q_ref)
        prepared = self._prepare(*self._pose(position, rotation))
        intervals = self._elbow_q7_intervals(prepared)
        if not intervals:
            return None
        q7_ref = joints[6][1]
        start, end = min(intervals, key=lambda ab: max(ab[0] - q7_ref, q7_ref - ab[1]))
        if start <= q7_ref <= end:
            first = q7_ref
        else:
            first = start + 0.25 * (end - start) if q7_ref < start else end - 0.25 * (end - start)
        best = self._best(prepared, [first], joints)
        middle = 0.5 * (start + end)
        if best is None and middle != first:
            best = self._best(prepared, [middle], joints)
        if best is None:
            for stage in self._q7_stages(q7_ref, intervals, {first, middle}):
                best = self._best(prepared, stage, joints)
                if best is not None:
                    break
        return None if best is None else np.array(best)

    def _nearest_compiled(
        self, constants: tuple[np.ndarray, ...], position, rotation, q_ref
    ) -> np.ndarray | None:
        """:meth:`nearest` by the compiled search; malformed input raises as in Python."""
        kernel = _panda_kernel()
        p = np.ascontiguousarray(position, dtype=float)
        r = np.ascontiguousarray(rotation, dtype=float)
        q = np.ascontiguousarray(q_ref, dtype=float)
        out = np.empty(7)
        if p.shape != (3,) or r.shape != (3, 3) or q.shape != (7,):
            status = kernel.NOT_FINITE  # wrong shapes: the checks below raise
        else:
            status = kernel.search(*constants, p, r, q, out)
        if status == kernel.NOT_FINITE:  # the Python path's checks raise (or it answers)
            return self._nearest_python(position, rotation, q_ref)
        return out if status == kernel.FOUND else None

    def nearest_many(
        self, positions: np.ndarray, rotations: np.ndarray, q_ref: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference (inputs unchecked).

        Compiled (:func:`kinplan.ik.panda_kernel.search_many`: :meth:`nearest`'s search pose
        by pose, the same answers, nothing left over) when numba is available, else the
        vectorised search of :meth:`PandaBatch.nearest_many
        <kinplan.ik.panda_batch.PandaBatch.nearest_many>`.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 7).

        Returns:
            (q (N, 7) [rad], found (N,), left (N,)): ``left`` marks poses the caller should
            solve with :meth:`nearest` (none on the compiled path); the other outputs of such
            poses, and ``q`` where nothing is found, are meaningless.
        """
        constants = self._search_inputs()
        if constants is None:
            return super().nearest_many(positions, rotations, q_ref)
        count = len(positions)
        q = np.zeros((count, 7))
        found = np.zeros(count, dtype=bool)
        if count:
            _panda_kernel().search_many(
                *constants,
                np.ascontiguousarray(positions, dtype=float).reshape(count, 3),
                np.ascontiguousarray(rotations, dtype=float).reshape(count, 3, 3),
                np.ascontiguousarray(q_ref, dtype=float).reshape(count, 7),
                q,
                found,
            )
        return q, found, np.zeros(count, dtype=bool)

    # ------------------------------------------------------------ along a path
    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """:meth:`nearest` sample by sample, each from the previous solution (the last one
        found; ``q_ref`` first). Rows of NaN where none is found. Shapes (N, 3), (N, 3, 3)."""
        if rotations is None:
            raise InputError(
                "the closed-form IK of this 7-joint arm needs the tool rotation; position-only "
                "targets are for the planar 2R (use Arm.ik instead)"
            )
        previous = np.asarray(q_ref, dtype=float)
        out = np.full((len(positions), 7), np.nan)
        for i, (position, rotation) in enumerate(zip(positions, rotations)):
            q = self.nearest(position, rotation, previous)
            if q is not None:
                out[i] = previous = q
        return out


# ---------------------------------------------------------------------------- factory
def panda_solver_for(robot: Arm, weights: np.ndarray | None = None) -> PandaIK | None:
    """The semi-analytic IK of a panda-type ``robot``, or None for any other arm (and for a
    panda-type arm with an unbounded, continuous joint: its numerical IK serves it).

    The structure is read from the Pinocchio model (:func:`panda_geometry`) and the solver is
    checked against Pinocchio's forward kinematics on random configurations.

    Args:
        robot: A :class:`kinplan.Robot`.
        weights: Joint weights of the distance by which :meth:`PandaIK.nearest` chooses.
    """
    geometry = panda_geometry(robot)
    if geometry is None:
        return None
    unbounded = ~(np.isfinite(robot.lower) & np.isfinite(robot.upper))
    if unbounded.any():  # the θ7 search and the mid-range references need finite limits
        names = ", ".join(n for n, u in zip(robot.joint_names, unbounded) if u)
        logger.debug("panda-type IK of %s not used: unbounded joints %s", robot.name, names)
        return None
    solver = PandaIK(geometry, robot.lower, robot.upper, weights)
    check = lambda pose, q: solver.solutions_q7(pose.translation, pose.rotation, q[6])  # noqa: E731
    if not self_check(robot, check):
        logger.debug("panda-type IK of %s disagrees with its forward kinematics", robot.name)
        return None
    return solver
