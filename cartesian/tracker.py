"""Warm-started IK along a path and the quantities that monitor it.

:class:`Tracker` holds, for one plan, the arm, its IK solver and the monitoring thresholds: it
accepts predicted configurations, solves the ones that need Newton steps, factors the Jacobian
for the joint rates and the manipulability, and phrases the events (joint limit, singularity,
jump, velocity) of a sample. :func:`path_targets` evaluates a path at many fractions at once.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import eigenpy
import numpy as np
import pinocchio as pin

from cartesian.events import Event, Status, distinct, joint_units, out_of_reach, where
from cartesian.paths import HeldOrientation, Path
from kinplan.cell import WorkCell
from kinplan.errors import InputError
from kinplan.ik import Evaluation, frobenius_tolerance
from kinplan.model.robot import Robot, manipulability_of
from kinplan.trajectory._profiles import round_up
from kinplan.trajectory.sampling import joint_speeds

#: Default singularity threshold, as a share of the arm's median manipulability.
SINGULAR_FRACTION = 0.05
#: Newton steps per point after a missed prediction (:meth:`Tracker.solve`).
NEWTON_ITERATIONS = 12


# ------------------------------------------------------------------------------------------
class Tracker:
    """Warm-started IK along a path plus the monitoring quantities, on the robot's IK data."""

    def __init__(
        self,
        robot: Robot,
        position_only: bool,
        tolerance: float,
        rotation_tolerance: float,
        singular_threshold: float,
        velocity_scale: float,
        jump_tolerance: float,
        acceleration_limit: np.ndarray | None = None,
    ) -> None:
        self.robot = robot
        #: The work cell the motion is checked against (set by the caller), and the clearance [m].
        self.cell: WorkCell | None = None
        self.clearance = 0.0
        #: Joint acceleration limits [rad/s² or m/s²] (inf: none), default the robot's.
        self.acceleration_limit = (
            robot.acceleration_limit if acceleration_limit is None else acceleration_limit
        )
        self.solver = robot.ik_solver
        #: evaluate(q, position, rotation) -> Evaluation: the tool at q against a target (one
        #: kinematics pass: Jacobian, tool position, pose error; the joint limits not applied).
        #: Position [m] as 3 floats, rotation as 9 floats (row-major) or None.
        self.evaluate: Callable[[np.ndarray, list[float], list[float] | None], Evaluation] = (
            robot.ik_solver.evaluate
        )
        self.position_only = position_only
        self.rows, self.rank = robot.task_rows(position_only), robot.task_rank(position_only)
        # the same rows as a slice when they are consecutive: a view instead of a copy
        first, last = int(self.rows[0]), int(self.rows[-1])
        consecutive = np.array_equal(self.rows, np.arange(first, last + 1))
        self._row_index = slice(first, last + 1) if consecutive else self.rows
        self._all_rows = consecutive and (first, last) == (0, 5)
        rows, cols = len(self.rows), robot.nq
        self._shape = (rows > cols) - (rows < cols)  # −1 wide, 0 square, 1 tall
        self._full_rank = self.rank == min(rows, cols)
        self.tolerance, self.rotation_tolerance = tolerance, rotation_tolerance
        #: (squared position tolerance [m²], tolerance on ‖R* − R‖_F²) of :meth:`within`
        self.tolerances2 = (tolerance * tolerance, frobenius_tolerance(rotation_tolerance))
        self.singular_threshold = singular_threshold
        self.velocity_scale = velocity_scale
        self.speed_limit = robot.velocity_limit * velocity_scale
        self.jump_tolerance = jump_tolerance
        self.units = joint_units(robot)
        # below this manipulability no joint rates can be computed, whatever the threshold:
        # the rates would be a million times the arm's usual ones, and the √det of a Gram
        # matrix JJᵀ carries a rounding noise of √ε‖J‖² (1e-7 for a 3 m arm at full stretch)
        self.rank_floor = 1e-6 * robot.reference_manipulability(position_only)

    def solve(
        self,
        guess: np.ndarray,
        position: np.ndarray,
        rotation: np.ndarray | None,
        evaluated: Evaluation | None = None,
        iterations: int = NEWTON_ITERATIONS,
    ) -> tuple[np.ndarray, bool, float, float, int, Evaluation]:
        """Newton steps from ``guess``, ignoring the joint limits (the caller checks them: a
        joint that must leave its range is a ``joint_limit`` event, never a clamp).
        ``evaluated``: the evaluation at ``guess`` that did not meet the tolerances, reused
        (see :meth:`IKSolver.descend`). Returns (q, converged, position error [m], rotation
        error [rad], iterations, the evaluation at q)."""
        return self.solver.descend(
            guess, position, rotation, self.tolerance, self.rotation_tolerance, iterations,
            clamp=False, evaluated=evaluated,
        )  # fmt: skip

    def within(self, evaluation: Evaluation) -> bool:
        """Whether an evaluation meets the follower's position and rotation tolerances."""
        dx, dy, dz, frobenius2 = evaluation.differences
        position2, frobenius_tolerance2 = self.tolerances2
        return dx * dx + dy * dy + dz * dz <= position2 and frobenius2 <= frobenius_tolerance2

    def beyond_limit(self, q: np.ndarray) -> int | None:
        """Index of the joint furthest beyond its position limits at ``q``, or None."""
        over = np.maximum(self.robot.lower - q, q - self.robot.upper)
        j = int(np.argmax(over))
        return j if over[j] > 0.0 else None

    def limit_event(
        self, k: int, t: float, s: float, q: np.ndarray, j: int, position: np.ndarray
    ) -> Event:
        """The "joint_limit" event of joint ``j`` beyond its range at ``q``."""
        robot = self.robot
        name, unit = robot.joint_names[j], self.units[j]
        upper = q[j] > robot.upper[j]
        bound = robot.upper[j] if upper else robot.lower[j]
        value, limit = distinct(float(q[j]), float(bound))
        return Event(
            Status.JOINT_LIMIT, float(t), float(s), k,
            f"joint {name} would need {value} {unit}, beyond its {'upper' if upper else 'lower'}"
            f" limit {limit} {unit}, to keep the tool on the path at {where(position)}",
            position, name, float(q[j]), float(bound),
            remedy=f"start from a configuration with joint {name} further from that limit "
            "(another q_seed), or move the path",
        )  # fmt: skip

    def factor(self, jacobian: np.ndarray) -> float:
        """Factor the task rows J of a tool ``jacobian`` (6, nq) for :meth:`rates`; return the
        manipulability.

        One LU factorisation (partial pivoting) serves the joint velocities and the
        manipulability: of J itself when it is square (manipulability |det J|), else of the
        smaller Gram matrix JJᵀ or JᵀJ (manipulability √det). A structurally rank-deficient
        task falls back to the pseudo-inverse. An exactly singular J gives 0.
        """
        J = self._J = jacobian if self._all_rows else jacobian[self._row_index]
        if not self._full_rank:
            self._lu = None
            return float(manipulability_of(J, self.rank))
        if self._shape == 0:
            self._lu = eigenpy.PartialPivLU(J)
            return abs(self._lu.determinant())
        self._lu = eigenpy.PartialPivLU(J.dot(J.T) if self._shape < 0 else J.T.dot(J))
        return math.sqrt(max(self._lu.determinant(), 0.0))

    def rates(self, b: np.ndarray) -> np.ndarray:
        """J⁺ b for the last factored J: the solution (square), least squares (tall) or minimum
        norm (wide)."""
        J, lu, shape = self._J, self._lu, self._shape
        if lu is None:  # a task of deficient rank: its `rank` directions only
            return truncated_pinv(J, self.rank) @ b
        if shape == 0:
            return lu.solve(b)
        return lu.solve(b).dot(J) if shape < 0 else lu.solve(b.dot(J))

    def accelerations(
        self,
        q: np.ndarray,
        jacobians: np.ndarray,
        qd: np.ndarray,
        xdd: np.ndarray,
        pinv: np.ndarray | None = None,
    ) -> np.ndarray:
        """q̈ = dq̇/dt [rad/s²] of the rates q̇ = J⁺ẋ, at many samples at once.

        q̈ = J⁺(ẍ − J̇q̇) + (I − J⁺J) J̇ᵀJ⁺ᵀq̇, computed as z + J⁺(ẍ − J̇q̇ − Jz) with
        z = J̇ᵀJ⁺ᵀq̇. The second term is the null-space part of the derivative of a redundant
        arm's minimum-norm rate; it vanishes (and is skipped) when J has full column rank
        (square or tall J).
        J̇ comes from the Jacobians and the rates (:meth:`~kinplan.robot.Robot.
        jacobian_time_variations`: no kinematics pass unless the arm has mimic joints).

        Args:
            q: Joint positions (N, nq) of the samples.
            jacobians: Tool Jacobians (N, 6, nq) of the samples (their evaluations).
            qd: Joint velocities (N, nq) [rad/s] there.
            xdd: Task accelerations (N, r): the tool origin's classical acceleration [m/s²] and
                the angular acceleration [rad/s²], in the task rows.
            pinv: The task rows' pseudo-inverses (N, nq, r) (:func:`pseudo_inverses`), when
                the caller has them at hand.
        """
        J_dot = self.robot.jacobian_time_variations(q, qd, jacobians)
        J = jacobians
        if not self._all_rows:
            J_dot, J = J_dot[:, self.rows], J[:, self.rows]
        if pinv is None:
            pinv = pseudo_inverses(J, self.rank)
        b = xdd - matvec(J_dot, qd)
        if self.rank == J.shape[2]:  # full column rank: no null space
            return matvec(pinv, b)
        z = matvec(J_dot.transpose(0, 2, 1), matvec(pinv.transpose(0, 2, 1), qd))
        return z + matvec(pinv, b - matvec(J, z))

    def check_sample(
        self,
        k: int,
        t: float,
        s: float,
        evaluation: Evaluation,
        q_prev: np.ndarray | None,
        qd_prev: np.ndarray | None,
        h: float,
        xd: np.ndarray,
        position: np.ndarray,
        corrections: int,
    ) -> tuple[Event | None, np.ndarray | None, float, np.ndarray | None]:
        """Check a solved sample k (its ``evaluation`` at its configuration q): joint limits,
        singularity and, when Newton ``corrections`` moved it off its prediction, a jump
        relative to the previous sample.

        Args:
            q_prev, qd_prev: Previous sample's configuration and rates (None at k = 0).
            h: Time step from the previous sample [s].
            xd: Task velocity of the sample.

        Returns:
            (event or None, Jacobian (6, nq), manipulability, rates q̇); the last three are
            None / nan where the check stopped before computing them.
        """
        q = evaluation.q
        j = self.beyond_limit(q)
        if j is not None:
            return self.limit_event(k, t, s, q, j, position), None, math.nan, None
        J = evaluation.jacobian
        m = self.factor(J)
        if self.is_singular(m):
            return self.singular_event(k, t, s, m, position), J, m, None
        qd = self.rates(xd)
        event = None
        if corrections:  # an uncorrected prediction (q = guess) cannot jump
            event = self.jump_event(k, t, s, q, q_prev, qd, qd_prev, h, position)
        return event, J, m, qd

    def coarse_step_event(
        self,
        k: int,
        t: np.ndarray,
        s: float,
        q: np.ndarray,
        q_prev: np.ndarray,
        qd: np.ndarray,
        qd_prev: np.ndarray | None,
        h: float,
        position: np.ndarray,
        qs: list[np.ndarray],
        qds: list[np.ndarray],
    ) -> Event | None:
        """The event of sample k whose step its rates do not explain although the path is
        continuous there (a finer trace reached q): the motion is too fast for a joint (a
        "velocity_limit" at the step's mean speed) or, with the speed limits lifted, too fast
        for the sampling (a "jump" that says so, with a smaller dt as its remedy).

        Args:
            t: All sample times [s] (sample k's is t[k]).
            q, q_prev, qd, qd_prev: The sample's and the previous sample's configurations and
                rates.
            h: Time step between them [s].
            qs, qds: Configurations and rates of the samples achieved before.
        """
        ratios = np.abs(q - q_prev) / h / self.speed_limit
        if ratios.max() > 1.0:
            before = joint_speeds(np.array(qs), np.array(qds), t[: len(qs)]) / self.speed_limit
            peak = max(float(ratios.max()), float(before.max(initial=0.0)))
            return self.speed_event(k, t[k], s, ratios, peak, position)
        return self.jump_event(k, t[k], s, q, q_prev, qd, qd_prev, h, position, continuous=True)

    def is_singular(self, m: float) -> bool:
        """Whether manipulability ``m`` is under the threshold, or so small (numerically zero)
        that no joint rates can be computed, whatever the threshold."""
        return not m >= self.singular_threshold or m <= self.rank_floor

    def singular_event(
        self, k: int, t: float, s: float, m: float, position: np.ndarray
    ) -> Event | None:
        """A "singular" event when :meth:`is_singular` holds for the manipulability m."""
        if not self.is_singular(m):
            return None
        return Event(
            Status.SINGULAR, float(t), float(s), k,
            f"near a singularity at {where(position)}: manipulability {m:.3g} is below "
            f"{max(self.singular_threshold, self.rank_floor):.3g}",
            position, value=m, limit=self.singular_threshold,
            remedy="keep the path away from the workspace boundary and from configurations "
            "with aligned joint axes",
        )  # fmt: skip

    def jump_event(
        self,
        k: int,
        t: float,
        s: float,
        q: np.ndarray,
        q_prev: np.ndarray | None,
        rate: np.ndarray,
        rate_prev: np.ndarray | None,
        h: float,
        position: np.ndarray,
        continuous: bool = False,
    ) -> Event | None:
        """A "jump" event when q moved more than its rates explain over the step h: a branch
        flip or, when a finer trace showed the path ``continuous`` there, a sampling too coarse
        for the motion."""
        if q_prev is None:
            return None
        assert rate_prev is not None  # a previous sample comes with its rates
        step = abs(q - q_prev - 0.5 * (rate + rate_prev) * h)
        if step.max() <= self.jump_tolerance:
            return None
        j = int(np.argmax(step))
        name, unit = self.robot.joint_names[j], self.units[j]
        if continuous:
            why = "the path is continuous there, but the sampling is too coarse for the motion"
            remedy = f"sample more finely (a dt well below {h:.3g} s)"
        else:
            why = "a branch flip"
            remedy = "start from another configuration (q_seed) or split the path there"
        return Event(
            Status.SAMPLING if continuous else Status.JUMP, float(t), float(s), k,
            f"joint {name} moves {q[j] - q_prev[j]:.4f} {unit} in {h:.3g} s at "
            f"{where(position)}, {step[j]:.4f} {unit} more than its rates explain: {why}",
            position, name, float(q[j] - q_prev[j]), self.jump_tolerance, remedy=remedy,
        )  # fmt: skip

    def speed_event(
        self, k: int, t: float, s: float, ratios: np.ndarray, peak: float, position: np.ndarray
    ) -> Event:
        """The "velocity_limit" event of sample k, for the joint furthest above its (scaled)
        limit.

        Args:
            ratios: Joint speeds of the sample over their limits
                (:func:`kinplan.sampling.joint_speeds`).
            peak: The largest such ratio over the whole motion.
        """
        j = int(np.argmax(ratios))
        name, unit = self.robot.joint_names[j], self.units[j]
        speed, limit = float(ratios[j] * self.speed_limit[j]), float(self.speed_limit[j])
        scaled = "" if self.velocity_scale == 1.0 else f" ({self.velocity_scale:g} of its rating)"
        return Event(
            Status.VELOCITY_LIMIT, float(t), float(s), k,
            f"joint {name} would need {speed:.4g} {unit}/s, above its limit {limit:.4g} "
            f"{unit}/s{scaled}, at {where(position)} (the motion needs up to {peak:.3g}× the "
            "joint speed limits)",
            position, name, speed, limit,
            remedy=f"slow the tool down by a factor of at least {round_up(peak, 3):g} (a lower "
            "speed "
            "or a longer duration)",
        )  # fmt: skip

    def acceleration_event(
        self, k: int, t: float, s: float, qdd: np.ndarray, peak: float, position: np.ndarray
    ) -> Event:
        """The "acceleration_limit" event of sample k with joint accelerations ``qdd``, for the
        joint furthest above its limit; ``peak``: the largest ratio over the motion."""
        ratios = np.abs(qdd) / self.acceleration_limit
        j = int(np.argmax(ratios))
        name, unit = self.robot.joint_names[j], self.units[j]
        limit = float(self.acceleration_limit[j])
        return Event(
            Status.ACCELERATION_LIMIT, float(t), float(s), k,
            f"joint {name} would need {abs(qdd[j]):.4g} {unit}/s², above its limit {limit:.4g} "
            f"{unit}/s², at {where(position)} (the motion needs up to {peak:.3g}× the joint "
            "acceleration limits)",
            position, name, float(qdd[j]), limit,
            remedy="slow the tool down by a factor of at least "
            f"{round_up(math.sqrt(peak), 3):g} (a "
            "lower speed or a longer duration)",
        )  # fmt: skip

    def start(
        self, position: np.ndarray, rotation: np.ndarray | None, seed: np.ndarray
    ) -> np.ndarray:
        """Configuration for the first point: full IK from ``seed`` (the seed's branch), or the
        seed itself when IK fails (the tracking step then diagnoses why)."""
        target = position if rotation is None else pin.SE3(rotation, position)
        first = self.robot.ik(
            target, q_seed=seed, position_only=rotation is None,
            position_tolerance=self.tolerance, rotation_tolerance=self.rotation_tolerance,
        )  # fmt: skip
        return first.q if first.success else seed

    def rescue(
        self,
        k: int,
        t: float,
        s: float,
        guess: np.ndarray,
        q_prev: np.ndarray | None,
        position: np.ndarray,
        rotation: np.ndarray | None,
    ) -> np.ndarray | Event:
        """Sample k after the short Newton pass from the prediction failed: a configuration
        found by a longer search (the caller checks it for limits and jumps), or the event that
        says why there is none: jump (reachable only on another branch) or unreachable."""
        robot = self.robot
        q, converged, *_, evaluation = self.solve(guess, position, rotation, iterations=60)
        if converged:
            return q
        # the arm cannot move the tool in every task direction although some of its joints are
        # redundant there (parallel prismatic joints, a tool on a joint's axis): say so; an arm
        # with fewer joints than task rows (a planar 2R asked for a pose) gets the full solver's
        # closest pose below, which says more
        if self.rank < len(self.rows) and self.rank < robot.nq:
            event = self.rank_event(k, t, s, evaluation, position, rotation)
            if event is not None:
                return event
        target = position if rotation is None else pin.SE3(rotation, position)
        only = rotation is None
        here = where(position)
        # the full solver (closed form or restarts), from the previous sample (its branch)
        res = robot.ik(
            target, q_seed=guess if q_prev is None else q_prev, position_only=only,
            position_tolerance=self.tolerance, rotation_tolerance=self.rotation_tolerance,
        )  # fmt: skip
        if res.success:
            if q_prev is None:
                return res.q
            j = int(np.argmax(np.abs(res.q - q_prev)))
            if abs(res.q[j] - q_prev[j]) <= self.jump_tolerance:
                return res.q  # the same branch, found by the full solver
            name, unit = robot.joint_names[j], self.units[j]
            return Event(
                Status.JUMP, t, s, k,
                f"{here} is reachable only on another branch: joint {name} would jump "
                f"from {q_prev[j]:.4f} to {res.q[j]:.4f} {unit}",
                position, name, float(res.q[j] - q_prev[j]), self.jump_tolerance,
                remedy="split the path there or start from another configuration (q_seed)",
            )  # fmt: skip
        why = out_of_reach(robot, res, position)
        return Event(
            Status.UNREACHABLE, t, s, k, f"{here} is out of reach: {why}", position,
            value=res.position_error,
            remedy="shorten or move the path, or move the robot's base",
        )  # fmt: skip

    def rank_event(
        self,
        k: int,
        t: float,
        s: float,
        evaluation: Evaluation,
        position: np.ndarray,
        rotation: np.ndarray | None,
    ) -> Event | None:
        """The "unreachable" event of a task of deficient rank (fewer independent tool motions
        than task rows: parallel prismatic joints, a 5-joint arm asked for a full pose) when
        what the Newton steps left of the error at ``evaluation`` lies in the directions the
        arm cannot move the tool in (beyond the tolerances, and more than in the others);
        else None (the target is out of reach for another reason)."""
        error = np.zeros(6)  # target minus tool: [m; rad], world-aligned
        error[:3] = evaluation.differences[:3]
        if rotation is not None:
            error[3:] = pin.log3(rotation @ np.array(evaluation.tool_pose)[:3, :3].T)
        J, e = evaluation.jacobian[self.rows], error[self.rows]
        missing = np.linalg.svd(J)[0][:, self.rank :]  # task directions the arm cannot move in
        off = missing @ (missing.T @ e)
        linear = self.rows < 3
        off_m, off_rad = float(np.linalg.norm(off[linear])), float(np.linalg.norm(off[~linear]))
        if off_m <= self.tolerance and off_rad <= self.rotation_tolerance:
            return None
        if np.linalg.norm(e - off) > np.linalg.norm(off):  # mostly where the arm can move
            return None
        robot, rows = self.robot, len(self.rows)
        task = "position" if self.position_only else "pose"
        axes = ("x", "y", "z", "rx", "ry", "rz")
        direction = off / np.linalg.norm(off)
        along = ", ".join(f"{axes[r]} {v:+.3f}" for r, v in zip(self.rows.tolist(), direction))
        remedy = "keep the path in the directions the arm can move the tool in"
        if not self.position_only and robot.task_rank(True) == len(robot.task_rows(True)):
            remedy = (
                f"follow the position only (position_only=True: {robot.name} can move its tool "
                f"position in every direction), or {remedy}"
            )
        angular = bool((~linear).any())
        beyond = f"{off_m:.3g} m and {off_rad:.3g} rad" if angular else f"{off_m:.3g} m"
        tolerances = f"{self.tolerance:g} m" + (
            f", {self.rotation_tolerance:g} rad" if angular else ""
        )
        return Event(
            Status.UNREACHABLE, float(t), float(s), k,
            f"{where(position)} is out of reach along the path: the {robot.nq} joints of "
            f"{robot.name} move its tool {task} in only {self.rank} independent "
            f"direction{'s' if self.rank != 1 else ''} (rank {self.rank} of the {rows}-D task), "
            f"and the path leaves {'them' if self.rank != 1 else 'it'}: the tool would have to "
            f"move along ({along}) "
            f"[{'m, rad' if angular else 'm'}; unit vector], {beyond} beyond what its joints can "
            f"do (tolerance{'s' if angular else ''} {tolerances})",
            position, value=float(np.linalg.norm(off)),
            remedy=f"{remedy} (a path whose tangent the arm's joints can produce)",
        )  # fmt: skip


