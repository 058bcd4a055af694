"""Numerical inverse kinematics on Pinocchio: Levenberg–Marquardt with adaptive damping.

The solver minimises the tool-pose error e = [p* − p; log(R* Rᵀ)] (world-aligned, at the tip)
with steps (JᵀJ + λI) Δq = Jᵀe, where λ = ½‖e‖² + λ₀ (Sugihara's error-dependent damping):
Gauss–Newton close to the solution (quadratic convergence), gradient-like far from it and near
singularities. Every iterate is kept within the joint limits: a revolute joint that a step
takes beyond a limit is turned by whole turns into them where it fits (the same tool pose:
limits of ±π would otherwise stop an attempt that has to cross ±π), at most
:data:`TURNS_PER_ATTEMPT` times a joint an attempt, else clamped. One Pinocchio pass
(``computeJointJacobians``) per iteration gives both the tool pose and its Jacobian; the 6×6 (or
nq×nq) system is solved by a Cholesky factorisation.

When the attempt from the seed fails, the solver restarts from configurations of a Halton
sequence spread over the joint limits (deterministic: the same input gives the same answer).
When every attempt fails, the best one is polished with undamped steps (a near-singular target
converges slowly under the damping), and a solution found ignoring the limits is tried with its
revolute joints turned by whole turns into them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import eigenpy
import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.errors import InputError
from kinplan.ik.base import AnalyticIK
from kinplan.ik.screws import TAU

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
#: Damping λ = DAMPING_GAIN·½‖e‖² + DAMPING_FLOOR of the normal equations (Sugihara-style).
DAMPING_GAIN = 1e-3
DAMPING_FLOOR = 1e-6
#: Largest joint step of one iteration [rad or m].
MAX_STEP = 1.0
#: Iterations without a 0.1 % decrease of the error before an attempt is abandoned.
STALL_ITERATIONS = 5
#: How often an attempt may turn one joint by whole turns into its limits (see
#: :meth:`IKSolver.descend`'s ``turn``): across ±π and back. Unlimited turns let an optimum that
#: sits on a limit at ±π (a planar arm's folded elbow, the point nearest a target in the hole)
#: swing across it: the best attempt stopped 0.039 m short of it, clamped on the third crossing
#: it ends 2e-8 m from it. More turns save few iterations (on skewed_axes's ±π joints: mean 38
#: iterations a solve with one, 24 with two, 22 with three, 20 unlimited).
TURNS_PER_ATTEMPT = 2
#: Damping floor and patience of the polish that ends a failed solve (see
#: :meth:`IKSolver.solve`): Gauss–Newton steps finish what the damped ones leave near a
#: singularity, where a floor of DAMPING_FLOOR makes them crawl.
POLISH_DAMPING_FLOOR = 1e-12
POLISH_STALL_ITERATIONS = 20
#: The polish and the solve without limits may take this many times ``max_iterations`` each.
POLISH_ITERATIONS = 2
#: Most iterations of one attempt (``max_iterations``) and most restarts (``max_restarts``).
MAX_ITERATIONS = 10_000
MAX_RESTARTS = 10_000
#: Most iterations one solve may take: (max_restarts + 1) attempts, then (with restarts) the
#: polish and the solve without limits (:data:`POLISH_ITERATIONS` × max_iterations each) and a
#: last polish (max_iterations), i.e. (max_restarts + 2 + 2·POLISH_ITERATIONS) ×
#: max_iterations, or max_iterations without restarts. The defaults (40 and 40) take at most
#: 1,840; this bound keeps one solve within seconds.
MAX_SOLVE_ITERATIONS = 50_000
_SQRT8 = math.sqrt(8.0)
_PRIMES = (2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71)


@dataclass
class IKResult:
    """Outcome of an inverse-kinematics solve.

    Attributes:
        q: Best joint configuration found [rad or m], within the joint limits.
        success: Whether both errors are within the requested tolerances.
        position_error: Tool position error ‖p* − p(q)‖ [m].
        rotation_error: Tool rotation error, the angle of R* R(q)ᵀ [rad] (0 for position-only).
        iterations: Solver iterations over all attempts.
        attempts: Number of starts (1 = the seed; more = random restarts were needed).
        method: "numerical" or "analytic" (the closed form of a planar 2R, a UR arm or a
            panda-type arm).
    """

    q: np.ndarray
    success: bool
    position_error: float
    rotation_error: float
    iterations: int
    attempts: int = 1
    method: str = "numerical"


class Evaluation(NamedTuple):
    """The tool at one configuration against a target: what one kinematics pass gives.

    Returned by :meth:`IKSolver.evaluate` (and with the result of :meth:`IKSolver.descend`), so
    a caller reads the Jacobian and the tool position of the configuration it asked about,
    not whatever the solver computed last.

    Attributes:
        q: The configuration [rad or m], shape (nq,).
        tool_position: Tool position [m], 3 floats (world frame).
        differences: The target minus the tool pose: (Δx, Δy, Δz [m], ‖R* − R‖_F²), the last
            0 for a position-only target (:func:`_pose_differences`).
        jacobian: Tool Jacobian (6, nq) at q, in the world-aligned frame at the tool
            (``LOCAL_WORLD_ALIGNED``: linear rows of the tool origin, then angular rows).
        tool_pose: The tool pose as the rows of its 4×4 homogeneous matrix (plain floats:
            cheaper than an array on the hot path; ``np.array(tool_pose)`` gives the matrix).
    """

    q: np.ndarray
    tool_position: tuple[float, float, float]
    differences: tuple[float, float, float, float]
    jacobian: np.ndarray
    tool_pose: list[list[float]]

    def within(self, position_tolerance2: float, frobenius_tolerance2: float) -> bool:
        """Whether the tool meets the tolerances: squared position [m²] and ‖R* − R‖_F²
        (:func:`frobenius_tolerance`)."""
        dx, dy, dz, frobenius2 = self.differences
        return dx * dx + dy * dy + dz * dz <= position_tolerance2 and (
            frobenius2 <= frobenius_tolerance2
        )


def _pose_differences(
    rows: list[list[float]], position: list[float], rotation: list[float] | None
) -> tuple[float, float, float, float]:
    """The target minus the tool pose, in plain floats (a handful of numpy calls on
    3-vectors would cost more than the kinematics pass that gave the pose).

    Args:
        rows: Tool pose: the rows of its homogeneous matrix.
        position: Target position [m], 3 floats.
        rotation: Target rotation, 9 floats (row-major), or None (position only).

    Returns:
        (Δx, Δy, Δz [m], ‖R* − R‖_F²), the last 0 for position only. For a rotation error of
        angle θ, ‖R* − R‖_F² = 8 sin²(θ/2) (see :func:`_angle_of`).
    """
    (a0, a1, a2, x), (a3, a4, a5, y), (a6, a7, a8, z), _ = rows
    px, py, pz = position
    if rotation is None:
        return px - x, py - y, pz - z, 0.0
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = rotation
    squares = (b0 - a0) ** 2 + (b1 - a1) ** 2 + (b2 - a2) ** 2 + (b3 - a3) ** 2
    squares += (b4 - a4) ** 2 + (b5 - a5) ** 2 + (b6 - a6) ** 2 + (b7 - a7) ** 2
    return px - x, py - y, pz - z, squares + (b8 - a8) ** 2


def _angle_of(frobenius2: float) -> float:
    """The angle θ [rad] of a rotation error from ‖R* − R‖_F² = 8 sin²(θ/2): as precise as the
    matrices for small angles, unlike the trace's arccos."""
    return 2.0 * math.asin(min(math.sqrt(frobenius2) / _SQRT8, 1.0))


