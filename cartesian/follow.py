"""Following a Cartesian path: IK at every sample, with reachability and singularity monitoring.

:func:`follow` times the path with a 1-D profile, solves IK at every sample warm-started from the
previous one (so the arm stays on its branch), derives joint velocities and accelerations from the
timed path (q̇ = J⁺ẋ, q̈ = dq̇/dt = J⁺(ẍ − J̇q̇) plus, for a redundant arm, the null-space part
of the derivative of its minimum-norm q̇), and stops at the first sample that is unreachable,
beyond a joint limit, needs a branch flip ("jump"), is near a singularity or too fast for a
joint. The plan says where and why (:class:`Event`) and how much of the path was achieved.
:func:`check_reachability` runs the same monitoring on the geometry alone, before any timing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import eigenpy
import numpy as np
import pinocchio as pin

from cartesian.paths import Path
from cartesian.retime import grid_points, retime_for_speed_limits
from cartesian.timing import PathTiming, time_path
from kinplan import checks
from kinplan._profiles import PROFILES
from kinplan.errors import InputError
from kinplan.ik import finite_bounds, frobenius_tolerance, halton
from kinplan.robot import Robot, manipulability_of
from kinplan.sampling import joint_speeds

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: Default singularity threshold, as a share of the arm's median manipulability.
SINGULAR_FRACTION = 0.05


@dataclass
class Event:
    """Why a plan stopped.

    Attributes:
        kind: "unreachable", "joint_limit", "jump", "singular" or "velocity_limit".
        t: Time of the offending sample [s] (0 for a geometric check).
        s: Path fraction of the offending sample [-].
        index: Index of the offending sample.
        message: What happened and where (no advice: see ``remedy``).
        position: Target tool position of the offending sample [m].
        joint: The joint concerned (limits, speeds, jumps), if any.
        value: The offending value (joint position [rad or m], speed [rad/s or m/s],
            manipulability).
        limit: The limit it broke.
        remedy: What the caller of :func:`follow` can do about it ("" when nothing obvious).
    """

    kind: str
    t: float
    s: float
    index: int
    message: str
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    joint: str | None = None
    value: float | None = None
    limit: float | None = None
    remedy: str = ""

    def __str__(self) -> str:
        return f"{self.message}; {self.remedy}" if self.remedy else self.message


@dataclass
class CartesianPlan:
    """A timed, monitored Cartesian motion.

    Attributes:
        t: Sample times [s], shape (N,) (only the samples achieved before a failure).
        q: Joint positions, shape (N, nq).
        qd: Joint velocities [rad/s], shape (N, nq).
        qdd: Joint accelerations [rad/s²], shape (N, nq).
        s: Path fraction of each sample.
        ok: True when the whole path was planned without event.
        status: "ok" or the kind of the first event.
        fraction: Path fraction achieved before the first failure (1.0 when ok).
        events: The events at the offending sample (empty when ok).
        max_deviation: Largest tool distance from the path over the samples [m].
        min_manipulability: Smallest manipulability over the samples.
        duration: Duration of the planned (timed) motion [s].
        path: The Cartesian path.
        position_only: Whether the tool orientation was ignored.
        singular_threshold: Manipulability below which a sample counts as singular.
        tool_positions: Achieved tool positions (FK of q) [m], shape (N, 3).
        manipulability: Manipulability of each sample, shape (N,).
        retimed: Whether the time law was slowed down to respect the joint speed limits.
        retime_duration: For a plan stopped by a velocity limit: the duration of the retimed
            plan (``retime=True``) when that one is ok, else None.
        peak_speed_ratio: Largest joint speed over its (scaled) limit among the samples solved
            (:func:`kinplan.sampling.joint_speeds`), including those past a velocity event: the
            factor by which the motion is too fast (> 1) or has margin (< 1).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    s: np.ndarray
    ok: bool
    status: str
    fraction: float
    events: list[Event]
    max_deviation: float
    min_manipulability: float
    duration: float
    path: Path
    position_only: bool
    singular_threshold: float
    tool_positions: np.ndarray
    manipulability: np.ndarray
    retimed: bool = False
    retime_duration: float | None = None
    peak_speed_ratio: float = 0.0

    def __repr__(self) -> str:
        text = (
            f"CartesianPlan({self.status}, {len(self.t)} samples, {self.duration:.3f} s, "
            f"fraction {self.fraction:.3f}, max deviation {self.max_deviation:.2e} m"
        )
        return text + (f": {self.events[0].message})" if self.events else ")")

    def summary(self) -> str:
        """One line: status, and the first event's message when there is one."""
        if self.ok:
            return f"ok: {len(self.t)} samples, {self.duration:.3f} s"
        return f"{self.status} at s = {self.events[0].s:.3f}: {self.events[0].message}"