def truncated_pinv(J: np.ndarray, rank: int) -> np.ndarray:
    """Pseudo-inverse (..., c, r) of J (..., r, c), or of a stack, from its ``rank`` largest
    singular values only (a rank-revealing pseudo-inverse).

    A task of structurally deficient rank (four telescoping segments along one axis; a 5-joint
    arm asked for a full pose) has singular values beyond its rank that are rounding noise
    (1e-16 ‖J‖) or come from axes parallel only to the digits the URDF writes (1e-6 ‖J‖):
    inverting them would turn a path's rounding into joint speeds without bound.
    """
    U, S, Vt = np.linalg.svd(J, full_matrices=False)
    inverse = np.zeros_like(S)
    np.divide(1.0, S[..., :rank], out=inverse[..., :rank], where=S[..., :rank] > 0.0)
    return (Vt.swapaxes(-1, -2) * inverse[..., None, :]) @ U.swapaxes(-1, -2)


def matvec(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A x for stacks of matrices (N, r, c) and vectors (N, c)."""
    return (A @ x[:, :, None])[:, :, 0]


def pseudo_inverses(J: np.ndarray, rank: int) -> np.ndarray:
    """Pseudo-inverses J⁺ (N, c, r) of a stack of task Jacobians (N, r, c) of the given rank:
    from the inverse of J or of its smaller Gram matrix when the rank is full, else by SVD."""
    rows, cols = J.shape[1:]
    J_t = J.transpose(0, 2, 1)
    if rank == rows == cols:
        return np.linalg.inv(J)
    if rank == rows:
        return J_t @ np.linalg.inv(J @ J_t)
    if rank == cols:
        return np.linalg.inv(J_t @ J) @ J_t
    return truncated_pinv(J, rank)


def adams_bashforth_weights(steps: np.ndarray) -> list[tuple[float, float]]:
    """Weights (a_k, b_k) of the two-step Adams–Bashforth prediction q_k ≈ q_(k−1) +
    a_k q̇_(k−1) + b_k q̇_(k−2), for steps h_k = t_k − t_(k−1) [s] (``steps`` are h_1, h_2, ...):
    q + h q̇ + (h²/2) q̈ with q̈ ≈ (q̇_(k−1) − q̇_(k−2)) / h_(k−1). Entry k of the list is for
    sample k (entries 0 and 1 are unused)."""
    h = np.concatenate([[np.nan, np.nan], steps[1:]])
    h_prev = np.concatenate([[np.nan, np.nan], steps[:-1]])
    ratio = 0.5 * h / h_prev
    return list(zip((h * (1.0 + ratio)).tolist(), (-h * ratio).tolist()))


def resolve_task(
    robot: Robot, path: Path, position_only: bool | None, seed: np.ndarray
) -> tuple[Path, bool]:
    """The path the tool follows and whether its orientation is ignored.

    ``position_only=None``: position only on arms with fewer than 6 joints; otherwise the path's
    orientation, and a path built from 3-vectors keeps the tool orientation the arm starts with
    (the seed's FK: :class:`~cartesian.paths.HeldOrientation`). ``True`` ignores the
    orientation; ``False`` on a 3-vector path also holds the start orientation (an InputError on
    an arm with fewer than 6 joints).
    """
    if position_only is None:
        position_only = robot.default_position_only()
    if position_only:
        return path, True
    if not path.has_orientation:
        if robot.default_position_only():
            raise InputError(
                f"the path has no orientation (built from 3-vectors) and {robot.name} has "
                f"{robot.nq} joints (fewer than 6, so it cannot hold one): use position_only=True"
            )
        path = HeldOrientation(path, robot.fk(seed).rotation)
    return path, False


@dataclass
class Targets:
    """Tool targets along a path at fractions s, in the task rows of the arm.

    Attributes:
        positions: Tool positions [m], (N, 3).
        rotations: Tool rotations (N, 3, 3), or None for a position-only task.
        rate: dx/ds of the task rows (linear [m], angular [rad] per unit s), (N, r).
        curvature: d²x/ds² of the task rows, (N, r).
    """

    positions: np.ndarray
    rotations: np.ndarray | None
    rate: np.ndarray
    curvature: np.ndarray


def path_targets(path: Path, s: np.ndarray, position_only: bool, rows: np.ndarray) -> Targets:
    """Evaluate the path at fractions ``s`` (vectorised): poses and their s-derivatives."""
    first, second = np.zeros((len(s), 6)), np.zeros((len(s), 6))
    first[:, :3], second[:, :3] = path.position_derivatives(s)
    rotations = None
    if not position_only:
        rotations = path.rotation(s)
        first[:, 3:], second[:, 3:] = path.angular_rates(s)
    return Targets(path.position(s), rotations, first[:, rows], second[:, rows])