def frobenius_tolerance(rotation_tolerance: float) -> float:
    """‖R* − R‖_F² of a rotation error of ``rotation_tolerance`` [rad]: 8 sin²(θ/2), the rotation
    test of :meth:`Evaluation.within` in plain floats.

    Raises:
        InputError: ``rotation_tolerance`` not a finite number ≥ 0.
    """
    if type(rotation_tolerance) is not float or not 0.0 <= rotation_tolerance < math.inf:
        rotation_tolerance = checks.number(
            rotation_tolerance, "rotation_tolerance", minimum=0.0, unit="rad"
        )
    return 8.0 * math.sin(0.5 * min(rotation_tolerance, math.pi)) ** 2


def finite_bounds(lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Limits to sample configurations from [rad or m]: unbounded (continuous) joints span
    [−π, π]."""
    return np.where(np.isfinite(lower), lower, -math.pi), np.where(
        np.isfinite(upper), upper, math.pi
    )


def halton(index: int, dim: int) -> np.ndarray:
    """Point ``index`` (≥ 1) of the Halton low-discrepancy sequence in [0, 1)^dim.

    Raises:
        InputError: ``index`` not an integer ≥ 1 or ``dim`` not an integer in [1, 1000].
    """
    index = checks.count(index, "index", minimum=1)
    dim = checks.count(dim, "dim", minimum=1)
    if dim > 1000:
        raise InputError(f"dim must be an integer in [1, 1000] (one per joint), got {dim}")
    out = np.empty(dim)
    for k in range(dim):
        base = _PRIMES[k % len(_PRIMES)]
        f, r, i = 1.0, 0.0, index
        while i > 0:
            f /= base
            r += f * (i % base)
            i //= base
        out[k] = r
    return out


def check_effort(max_iterations: int, max_restarts: int) -> None:
    """Refuse iteration counts that would let one solve run for minutes.

    Args:
        max_iterations: Iterations per attempt (an int ≥ 1, already checked).
        max_restarts: Restarts after the seeded attempt (an int ≥ 0, already checked).

    Raises:
        InputError: ``max_iterations`` above :data:`MAX_ITERATIONS`, ``max_restarts`` above
            :data:`MAX_RESTARTS`, or together more than :data:`MAX_SOLVE_ITERATIONS`
            iterations per solve; the message says what fits.
    """
    if max_iterations > MAX_ITERATIONS:
        raise InputError(
            f"max_iterations must be at most {MAX_ITERATIONS:,} iterations per attempt (the "
            f"default 40 converges or stalls well before), got {max_iterations:,}"
        )
    if max_restarts > MAX_RESTARTS:
        raise InputError(
            f"max_restarts must be at most {MAX_RESTARTS:,} (the default is 40), got "
            f"{max_restarts:,}"
        )
    extra = 2 + 2 * POLISH_ITERATIONS  # the seed's attempt, the rescue (polish, no limits, polish)
    rounds = max_restarts + extra if max_restarts > 0 else 1  # 0 restarts: no rescue either
    if rounds * max_iterations > MAX_SOLVE_ITERATIONS:
        restarts = MAX_SOLVE_ITERATIONS // max_iterations - extra
        raise InputError(
            f"max_iterations {max_iterations:,} with max_restarts {max_restarts:,} would allow "
            f"{rounds * max_iterations:,} iterations per solve (({max_restarts:,} + {extra}) × "
            f"{max_iterations:,}; at most {MAX_SOLVE_ITERATIONS:,}); use max_iterations ≤ "
            f"{MAX_SOLVE_ITERATIONS // rounds:,} or max_restarts ≤ {max(restarts, 0):,}"
        )


class IKSolver:
    """Damped least-squares IK for one tool frame of a Pinocchio model.

    Owns its own ``pin.Data`` and reuses it for every solve.

    Args:
        model: The (reduced, serial) Pinocchio model.
        frame_id: Tool frame index in ``model``.
        lower: Lower joint limits [rad or m] (−inf for an unbounded joint).
        upper: Upper joint limits [rad or m] (+inf for an unbounded joint).
    """

    def __init__(
        self, model: pin.Model, frame_id: int, lower: np.ndarray, upper: np.ndarray
    ) -> None:
        if not isinstance(model, pin.Model):
            raise InputError(f"model must be a pinocchio.Model, got {checks.describe(model)}")
        frame_id = checks.count(frame_id, "frame_id", minimum=0)
        if frame_id >= model.nframes:
            raise InputError(f"frame_id must be a frame index < {model.nframes}, got {frame_id}")
        lower = checks.vector(lower, "lower", model.nq, "rad or m", infinite=True)
        upper = checks.vector(upper, "upper", model.nq, "rad or m", infinite=True)
        if np.any(lower > upper) or np.any(lower == np.inf) or np.any(upper == -np.inf):
            raise InputError(f"every lower limit must be ≤ its upper limit: {lower} vs {upper}")
        self.model = model
        self.data = model.createData()
        self.frame_id = frame_id
        self.lower = lower
        self.upper = upper
        self.nq = model.nq
        self._diagonal = np.diag_indices(model.nq)
        self._revolute = np.zeros(model.nq, dtype=bool)  # joints that a whole turn leaves alike
        for j in range(1, model.njoints):
            joint = model.joints[j]
            if joint.nq == 1 and joint.shortname().startswith("JointModelR"):
                self._revolute[joint.idx_q] = True
        self._no_lower = np.full(model.nq, -np.inf)
        self._no_upper = np.full(model.nq, np.inf)
        self._restarts: np.ndarray = np.empty((0, model.nq))
        #: The compiled solve: None until first needed, then (module, screws, tool) or False.
        self._kernel: tuple[Any, np.ndarray, np.ndarray] | bool | None = None
        self._limits = np.ascontiguousarray(np.vstack([lower, upper]))
        #: The compiled solve's settings (:meth:`_kernel_inputs`) and the arguments they are for.
        self._settings: tuple[tuple[float, float, int] | None, np.ndarray] = (None, np.empty(0))
        #: Which solver :meth:`kinplan.Robot.ik` uses for this arm: a closed form, or numerical and
        #: why no closed form fits (set by the robot when it looks for one).
        self.description = "numerical (Levenberg–Marquardt)"

    def restart_configuration(self, attempt: int) -> np.ndarray:
        """Start of restart ``attempt`` (≥ 1): a Halton point spread over the joint limits."""
        if attempt > len(self._restarts):
            count = max(2 * attempt, 64)
            unit = np.array([halton(i, self.nq) for i in range(1, count + 1)])
            low, high = finite_bounds(self.lower, self.upper)
            self._restarts = low + (high - low) * unit
        return self._restarts[attempt - 1]

    def errors(
        self, q: np.ndarray, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[float, float]:
        """Position error [m] and rotation error [rad] (see :func:`_angle_of`) of the tool at
        ``q`` (one FK pass)."""
        pin.forwardKinematics(self.model, self.data, q)
        pose = pin.updateFramePlacement(self.model, self.data, self.frame_id)
        target_rotation = None if rotation is None else rotation.reshape(9).tolist()
        dx, dy, dz, frobenius2 = _pose_differences(
            pose.homogeneous.tolist(), position.tolist(), target_rotation
        )
        return math.sqrt(dx * dx + dy * dy + dz * dz), _angle_of(frobenius2)

    def evaluate(
        self, q: np.ndarray, position: list[float], rotation: list[float] | None
    ) -> Evaluation:
        """The tool at ``q`` against a target: one kinematics pass (joint Jacobians included).

        Args:
            q: Configuration [rad or m], shape (nq,).
            position: Target tool position [m], 3 floats.
            rotation: Target tool rotation, 9 floats (row-major), or None (position only).
        """
        pin.computeJointJacobians(self.model, self.data, q)
        rows = pin.updateFramePlacement(self.model, self.data, self.frame_id).homogeneous.tolist()
        jacobian = pin.getFrameJacobian(self.model, self.data, self.frame_id, _LWA)
        if self.nq == 1:  # eigenpy gives a 1-D array for one column
            jacobian = jacobian.reshape(6, 1)
        tool = (rows[0][3], rows[1][3], rows[2][3])
        return Evaluation(q, tool, _pose_differences(rows, position, rotation), jacobian, rows)

    def descend(
        self,
        q: np.ndarray,
        position: np.ndarray,
        rotation: np.ndarray | None,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        clamp: bool = True,
        evaluated: Evaluation | None = None,
        *,
        damping_floor: float | None = None,
        stall_iterations: int | None = None,
        turn: bool = False,
    ) -> tuple[np.ndarray, bool, float, float, int, Evaluation]:
        """Iterate from ``q`` (not modified) until converged, stalled or out of iterations.

        Args:
            clamp: Keep every iterate within the joint limits (False: ignore the limits, to tell
                a limit problem from an unreachable target).
            evaluated: The caller's :meth:`evaluate` of this target at ``q`` (within the limits
                applied here), which did not meet the tolerances: the first iterate reuses it.
            damping_floor: λ₀ of the damping (default :data:`DAMPING_FLOOR`).
            stall_iterations: Iterations without progress before giving up (default
                :data:`STALL_ITERATIONS`).
            turn: With ``clamp``, a revolute joint that a step takes beyond a limit is first
                turned by whole turns into the limits (the same tool pose) when that lands
                inside them, at most :data:`TURNS_PER_ATTEMPT` times; otherwise it is clamped.
                What an IK solve does (an attempt is not a path); a path follower keeps False.

        Returns:
            (q, converged, position_error [m], rotation_error [rad], iterations, the
            evaluation at the returned q)
        """
        lower, upper = (self.lower, self.upper) if clamp else (self._no_lower, self._no_upper)
        q = np.minimum(np.maximum(q, lower), upper)
        touching = True  # whether q may sit on a limit (then the active set is checked)
        turns = np.zeros(self.nq, dtype=int)  # of each joint into the limits (turn)
        rows = 3 if rotation is None else 6
        diagonal = self._diagonal
        e = None  # the error vector, made when a step is needed
        position_tolerance2 = position_tolerance * position_tolerance
        frobenius_tolerance2 = frobenius_tolerance(rotation_tolerance)
        target_position = position.tolist()
        target_rotation = None if rotation is None else rotation.reshape(9).tolist()
        best_cost = np.inf
        stalled = 0
        floor = DAMPING_FLOOR if damping_floor is None else damping_floor
        patience = STALL_ITERATIONS if stall_iterations is None else stall_iterations
        perr2 = rerr2 = np.inf
        for it in range(max_iterations + 1):
            if it == 0 and evaluated is not None:
                evaluation = evaluated
            else:
                evaluation = self.evaluate(q, target_position, target_rotation)
            dx, dy, dz, frobenius2 = evaluation.differences
            perr2 = dx * dx + dy * dy + dz * dz
            if perr2 <= position_tolerance2 and frobenius2 <= frobenius_tolerance2:
                return q, True, math.sqrt(perr2), _angle_of(frobenius2), it, evaluation
            if e is None:
                e = np.zeros(6)
            e[:3] = (dx, dy, dz)
            if rotation is not None:
                tool_rotation = np.array(evaluation.tool_pose)[:3, :3]
                er = pin.log3(rotation @ tool_rotation.T)
                e[3:] = er
                rerr2 = float(er.dot(er))
            else:
                rerr2 = 0.0
            if it == max_iterations:
                break
            cost = 0.5 * (perr2 + rerr2)
            if cost < 0.999 * best_cost:
                best_cost, stalled = cost, 0
            else:
                stalled += 1
                if stalled >= patience:
                    break
            J = evaluation.jacobian[:rows]
            A = J.T.dot(J)
            A[diagonal] += DAMPING_GAIN * cost + floor
            g = e[:rows].dot(J)
            dq = eigenpy.LLT(A).solve(g)
            if touching:
                # Joints at a limit that the step pushes outwards leave the step (active
                # set): their rows and columns become identity, their gradient zero.
                blocked = ((q <= lower) & (dq < 0)) | ((q >= upper) & (dq > 0))
                if blocked.any():
                    free = (~blocked).astype(float)
                    A *= np.multiply.outer(free, free)
                    A[diagonal] += blocked
                    dq = eigenpy.LLT(A).solve(g * free)
            step = abs(dq).max()
            if step > MAX_STEP:
                dq *= MAX_STEP / step
            free_q = q + dq
            if turn and clamp:
                free_q, turns = self._turned(free_q, turns)
            q = np.minimum(np.maximum(free_q, lower), upper)
            touching = bool((q != free_q).any())
        return q, False, math.sqrt(perr2), math.sqrt(rerr2), it, evaluation

    def _turned(self, q: np.ndarray, turns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``q`` with each revolute joint beyond a limit, turned fewer than
        :data:`TURNS_PER_ATTEMPT` times so far (``turns``), turned by whole turns into the
        limits where that lands inside them (see :meth:`descend`'s ``turn``); and ``turns``
        counting those."""
        beyond = self._revolute & (turns < TURNS_PER_ATTEMPT)
        beyond &= (q < self.lower) | (q > self.upper)  # never for an unbounded joint
        if not beyond.any():
            return q, turns
        lower = np.where(beyond, self.lower, 0.0)  # no inf - inf for the others
        turned = lower + np.mod(q - lower, TAU)
        beyond &= turned <= self.upper
        return np.where(beyond, turned, q), turns + beyond

    def solve(
        self,
        position: np.ndarray,
        rotation: np.ndarray | None,
        q_seed: np.ndarray,
        position_tolerance: float = 1e-6,
        rotation_tolerance: float = 1e-6,
        max_iterations: int = 40,
        max_restarts: int = 40,
        closed_form: AnalyticIK | None = None,
    ) -> IKResult:
        """Solve from ``q_seed``, then from Halton restarts until one attempt converges.

        When none does (and restarts are allowed), the best attempt is polished
        (:data:`POLISH_DAMPING_FLOOR`), then the seed's attempt is repeated ignoring the limits:
        a solution whose revolute joints come within the limits by whole turns is taken
        (polished there). Either counts as one more attempt.

        With a ``closed_form`` solver (see :mod:`kinplan.ik.closed_form`), its solution nearest the
        seed comes first; the numerical attempts only run when it has none within the limits
        (then they return the closest configuration they find, ``success=False``).

        Args:
            position: Target tool position in the world frame [m].
            rotation: Target tool rotation (3×3) in the world frame, or ``None``: position only.
            q_seed: Start configuration.
            position_tolerance: Accepted position error [m].
            rotation_tolerance: Accepted rotation error [rad].
            max_iterations: Iterations per attempt, at most :data:`MAX_ITERATIONS`.
            max_restarts: Restarts after the seeded attempt fails, at most
                :data:`MAX_RESTARTS`.
            closed_form: Optional closed-form solver with ``nearest(position, rotation, q)``.

        Raises:
            InputError: a target or seed of the wrong size or not finite, a rotation that is
                not 3×3, tolerances that are not finite numbers > 0, ``max_iterations`` not an
                integer from 1 to :data:`MAX_ITERATIONS`, ``max_restarts`` not an integer from 0
                to :data:`MAX_RESTARTS`, or together more than :data:`MAX_SOLVE_ITERATIONS`
                iterations per solve (:func:`check_effort`).
        """
        position = checks.vector(position, "position", 3, "m")
        if rotation is not None:
            rotation = checks.matrix(rotation, "rotation", (3, 3))
        q_seed = checks.vector(q_seed, "q_seed", self.nq, "rad or m")
        position_tolerance = checks.number(
            position_tolerance, "position_tolerance", positive=True, unit="m"
        )
        rotation_tolerance = checks.number(
            rotation_tolerance, "rotation_tolerance", positive=True, unit="rad"
        )
        max_iterations = checks.count(max_iterations, "max_iterations", minimum=1)
        max_restarts = checks.count(max_restarts, "max_restarts", minimum=0)
        return self.solve_checked(
            position,
            rotation,
            q_seed,
            position_tolerance,
            rotation_tolerance,
            max_iterations,
            max_restarts,
            closed_form,
        )

    def solve_checked(
        self,
        position: np.ndarray,
        rotation: np.ndarray | None,
        q_seed: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
        closed_form: AnalyticIK | None = None,
    ) -> IKResult:
        """:meth:`solve` for arguments already checked (float arrays of the right shapes, finite;
        tolerances finite floats > 0; counts ints in range): what :meth:`kinplan.Robot.ik`
        calls after its own checks, so a single IK does not pay for them twice.

        Raises:
            InputError: counts beyond :func:`check_effort`'s bounds.
        """
        if max_iterations > 40 or max_restarts > 40:  # the defaults need no check
            check_effort(max_iterations, max_restarts)
        best: tuple[float, np.ndarray, float, float] | None = None
        total = 0
        if closed_form is not None:
            # The closed form gives the solution nearest the seed at once (polished by Newton).
            q = closed_form.nearest(position, rotation, q_seed)
            if q is not None:
                perr, rerr = self.errors(q, position, rotation)
                its = 0
                if perr > position_tolerance or rerr > rotation_tolerance:
                    q, _, perr, rerr, its, _ = self.descend(
                        q, position, rotation, position_tolerance, rotation_tolerance, 3
                    )
                if perr <= position_tolerance and rerr <= rotation_tolerance:
                    return IKResult(q, True, perr, rerr, its, 1, "analytic")
        compiled = self._compiled_solve(
            position, rotation, q_seed, position_tolerance, rotation_tolerance,
            max_iterations, max_restarts,
        )  # fmt: skip
        if compiled is not None:
            return compiled
        for attempt in range(max_restarts + 1):
            start = q_seed if attempt == 0 else self.restart_configuration(attempt)
            q, ok, perr, rerr, its, _ = self.descend(
                start, position, rotation, position_tolerance, rotation_tolerance,
                max_iterations, turn=True,
            )  # fmt: skip
            total += its
            score = perr + rerr
            if best is None or score < best[0]:
                best = (score, q, perr, rerr)
            if ok:
                return IKResult(q, True, perr, rerr, total, attempt + 1)
        assert best is not None  # the loop runs at least once (max_restarts ≥ 0)
        _, q, perr, rerr = best
        tolerances = (position_tolerance, rotation_tolerance)
        rescued = None
        if max_restarts > 0:  # 0: the seed's attempt only
            rescued = self._rescue(q, q_seed, position, rotation, tolerances, max_iterations)
        if rescued is not None:
            q, perr, rerr, its = rescued
            return IKResult(q, True, perr, rerr, total + its, max_restarts + 2)
        return IKResult(q, False, perr, rerr, total, max_restarts + 1)

    def _compiled_solve(
        self,
        position: np.ndarray,
        rotation: np.ndarray | None,
        q_seed: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
    ) -> IKResult | None:
        """The whole solve compiled (:mod:`kinplan.ik.numeric_kernel`) for serial revolute
        arms: the seeded attempt, the restarts and the rescue, with the errors of the answer
        measured by Pinocchio; None without numba and for other arms (the Python loop then
        runs), and when Pinocchio and the kernel disagree about convergence at the tolerance's
        last digits (the Python loop decides then)."""
        inputs = self._kernel_inputs(
            position_tolerance, rotation_tolerance, max_iterations, max_restarts
        )
        if inputs is None:
            return None
        kernel, screws, tool, settings, restarts = inputs
        target = np.eye(4)
        target[:3, 3] = position
        if rotation is not None:
            target[:3, :3] = rotation
        q = np.empty(self.nq)
        ok, attempts, its, _, _ = kernel.solve(
            np.asarray(q_seed, dtype=float), target, rotation is not None, self._limits, screws,
            tool, settings, restarts, True, q,
        )  # fmt: skip
        perr, rerr = self.errors(q, position, rotation)
        if ok != (perr <= position_tolerance and rerr <= rotation_tolerance):
            return None
        return IKResult(q, ok, perr, rerr, its, attempts)

    def _kernel_inputs(
        self,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """(kernel module, screws, tool pose at q = 0, settings (4, 8), restart configurations)
        of the compiled solve (:mod:`kinplan.ik.numeric_kernel`), or None without numba and for
        arms other than serial chains of revolute joints."""
        if self._kernel is None:
            from kinplan.ik import numeric_kernel  # numba loads on first use

            found = numeric_kernel.screw_constants(self.model, self.frame_id)
            self._kernel = (numeric_kernel, *found) if found is not None else False
        if not isinstance(self._kernel, tuple):
            return None
        kernel, screws, tool = self._kernel
        key = (position_tolerance, rotation_tolerance, max_iterations)
        if self._settings[0] != key:  # made again only when the arguments change
            tolerances = (position_tolerance**2, frobenius_tolerance(rotation_tolerance))
            long = POLISH_ITERATIONS * max_iterations
            # rows: the attempts, the polish of the best, the attempt without limits, its
            # polish (the Python loop's descend arguments for each: solve_checked, _rescue);
            # columns: tolerances, iterations, damping gain and floor, patience, step, turns
            made = np.array(
                [
                    [max_iterations, DAMPING_FLOOR, STALL_ITERATIONS],
                    [long, POLISH_DAMPING_FLOOR, POLISH_STALL_ITERATIONS],
                    [long, DAMPING_FLOOR, STALL_ITERATIONS],
                    [max_iterations, POLISH_DAMPING_FLOOR, POLISH_STALL_ITERATIONS],
                ],
                dtype=float,
            )
            settings = np.empty((4, 8))
            settings[:, :2] = tolerances
            settings[:, 2], settings[:, 3] = made[:, 0], DAMPING_GAIN
            settings[:, 4], settings[:, 5] = made[:, 1], made[:, 2]
            settings[:, 6], settings[:, 7] = MAX_STEP, TURNS_PER_ATTEMPT
            self._settings = (key, settings)
        settings = self._settings[1]
        if max_restarts > 0:
            self.restart_configuration(max_restarts)  # the Halton starts, made once
        return kernel, screws, tool, settings, self._restarts[:max_restarts]

    @property
    def compiled(self) -> bool:
        """Whether solves run compiled (:mod:`kinplan.ik.numeric_kernel`: numba, a serial
        chain of revolute joints)."""
        return self._kernel_inputs(1e-6, 1e-6, 1, 0) is not None

    def compiled_solve_many(
        self,
        positions: np.ndarray,
        rotations: np.ndarray | None,
        seeds: np.ndarray,
        position_tolerance: float,
        rotation_tolerance: float,
        max_iterations: int,
        max_restarts: int,
        rescue: bool = True,
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The compiled solve of :meth:`_compiled_solve` for many targets (inputs checked and
        finite): the seeded attempt, the restarts and the rescue of each, as :meth:`solve`
        runs them for one target. What ``Robot.ik_batch`` runs for arms without a closed form.

        Args:
            positions: Tool positions in the base frame [m], shape (N, 3).
            rotations: Tool rotations, shape (N, 3, 3), or None (position only).
            seeds: Start configurations [rad], shape (N, nq).
            position_tolerance, rotation_tolerance: Convergence thresholds [m], [rad].
            max_iterations, max_restarts: As :meth:`solve`.
            rescue: Whether targets every attempt failed get the rescue (as :meth:`solve`).

        Returns:
            (q (N, nq) [rad]: the converged configuration, else the best attempt;
            converged (N,) bool, by the kernel's kinematics, which agree with Pinocchio to
            1e-12), or None when the compiled solve is not available.
        """
        inputs = self._kernel_inputs(
            position_tolerance, rotation_tolerance, max_iterations, max_restarts
        )
        if inputs is None:
            return None
        kernel, screws, tool, settings, restarts = inputs
        count = len(positions)
        targets = np.zeros((count, 4, 4))
        targets[:, 3, 3] = 1.0
        targets[:, :3, 3] = positions
        if rotations is not None:
            targets[:, :3, :3] = rotations
        q = np.empty((count, self.nq))
        converged = np.zeros(count, dtype=bool)
        kernel.solve_many(
            np.ascontiguousarray(seeds, dtype=float), targets, rotations is not None,
            self._limits, screws, tool, settings, np.ascontiguousarray(restarts), rescue, q,
            converged,
        )  # fmt: skip
        return q, converged

    def _rescue(
        self,
        best: np.ndarray,
        q_seed: np.ndarray,
        position: np.ndarray,
        rotation: np.ndarray | None,
        tolerances: tuple[float, float],
        max_iterations: int,
    ) -> tuple[np.ndarray, float, float, int] | None:
        """What :meth:`solve` tries when every attempt failed: polish the best attempt; then
        solve from the seed ignoring the limits and turn the revolute joints by whole turns
        into them.

        Returns:
            (q, position error [m], rotation error [rad], iterations), or None.
        """
        q, ok, perr, rerr, its, _ = self.descend(
            best,
            position,
            rotation,
            *tolerances,
            POLISH_ITERATIONS * max_iterations,
            damping_floor=POLISH_DAMPING_FLOOR,
            stall_iterations=POLISH_STALL_ITERATIONS,
            turn=True,
        )
        if ok:
            return q, perr, rerr, its
        q, ok, _, _, free_its, _ = self.descend(
            q_seed, position, rotation, *tolerances, POLISH_ITERATIONS * max_iterations, False
        )
        its += free_its
        if not ok:
            return None
        turns = np.ceil((self.lower - q) / (2.0 * math.pi) - 1e-12)
        q = q + 2.0 * math.pi * np.where(self._revolute & np.isfinite(turns), turns, 0.0)
        if np.any(q < self.lower) or np.any(q > self.upper):
            return None
        q, ok, perr, rerr, polish_its, _ = self.descend(
            q,
            position,
            rotation,
            *tolerances,
            max_iterations,
            damping_floor=POLISH_DAMPING_FLOOR,
            stall_iterations=POLISH_STALL_ITERATIONS,
            turn=True,
        )
        return (q, perr, rerr, its + polish_its) if ok else None