@dataclass
class Reachability:
    """Result of :func:`check_reachability` (geometric: no timing).

    Attributes:
        ok: Whether every sampled point of the path is reachable continuously.
        status: "ok" or the kind of the first event.
        fraction: Path fraction reached before the first failure (1.0 when ok).
        events: The events at the first failing point.
        s: Path fractions checked (up to the failure).
        q: Joint positions at those points (IK checks; empty for an analytic check).
    """

    ok: bool
    status: str
    fraction: float
    events: list[Event]
    s: np.ndarray
    q: np.ndarray

    def __repr__(self) -> str:
        text = f"Reachability({self.status}, fraction {self.fraction:.3f}, {len(self.s)} points"
        return text + (f": {self.events[0].message})" if self.events else ")")


# ------------------------------------------------------------------------------------------
class _Tracker:
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
    ):
        self.robot = robot
        self.solver = robot._ik
        self.model, self.data, self.fid = robot.model, robot._ik.data, robot.tip_id
        self.position_only = position_only
        self.rows, self.rank = robot.task_rows(position_only), robot.task_rank(position_only)
        # the same rows as a slice when they are consecutive: a view instead of a copy
        first, last = int(self.rows[0]), int(self.rows[-1])
        consecutive = np.array_equal(self.rows, np.arange(first, last + 1))
        self._row_index = slice(first, last + 1) if consecutive else self.rows
        self._all_rows = consecutive and (first, last) == (0, 5)
        self._flat_jacobian = robot.nq == 1  # eigenpy gives a 1-D array for one column
        rows, cols = len(self.rows), robot.nq
        self._shape = (rows > cols) - (rows < cols)  # −1 wide, 0 square, 1 tall
        self._full_rank = self.rank == min(rows, cols)
        self.tolerance, self.rotation_tolerance = tolerance, rotation_tolerance
        self._tolerances2 = (tolerance * tolerance, frobenius_tolerance(rotation_tolerance))
        self.singular_threshold = singular_threshold
        self.velocity_scale = velocity_scale
        self.speed_limit = robot.velocity_limit * velocity_scale
        self.jump_tolerance = jump_tolerance
        self.units = joint_units(robot)
        # below this manipulability no joint rates can be computed, whatever the threshold:
        # the rates would be a million times the arm's usual ones, and the √det of a Gram
        # matrix JJᵀ carries a rounding noise of √ε‖J‖² (1e-7 for a 3 m arm at full stretch)
        self.rank_floor = 1e-6 * reference_manipulability(robot, position_only)

    def solve(self, guess, position, rotation, evaluated: bool = False, iterations: int = 12):
        """Newton steps from ``guess``, ignoring the joint limits (the caller checks them: a
        joint that must leave its range is a ``joint_limit`` event, never a clamp).
        ``evaluated``: see :meth:`IKSolver.descend`."""
        return self.solver.descend(
            guess, position, rotation, self.tolerance, self.rotation_tolerance, iterations,
            clamp=False, evaluated=evaluated,
        )  # fmt: skip

    def accepts(
        self, guess: np.ndarray, position: list[float], rotation: list[float] | None
    ) -> np.ndarray | None:
        """``guess`` itself when the tool there already meets the tolerances (one kinematics
        pass, left for :meth:`jacobian`), else None. The joint limits are not applied here.

        Args:
            guess: Predicted configuration.
            position: Target tool position [m], 3 floats.
            rotation: Target tool rotation, 9 floats (row-major), or None (position only).
        """
        return guess if self.solver.accepts(guess, position, rotation, *self._tolerances2) else None

    def beyond_limit(self, q: np.ndarray) -> int | None:
        """Index of the joint furthest beyond its position limits at ``q``, or None."""
        over = np.maximum(self.robot.lower - q, q - self.robot.upper)
        j = int(np.argmax(over))
        return j if over[j] > 0.0 else None

    def limit_event(self, k, t, s, q: np.ndarray, j: int, position) -> Event:
        """The "joint_limit" event of joint ``j`` beyond its range at ``q``."""
        robot = self.robot
        name, unit = robot.joint_names[j], self.units[j]
        upper = q[j] > robot.upper[j]
        bound = robot.upper[j] if upper else robot.lower[j]
        return Event(
            "joint_limit", float(t), float(s), k,
            f"joint {name} would need {q[j]:.4f} {unit}, beyond its {'upper' if upper else 'lower'}"
            f" limit {bound:.4f} {unit}, to keep the tool on the path at {_where(position)}",
            position, name, float(q[j]), float(bound),
            remedy=f"start from a configuration with joint {name} further from that limit "
            "(another q_seed), or move the path",
        )  # fmt: skip

    def jacobian(self) -> np.ndarray:
        """Tool Jacobian (6, nq) at the last converged q (no new kinematics pass)."""
        J = pin.getFrameJacobian(self.model, self.data, self.fid, _LWA)
        return J.reshape(6, 1) if self._flat_jacobian else J

    def tool_position(self) -> tuple[float, float, float]:
        """Tool position [m] at the last converged q."""
        return self.solver.converged_position

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
            return manipulability_of(J, self.rank)
        if self._shape == 0:
            self._lu = eigenpy.PartialPivLU(J)
            return abs(self._lu.determinant())
        self._lu = eigenpy.PartialPivLU(J.dot(J.T) if self._shape < 0 else J.T.dot(J))
        return math.sqrt(max(self._lu.determinant(), 0.0))

    def rates(self, b: np.ndarray) -> np.ndarray:
        """J⁺ b for the last factored J: the solution (square), least squares (tall) or minimum
        norm (wide)."""
        J, lu, shape = self._J, self._lu, self._shape
        if lu is None:
            return np.linalg.pinv(J) @ b
        if shape == 0:
            return lu.solve(b)
        return lu.solve(b).dot(J) if shape < 0 else lu.solve(b.dot(J))

    def accelerations(
        self, q: np.ndarray, jacobians: np.ndarray, qd: np.ndarray, xdd: np.ndarray
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
            jacobians: Tool Jacobians (N, 6, nq) of the samples (:meth:`jacobian`).
            qd: Joint velocities (N, nq) [rad/s] there.
            xdd: Task accelerations (N, r): the tool origin's classical acceleration [m/s²] and
                the angular acceleration [rad/s²], in the task rows.
        """
        J_dot = self.robot.jacobian_time_variations(q, qd, jacobians)
        J = jacobians
        if not self._all_rows:
            J_dot, J = J_dot[:, self.rows], J[:, self.rows]
        pinv = _pseudo_inverses(J, self.rank)
        b = xdd - _matvec(J_dot, qd)
        if self.rank == J.shape[2]:  # full column rank: no null space
            return _matvec(pinv, b)
        z = _matvec(J_dot.transpose(0, 2, 1), _matvec(pinv.transpose(0, 2, 1), qd))
        return z + _matvec(pinv, b - _matvec(J, z))

    def check_sample(
        self, k, t, s, q, q_prev, qd_prev, h, xd, position, corrections: int
    ) -> tuple[Event | None, np.ndarray | None, float, np.ndarray | None]:
        """Check a solved sample k at ``q`` (kinematics at q in the solver's data): joint
        limits, singularity and, when Newton ``corrections`` moved it off its prediction, a
        jump relative to the previous sample.

        Args:
            q_prev, qd_prev: Previous sample's configuration and rates (None at k = 0).
            h: Time step from the previous sample [s].
            xd: Task velocity of the sample.

        Returns:
            (event or None, Jacobian (6, nq), manipulability, rates q̇); the last three are
            None / nan where the check stopped before computing them.
        """
        j = self.beyond_limit(q)
        if j is not None:
            return self.limit_event(k, t, s, q, j, position), None, math.nan, None
        J = self.jacobian()
        m = self.factor(J)
        if self.is_singular(m):
            return self.singular_event(k, t, s, m, position), J, m, None
        qd = self.rates(xd)
        event = None
        if corrections:  # an uncorrected prediction (q = guess) cannot jump
            event = self.jump_event(k, t, s, q, q_prev, qd, qd_prev, h, position)
        return event, J, m, qd

    def coarse_step_event(
        self, k, t, s, q, q_prev, qd, qd_prev, h, position, qs, qds
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

    def singular_event(self, k, t, s, m, position) -> Event | None:
        """A "singular" event when :meth:`is_singular` holds for the manipulability m."""
        if not self.is_singular(m):
            return None
        return Event(
            "singular", float(t), float(s), k,
            f"near a singularity at {_where(position)}: manipulability {m:.3g} is below "
            f"{max(self.singular_threshold, self.rank_floor):.3g}",
            position, value=m, limit=self.singular_threshold,
            remedy="keep the path away from the workspace boundary and from configurations "
            "with aligned joint axes",
        )  # fmt: skip

    def jump_event(
        self, k, t, s, q, q_prev, rate, rate_prev, h, position, continuous: bool = False
    ) -> Event | None:
        """A "jump" event when q moved more than its rates explain over the step h: a branch
        flip or, when a finer trace showed the path ``continuous`` there, a sampling too coarse
        for the motion."""
        if q_prev is None:
            return None
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
            "jump", float(t), float(s), k,
            f"joint {name} moves {q[j] - q_prev[j]:.4f} {unit} in {h:.3g} s at "
            f"{_where(position)}, {step[j]:.4f} {unit} more than its rates explain: {why}",
            position, name, float(q[j] - q_prev[j]), self.jump_tolerance, remedy=remedy,
        )  # fmt: skip

    def speed_event(self, k, t, s, ratios: np.ndarray, peak: float, position) -> Event:
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
            "velocity_limit", float(t), float(s), k,
            f"joint {name} would need {speed:.4g} {unit}/s, above its limit {limit:.4g} "
            f"{unit}/s{scaled}, at {_where(position)} (the motion needs up to {peak:.3g}× the "
            "joint speed limits)",
            position, name, speed, limit,
            remedy=f"slow the tool down by a factor of at least {peak:.3g} (a lower speed or a "
            "longer duration)",
        )  # fmt: skip

    def start(self, position, rotation, seed: np.ndarray) -> np.ndarray:
        """Configuration for the first point: full IK from ``seed`` (the seed's branch), or the
        seed itself when IK fails (the tracking step then diagnoses why)."""
        target = position if rotation is None else pin.SE3(rotation, position)
        first = self.robot.ik(
            target, q_seed=seed, position_only=rotation is None,
            position_tolerance=self.tolerance, rotation_tolerance=self.rotation_tolerance,
        )  # fmt: skip
        return first.q if first.success else seed

    def rescue(self, k, t, s, guess, q_prev, position, rotation) -> np.ndarray | Event:
        """Sample k after the short Newton pass from the prediction failed: a configuration
        found by a longer search (the caller checks it for limits and jumps), or the event that
        says why there is none: jump (reachable only on another branch) or unreachable."""
        robot = self.robot
        q, converged, *_ = self.solve(guess, position, rotation, iterations=60)
        if converged:
            return q
        target = position if rotation is None else pin.SE3(rotation, position)
        only = rotation is None
        where = _where(position)
        if q_prev is not None:
            res = robot.ik(
                target, q_seed=q_prev, position_only=only, position_tolerance=self.tolerance,
                rotation_tolerance=self.rotation_tolerance,
            )  # fmt: skip
            if res.success:
                j = int(np.argmax(np.abs(res.q - q_prev)))
                if abs(res.q[j] - q_prev[j]) <= self.jump_tolerance:
                    return res.q  # the same branch, found by the full solver
                name, unit = robot.joint_names[j], self.units[j]
                return Event(
                    "jump", t, s, k,
                    f"{where} is reachable only on another branch: joint {name} would jump "
                    f"from {q_prev[j]:.4f} to {res.q[j]:.4f} {unit}",
                    position, name, float(res.q[j] - q_prev[j]), self.jump_tolerance,
                    remedy="split the path there or start from another configuration (q_seed)",
                )  # fmt: skip
        res = robot.ik(target, q_seed=guess if q_prev is None else q_prev, position_only=only)
        if res.success:  # reachable within the limits, but not from where the arm is
            return Event(
                "jump", t, s, k,
                f"{where} is reachable only in another configuration than the arm's",
                position,
                remedy="start from another configuration (q_seed) or split the path there",
            )  # fmt: skip
        why = out_of_reach(robot, res, position)
        return Event(
            "unreachable", t, s, k, f"{where} is out of reach: {why}", position,
            value=res.position_error,
            remedy="shorten or move the path, or move the robot's base",
        )  # fmt: skip


def out_of_reach(robot: Robot, result, position: np.ndarray) -> str:
    """Why a target is out of reach, from an unsuccessful IK ``result``: the distance from the
    arm's first joint and its reach, or how close the best configuration came."""
    distance, reach = robot.shoulder_distance(position), robot.reach()
    annulus = robot.planar_reach()
    if distance > reach * (1 + 1e-12):
        return f"it is {distance:.4f} m from the arm's first joint, which reaches {reach:.4f} m"
    if annulus is not None and distance < annulus[0]:
        return (
            f"its distance to the first joint, {distance:.4f} m, is inside the hole "
            f"r < {annulus[0]:.4f} m that the arm cannot reach"
        )
    text = (
        f"within the arm's reach ({distance:.4f} m of {reach:.4f} m from its first joint), but the "
        f"closest tool pose within the joint limits is {result.position_error:.4f} m"
    )
    if result.rotation_error > 0:
        text += f" and {result.rotation_error:.3f} rad"
    return text + " away"


def joint_units(robot: Robot) -> list[str]:
    """Unit of each joint coordinate: "m" for prismatic joints, "rad" for the others."""
    units = ["rad"] * robot.nq
    for joint in robot.model.joints[1:]:
        if joint.nq == 1 and joint.shortname().startswith("JointModelP"):  # PX/PY/PZ/Unaligned
            units[joint.idx_q] = "m"
    return units


def _where(position: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4f}" for x in position) + ") m"


def _matvec(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A x for stacks of matrices (N, r, c) and vectors (N, c)."""
    return (A @ x[:, :, None])[:, :, 0]


def _pseudo_inverses(J: np.ndarray, rank: int) -> np.ndarray:
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
    return np.linalg.pinv(J)


def _adams_bashforth_weights(steps: np.ndarray) -> list[tuple[float, float]]:
    """Weights (a_k, b_k) of the two-step Adams–Bashforth prediction q_k ≈ q_(k−1) +
    a_k q̇_(k−1) + b_k q̇_(k−2), for steps h_k = t_k − t_(k−1) [s] (``steps`` are h_1, h_2, ...):
    q + h q̇ + (h²/2) q̈ with q̈ ≈ (q̇_(k−1) − q̇_(k−2)) / h_(k−1). Entry k of the list is for
    sample k (entries 0 and 1 are unused)."""
    h = np.concatenate([[np.nan, np.nan], steps[1:]])
    h_prev = np.concatenate([[np.nan, np.nan], steps[:-1]])
    ratio = 0.5 * h / h_prev
    return list(zip((h * (1.0 + ratio)).tolist(), (-h * ratio).tolist()))


def reference_manipulability(robot: Robot, position_only: bool) -> float:
    """Median manipulability over a fixed low-discrepancy set of configurations (cached)."""
    cache = robot.__dict__.setdefault("_reference_manipulability", {})
    if position_only not in cache:
        lower, upper = finite_bounds(robot.lower, robot.upper)
        values = [
            robot.manipulability(lower + (upper - lower) * halton(i, robot.nq), position_only)
            for i in range(1, 257)
        ]
        cache[position_only] = float(np.median(values))
    return cache[position_only]


def _resolve_position_only(robot: Robot, path: Path, position_only: bool | None) -> bool:
    if position_only is None:
        return robot.default_position_only() or not path.has_orientation
    if not position_only and not path.has_orientation:
        raise InputError("the path has no orientation (built from 3-vectors); use position_only")
    return bool(position_only)


@dataclass
class _Targets:
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


def _targets(path: Path, s: np.ndarray, position_only: bool, rows: np.ndarray) -> _Targets:
    """Evaluate the path at fractions ``s`` (vectorised): poses and their s-derivatives."""
    first, second = np.zeros((len(s), 6)), np.zeros((len(s), 6))
    first[:, :3], second[:, :3] = path.position_derivatives(s)
    rotations = None
    if not position_only:
        rotations = path.rotation(s)
        first[:, 3:], second[:, 3:] = path.angular_rates(s)
    return _Targets(path.position(s), rotations, first[:, rows], second[:, rows])


# ------------------------------------------------------------------------------------------
def follow(
    robot: Robot,
    path: Path,
    duration: float | None = None,
    speed: float | None = None,
    profile: str = "trapezoid",
    dt: float = 0.01,
    q_seed=None,
    position_only: bool | None = None,
    *,
    acceleration: float | None = None,
    singular_threshold: float | None = None,
    velocity_scale: float = 1.0,
    jump_tolerance: float = 0.05,
    tolerance: float = 1e-7,
    rotation_tolerance: float = 1e-7,
    retime: bool = False,
) -> CartesianPlan:
    """Plan the tool along ``path``: timed, IK at every sample, monitored.

    Args:
        robot: The arm.
        path: The Cartesian path (:class:`~cartesian.Line`, :class:`~cartesian.Arc`, ...).
        duration: Motion duration [s]; or
        speed: Tool cruise speed [m/s].
        profile: 1-D time law: "trapezoid" (default), "quintic" or "cubic".
        dt: Sampling period [s]; samples at 0, dt, ..., the last exactly at the end.
        q_seed: Start configuration guess (the IK of the path start stays on its branch).
        position_only: Ignore the tool orientation; default: when the arm has fewer than 6
            joints or the path was built from 3-vectors.
        acceleration: Tool acceleration of the trapezoid [m/s²] (default: cruise in 0.25 s).
        singular_threshold: Manipulability under which a sample is singular; default 5 % of
            the arm's median manipulability over its joint space.
        velocity_scale: Fraction of the robot's joint speed limits allowed.
        jump_tolerance: Largest joint step [rad] beyond what the joint velocities explain.
        tolerance: Tool position tolerance of every sample [m].
        rotation_tolerance: Tool rotation tolerance of every sample [rad].
        retime: Instead of stopping at a joint speed limit (near a singularity), slow the path
            parameter down where needed, keeping the exact path; ``duration`` becomes longer.

    Returns:
        CartesianPlan; an event stops it at the first offending sample.
    """
    _check_robot_and_path(robot, path)
    position_only = _resolve_position_only(robot, path, position_only)
    seed = robot.neutral() if q_seed is None else robot.check_q(q_seed, "q_seed")
    duration = checks.optional_number(duration, "duration", positive=True, unit="s")
    speed = checks.optional_number(speed, "speed", positive=True, unit="m/s")
    acceleration = checks.optional_number(acceleration, "acceleration", positive=True, unit="m/s²")
    profile = checks.choice(profile, "profile", PROFILES)
    dt = checks.number(dt, "dt", positive=True, unit="s")
    velocity_scale = checks.number(velocity_scale, "velocity_scale", positive=True)
    jump_tolerance = checks.number(jump_tolerance, "jump_tolerance", positive=True, unit="rad")
    tolerance = checks.number(tolerance, "tolerance", positive=True, unit="m")
    rotation_tolerance = checks.number(
        rotation_tolerance, "rotation_tolerance", positive=True, unit="rad"
    )
    retime = checks.flag(retime, "retime")
    if singular_threshold is None:
        singular_threshold = SINGULAR_FRACTION * reference_manipulability(robot, position_only)
    singular_threshold = checks.number(singular_threshold, "singular_threshold", minimum=0.0)
    tracker = _Tracker(
        robot, position_only, tolerance, rotation_tolerance, singular_threshold,
        velocity_scale, jump_tolerance,
    )  # fmt: skip
    timing = time_path(path.length, duration, speed, acceleration, profile, dt)
    if retime:
        return _retimed_plan(tracker, path, timing, seed, dt)
    plan = _track(tracker, path, timing, seed)
    if plan.status == "velocity_limit":
        # offer retiming only when it would pass: try it
        retimed = _retimed_plan(tracker, path, timing, seed, dt)
        if retimed.ok:
            plan.retime_duration = retimed.duration
            plan.events[0].remedy += (
                f", or retime (retime=True: the exact path in {retimed.duration:.3f} s instead "
                f"of {plan.duration:.3f} s)"
            )
    return plan


def _retimed_plan(
    tracker: _Tracker, path: Path, timing: PathTiming, seed: np.ndarray, dt: float
) -> CartesianPlan:
    """The plan of ``path`` with its time law slowed where a joint would be too fast (the
    nominal one when the geometric pass fails: the plan then reports that failure)."""
    s = np.linspace(0.0, 1.0, grid_points(path.length))
    geometry = trace_geometry(tracker, path, s, seed)
    new_timing = timing
    if not geometry.events:
        new_timing = retime_for_speed_limits(
            geometry.s, geometry.dq_ds, tracker.speed_limit, timing, dt
        )
    plan = _track(tracker, path, new_timing, seed)
    plan.retimed = new_timing is not timing
    return plan


def _check_robot_and_path(robot: object, path: object) -> None:
    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (from kinplan.load_robot), got {checks.describe(robot)}"
        )
    if not isinstance(path, Path):
        raise InputError(
            "path must be a cartesian path (cartesian.Line, Arc, Circle, Polyline, PathSequence, "
            f"FunctionPath), got {checks.describe(path)}"
        )


def _track(tracker: _Tracker, path: Path, timing: PathTiming, seed: np.ndarray) -> CartesianPlan:
    robot = tracker.robot
    position_only = tracker.position_only
    t, s, sd, sdd = timing.t, timing.s, timing.sd, timing.sdd
    n, nq = len(t), robot.nq

    targets = _targets(path, s, position_only, tracker.rows)
    positions, position_floats = targets.positions, targets.positions.tolist()
    if targets.rotations is None:
        rotations = rotation_floats = [None] * n
    else:
        rotations = list(targets.rotations)
        rotation_floats = targets.rotations.reshape(n, 9).tolist()
    xd = targets.rate * sd[:, None]  # task velocity ẋ = x' ṡ
    xdd = targets.curvature * (sd**2)[:, None] + targets.rate * sdd[:, None]  # x'' ṡ² + x' s̈

    # per sample: IK, Jacobian, manipulability, q̇ (for the next prediction); q̈ after the loop
    qs, qds, jacobians, tools, manips = [], [], [], [], []
    events: list[Event] = []
    q_prev = qd_prev = qd_before = None
    qdd_first = np.zeros(nq)  # q̈ at the first sample when it is at rest, for the second's guess
    steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]
    weights = _adams_bashforth_weights(np.diff(t))
    for k in range(n):
        if k == 0:
            guess = tracker.start(positions[0], rotations[0], seed)
        elif qd_before is None:  # second sample: Taylor, with q̈ = J⁺ẍ when starting at rest
            guess = q_prev + qd_prev * steps[k] + (0.5 * steps[k] ** 2) * qdd_first
        else:
            w_prev, w_before = weights[k]
            guess = q_prev + qd_prev * w_prev + qd_before * w_before
        # most predictions are within tolerance: one kinematics pass, else Newton steps
        q, corrections = tracker.accepts(guess, position_floats[k], rotation_floats[k]), 0
        if q is None:
            q, ok, _, _, corrections = tracker.solve(
                guess, positions[k], rotations[k], evaluated=True
            )
            if not ok:
                found = tracker.rescue(k, t[k], s[k], guess, q_prev, positions[k], rotations[k])
                if isinstance(found, Event):
                    events.append(found)
                    break
                q, corrections = found, 1
                tracker.accepts(q, position_floats[k], rotation_floats[k])  # kinematics at q
        event, J, m, qd = tracker.check_sample(
            k, t[k], s[k], q, q_prev, qd_prev, steps[k], xd[k], positions[k], corrections
        )
        if event is not None and k > 0 and event.kind in ("joint_limit", "jump"):
            # a limit or a branch flip, or only a step too coarse for a fast motion?
            found = _trace_between(tracker, path, s[k - 1], s[k], q_prev)
            if isinstance(found, Event):
                found.t, found.index = float(t[k]), k
                event = found
            elif found is not None:  # the continuous solution
                q = found
                tracker.accepts(q, position_floats[k], rotation_floats[k])  # kinematics at q
                event, J, m, qd = tracker.check_sample(
                    k, t[k], s[k], q, q_prev, qd_prev, steps[k], xd[k], positions[k], 1
                )
                if event is not None and event.kind == "jump":
                    event = tracker.coarse_step_event(
                        k, t, s[k], q, q_prev, qd, qd_prev, steps[k], positions[k], qs, qds
                    )
        if event is not None:
            events.append(event)
            break
        if k == 0 and not qd.any():
            qdd_first = tracker.rates(xdd[0])
        qs.append(q)
        qds.append(qd)
        jacobians.append(J)
        tools.append(tracker.tool_position())
        manips.append(m)
        q_prev, qd_prev, qd_before = q, qd, qd_prev

    done = len(qs)
    q_out = np.array(qs).reshape(done, nq)
    qd_out = np.array(qds).reshape(done, nq)
    # joint speeds are checked once, vectorised (rates and mean speeds between samples); a
    # sample too fast comes before any event the loop stopped at (those stop the loop at index
    # `done`), so it is the first event
    ratios = joint_speeds(q_out, qd_out, t[:done]) / tracker.speed_limit
    over = np.flatnonzero((ratios > 1.0).any(axis=1))
    peak = float(ratios.max(initial=0.0))
    if len(over):
        k = int(over[0])
        events = [tracker.speed_event(k, t[k], s[k], ratios[k], peak, positions[k])]
        done = k
    q_out, qd_out = q_out[:done], qd_out[:done]
    jacobian_stack = np.array(jacobians[:done]).reshape(done, 6, nq)
    qdd_out = tracker.accelerations(q_out, jacobian_stack, qd_out, xdd[:done])
    tool = np.array(tools[:done]).reshape(done, 3)
    manip = np.array(manips[:done])

    ok = not events
    deviation = np.linalg.norm(tool - positions[:done], axis=1)
    return CartesianPlan(
        t=t[:done].copy(),
        q=q_out,
        qd=qd_out,
        qdd=qdd_out,
        s=s[:done].copy(),
        ok=ok,
        status="ok" if ok else events[0].kind,
        peak_speed_ratio=peak,
        fraction=1.0 if ok else (float(s[done - 1]) if done else 0.0),
        events=events,
        max_deviation=float(deviation.max()) if done else 0.0,
        min_manipulability=float(manip.min()) if done else 0.0,
        duration=float(timing.duration),
        path=path,
        position_only=position_only,
        singular_threshold=float(tracker.singular_threshold),
        tool_positions=tool,
        manipulability=manip,
    )


#: Points of the finer trace that checks a jump between two samples.
JUMP_CHECK_POINTS = 17


def _trace_between(
    tracker: _Tracker, path: Path, s0: float, s1: float, q0: np.ndarray
) -> np.ndarray | Event | None:
    """Follow the path geometrically from ``q0`` at fraction ``s0`` to ``s1`` on a finer grid
    (bisected where a joint moves fast): what a sample that seems to jump really is.

    Returns:
        The configuration at s1 reached continuously (the sample's step was only too coarse
        for the motion: its speed is then checked like any other), the event that the finer
        trace meets on the way (a singularity, a joint limit, a branch flip), or None when it
        cannot be started from q0.
    """
    geometry = trace_geometry(tracker, path, np.linspace(s0, s1, JUMP_CHECK_POINTS), q0)
    if geometry.events:
        return geometry.events[0]
    if len(geometry.q) == 0 or np.max(np.abs(geometry.q[0] - q0)) > tracker.jump_tolerance:
        return None
    return geometry.q[-1]


# ------------------------------------------------------------------------------------------
def check_reachability(
    robot: Robot,
    path: Path,
    q_seed=None,
    position_only: bool | None = None,
    *,
    resolution: float = 0.005,
    singular_threshold: float | None = None,
) -> Reachability:
    """Fast pre-check: does the path stay in the workspace, continuously, away from singularities?

    Warm-started IK at points every ``resolution`` metres (at least 50 points, bisected where a
    joint moves more than 0.1 rad), reporting unreachable points, joint limits, branch jumps and
    singularities with the thresholds :func:`follow` uses, so the two agree. Planar arms first
    check their analytic workspace (the annulus r_min ≤ r ≤ r_max about the first joint, in its
    plane), which names the exact reason of an unreachable point. No timing, so no velocity
    check.

    Args:
        robot: The arm.
        path: The path.
        q_seed: Start configuration guess.
        position_only: As in :func:`follow`.
        resolution: Spacing of the checked points along the path [m].
        singular_threshold: As in :func:`follow`.
    """
    position_only = _resolve_position_only(robot, path, position_only)
    count = max(50, int(np.ceil(path.length / resolution)) + 1)
    s = np.linspace(0.0, 1.0, count)
    reach = robot.planar_reach()
    if reach is not None and position_only:
        annulus = _planar_check(robot, path, s, reach)
        if not annulus.ok:  # the analytic answer, with its exact reason
            return annulus
    seed = robot.neutral() if q_seed is None else robot.check_q(q_seed, "q_seed")
    if singular_threshold is None:
        singular_threshold = SINGULAR_FRACTION * reference_manipulability(robot, position_only)
    tracker = _Tracker(robot, position_only, 1e-7, 1e-7, singular_threshold, 1.0, 0.1)
    geometry = trace_geometry(tracker, path, s, seed)
    done = len(geometry.q)
    return Reachability(
        ok=not geometry.events,
        status=geometry.events[0].kind if geometry.events else "ok",
        fraction=1.0 if not geometry.events else (float(geometry.s[-1]) if done else 0.0),
        events=geometry.events,
        s=geometry.s,
        q=geometry.q,
    )


def _planar_check(robot: Robot, path: Path, s: np.ndarray, reach) -> Reachability:
    """Analytic check of a planar arm: annulus about the first joint, in its plane."""
    base = robot.model.jointPlacements[1]
    local = (path.position(s) - base.translation) @ base.rotation  # in the first joint's frame
    r = np.hypot(local[:, 0], local[:, 1])
    r_min, r_max = reach
    bad = (r < r_min - 1e-9) | (r > r_max + 1e-9) | (np.abs(local[:, 2]) > 1e-9)
    if not bad.any():
        return Reachability(True, "ok", 1.0, [], s, np.empty((0, robot.nq)))
    k = int(np.argmax(bad))
    position = path.position(s[k : k + 1])[0]
    if abs(local[k, 2]) > 1e-9:
        why = f"it is {local[k, 2]:.4f} m off the arm's plane"
    elif r[k] < r_min:
        why = f"its distance to the first joint, {r[k]:.4f} m, is inside the hole r < {r_min:.4f} m"
    else:
        why = f"its distance to the first joint, {r[k]:.4f} m, exceeds the reach {r_max:.4f} m"
    event = Event(
        "unreachable", 0.0, float(s[k]), k, f"{_where(position)} is out of reach: {why}", position,
        remedy="shorten or move the path, or move the robot's base",
    )  # fmt: skip
    fraction = float(s[k - 1]) if k else 0.0
    return Reachability(False, "unreachable", fraction, [event], s[:k], np.empty((0, robot.nq)))


@dataclass
class Geometry:
    """Joint solutions along the path up to the first event (for checks and retiming).

    Attributes:
        s: Path fractions solved (the requested ones plus refinements).
        q: Joint positions there, shape (len(s), nq).
        dq_ds: Geometric joint rates dq/ds there.
        events: The first event, if any.
    """

    s: np.ndarray
    q: np.ndarray
    dq_ds: np.ndarray
    events: list[Event]


#: Largest joint step [rad] between checked points before the interval is bisected.
MAX_JOINT_STEP = 0.1
#: Smallest interval in s that is still bisected.
MIN_REFINE_DS = 1e-7


def _points(tracker: _Tracker, path: Path, s: np.ndarray) -> list[tuple]:
    """(s, position, rotation or None, dx/ds) of each path fraction in ``s``."""
    targets = _targets(path, s, tracker.position_only, tracker.rows)
    rotations = [None] * len(s) if targets.rotations is None else list(targets.rotations)
    return list(zip(s.tolist(), targets.positions, rotations, targets.rate))


def trace_geometry(tracker: _Tracker, path: Path, s: np.ndarray, seed: np.ndarray) -> Geometry:
    """Warm-started IK at path fractions ``s`` with joint-limit/jump/singularity checks.

    Where a joint moves more than :data:`MAX_JOINT_STEP` between two points the interval is
    bisected, so a singularity or a branch flip between grid points is not stepped over. Also
    returns dq/ds = J⁺ dx/ds at every solved point.
    """
    robot = tracker.robot
    # A stack of (s, position, rotation, dx/ds): the next point to check is at the end.
    pending = _points(tracker, path, s)[::-1]
    solved_s: list[float] = []
    qs, dqs, events = [], [], []
    q_prev = None
    while pending:
        sk, position, rotation, dx = pending[-1]
        k = len(qs)
        if q_prev is None:
            guess = tracker.start(position, rotation, seed)
        else:
            guess = q_prev + dqs[-1] * (sk - solved_s[-1])
        q, ok, *_ = tracker.solve(guess, position, rotation)
        if q_prev is not None and sk - solved_s[-1] > MIN_REFINE_DS:
            if not ok or np.max(np.abs(q - q_prev)) > MAX_JOINT_STEP:
                pending += _points(tracker, path, np.array([0.5 * (sk + solved_s[-1])]))
                continue
        if not ok:
            found = tracker.rescue(k, 0.0, sk, guess, q_prev, position, rotation)
            if isinstance(found, Event):
                events.append(found)
                break
            q = found
            tracker.accepts(
                q, position.tolist(), None if rotation is None else rotation.reshape(9).tolist()
            )
        j = tracker.beyond_limit(q)
        if j is not None:
            events.append(tracker.limit_event(k, 0.0, sk, q, j, position))
            break
        m = tracker.factor(tracker.jacobian())
        event = tracker.singular_event(k, 0.0, sk, m, position)
        dq = None
        if event is None:
            dq = tracker.rates(dx)
            h = sk - solved_s[-1] if solved_s else 0.0
            rate_prev = dqs[-1] if dqs else None
            event = tracker.jump_event(k, 0.0, sk, q, q_prev, dq, rate_prev, h, position)
        if event is not None:
            events.append(event)
            break
        pending.pop()
        solved_s.append(sk)
        qs.append(q)
        dqs.append(dq)
        q_prev = q
    nq = robot.nq
    return Geometry(
        np.array(solved_s), np.array(qs).reshape(-1, nq), np.array(dqs).reshape(-1, nq), events
    )
