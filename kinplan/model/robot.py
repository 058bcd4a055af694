"""Robot models: a serial chain of a URDF, with forward kinematics, Jacobians and IK.

:func:`load_robot` builds a :class:`Robot` from a bundled name, an example-robot-data name or a
URDF path; :func:`planar_arm` from link lengths. Kinematics come from Pinocchio: the robot keeps
one ``pin.Model`` (reduced to the chain from the URDF root to the tool frame) and reuses its own
``pin.Data``.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.checks import parse_target
from kinplan.errors import InputError, RobotNotFoundError
from kinplan.ik import AnalyticIK, IKResult, IKSolver, finite_bounds, halton
from kinplan.model.extent import planar_link_lengths, prismatic_joints, stored_reach
from kinplan.model.jacobians import (
    jacobian_time_variation,
    manipulability_of,
    mimic_jacobian_time_variations,
)
from kinplan.model.planar import planar_arm_urdf, write_planar_arm
from kinplan.model.sources import RobotSpec, known_names, resolve_source
from kinplan.model.tool import Tool, tool_urdf
from kinplan.model.urdf_frames import frame_id
from kinplan.model.urdf_model import build_chain

if TYPE_CHECKING:
    from kinplan.cell import Body
    from kinplan.ik.batch import BatchSolver

logger = logging.getLogger(__name__)

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_TAU = 2.0 * math.pi


class Robot:
    """A serial arm: its Pinocchio model, limits and tool frame.

    Attributes:
        name: Robot name.
        nq: Number of joints.
        joint_names: Names of the joints, base to tip.
        tip_frame: Tool frame (a URDF link or frame name).
        base_frame: The URDF's root link; poses are expressed in it (the world frame).
        urdf_path: A URDF file on disk that describes this robot.
        lower: Lower position limits [rad or m], shape (nq,).
        upper: Upper position limits [rad or m], shape (nq,).
        velocity_limit: Speed limits [rad/s or m/s], shape (nq,) (``inf`` where the URDF has none).
        prismatic: Which joints are prismatic (their coordinates in m, the others' in rad),
            shape (nq,) bool.
        model: The Pinocchio model of the chain (shared, do not modify).
        package_dirs: Folders that resolve the URDF's ``package://`` mesh paths.
        tool: The tool of a robot made by :meth:`with_tool` (None without one).
        tool_links: Links that are tool bodies (set by :meth:`with_tool`).
        source_urdf_path: The URDF the robot was loaded from, before :meth:`with_tool` wrote
            its own (None: ``urdf_path``).
    """

    tool: Tool | None = None
    tool_links: tuple[str, ...] = ()
    source_urdf_path: Path | None = None

    def __init__(
        self,
        spec: RobotSpec,
        tip: str | None = None,
        *,
        locked_joints: Mapping[str, float] | None = None,
        base_pose: pin.SE3 | None = None,
        limits: Mapping[str, Mapping[str, float]] | None = None,
    ) -> None:
        if not isinstance(spec, RobotSpec):
            raise InputError(
                "Robot(spec) takes a kinplan.model.sources.RobotSpec; load a robot with "
                f"kinplan.load_robot(name or URDF path), got {checks.describe(spec)}"
            )
        if tip is not None:
            tip = checks.text(tip, "tip (a frame or link name)")
        if base_pose is not None:
            position, rotation = parse_target(base_pose, "base_pose")
            if rotation is None:
                rotation = np.eye(3)
            base_pose = pin.SE3(rotation, position)
        urdf_path = Path(spec.urdf_path)
        chain = build_chain(
            urdf_path, tip, spec.default_tip, locked_joints=locked_joints, base_pose=base_pose,
            limits=limits,
        )  # fmt: skip
        self.model = chain.model
        self.tip_frame = chain.tip
        self.base_frame = chain.base_frame
        self.name = spec.name or chain.name
        self.urdf_path = urdf_path
        self.package_dirs = spec.package_dirs
        self.nq = self.model.nq
        self.joint_names = [
            self.model.names[j] for j in range(1, self.model.njoints) if self.model.joints[j].nq
        ]
        self.continuous_joints = chain.continuous
        self.mimic_joints = chain.mimic
        self.locked_joints = chain.locked
        self.held_root = chain.held_root
        self.base_pose = pin.SE3.Identity() if base_pose is None else base_pose
        self.tip_id = frame_id(self.model, self.tip_frame, urdf_path)
        self.lower, self.upper = chain.lower, chain.upper
        self.velocity_limit, self.acceleration_limit = chain.velocity, chain.acceleration
        self.data = self.model.createData()
        self._ik = IKSolver(self.model, self.tip_id, self.lower, self.upper)
        self._reference_manipulability: dict[bool, float] = {}
        self._unbounded = np.flatnonzero(~np.isfinite(self.lower) & ~np.isfinite(self.upper))
        self.prismatic = prismatic_joints(self.model)
        self._task = self._task_structure()
        self.link_lengths = planar_link_lengths(self.model, self.tip_id)

    def __repr__(self) -> str:
        return (
            f"Robot({self.name!r}, nq={self.nq}, tip={self.tip_frame!r}, base={self.base_frame!r})"
        )

    # ------------------------------------------------------------------ validation
    def check_q(self, q: Sequence[float] | np.ndarray, what: str = "q") -> np.ndarray:
        """``q`` as a float array of shape (nq,) [rad or m].

        Args:
            q: Joint values, one per joint (a list, tuple or array of numbers).
            what: How the argument is named in messages.

        Raises:
            InputError: not numbers (text, None, booleans, nested lists), the wrong size, NaN or
                inf; the message names the joints.
        """
        if type(q) is np.ndarray and q.dtype == np.float64:  # the common case: no conversion
            arr = q
        elif q is None or isinstance(q, (str, bytes)):
            raise self._q_error(what, q)
        else:
            try:
                arr = np.asarray(q)
                if arr.dtype.kind not in "iuf" and arr.dtype != object:
                    raise TypeError  # booleans, text, complex numbers
                arr = arr.astype(float, copy=False)
            except Exception:  # ragged nesting, objects that are not numbers
                raise self._q_error(what, q) from None
        if arr.shape != (self.nq,):
            raise self._q_error(what, q, f"shape {arr.shape}")
        # finite only when every term is (plain floats: fast); a huge finite q may overflow
        # the sum, so numpy has the last word
        if not math.isfinite(sum(arr.tolist())) and not np.all(np.isfinite(arr)):
            raise InputError(f"{what} must be finite, got {arr}")
        return arr

    def _q_error(self, what: str, q: object, note: str = "") -> InputError:
        return InputError(
            f"{what} must hold {self.nq} joint values for {self.name} "
            f"({', '.join(self.joint_names)}) [rad, or m for prismatic joints], got "
            f"{checks.describe(q)}" + (f" ({note})" if note else "")
        )

    def within_limits(self, q: Sequence[float] | np.ndarray, tolerance: float = 1e-9) -> bool:
        """Whether ``q`` lies within the position limits (± ``tolerance`` [rad or m], ≥ 0)."""
        q = self.check_q(q)
        if type(tolerance) is not float or not 0.0 <= tolerance < math.inf:
            tolerance = checks.number(tolerance, "tolerance", minimum=0.0, unit="rad or m")
        return bool(np.all(q >= self.lower - tolerance) and np.all(q <= self.upper + tolerance))

    def neutral(self) -> np.ndarray:
        """Zero configuration moved into the limits (the default IK seed)."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    def random_configuration(self, rng: np.random.Generator) -> np.ndarray:
        """A configuration drawn uniformly within the limits (continuous joints within [−π, π])
        with the caller's generator (``numpy.random.default_rng(seed)``)."""
        if not isinstance(rng, np.random.Generator):
            raise InputError(
                f"rng must be a numpy.random.Generator (numpy.random.default_rng(seed)); got "
                f"{checks.describe(rng)}"
            )
        return rng.uniform(*finite_bounds(self.lower, self.upper))

    # ------------------------------------------------------------------ kinematics
    def fk(self, q: Sequence[float] | np.ndarray) -> pin.SE3:
        """Tool pose in the base (world) frame: a new ``pin.SE3`` each call."""
        q = self.check_q(q)
        pin.forwardKinematics(self.model, self.data, q)
        return pin.SE3(pin.updateFramePlacement(self.model, self.data, self.tip_id))

    def tool_positions(self, q: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        """Tool positions [m] in the base frame for joint rows ``q`` (N, nq): shape (N, 3),
        one FK pass per row."""
        rows = checks.rows(q, f"the joint rows of {self.name}", self.nq, unit="rad or m")
        out = np.empty((len(rows), 3))
        for k, row in enumerate(rows):
            pin.forwardKinematics(self.model, self.data, row)
            out[k] = pin.updateFramePlacement(self.model, self.data, self.tip_id).translation
        return out

    def jacobian(self, q: Sequence[float] | np.ndarray) -> np.ndarray:
        """Tool Jacobian (6, nq), rows [linear; angular], world-aligned frame at the tool."""
        q = self.check_q(q)
        J = pin.computeFrameJacobian(self.model, self.data, q, self.tip_id, _LWA)
        return J.reshape(6, self.nq).copy()  # eigenpy gives a 1-D array when nq == 1

    def pose_and_jacobian(self, q: Sequence[float] | np.ndarray) -> tuple[pin.SE3, np.ndarray]:
        """:meth:`fk` and :meth:`jacobian` of ``q`` from one kinematics pass."""
        q = self.check_q(q)
        pin.computeJointJacobians(self.model, self.data, q)
        pose = pin.SE3(pin.updateFramePlacement(self.model, self.data, self.tip_id))
        J = pin.getFrameJacobian(self.model, self.data, self.tip_id, _LWA)
        return pose, J.reshape(6, self.nq).copy()

    def _task_structure(self) -> dict[bool, tuple[np.ndarray, int]]:
        """Task rows and rank of the position-only and full tool Jacobian.

        A row is part of the task when it is non-zero at some generic configuration (a planar
        arm in the xy-plane drops z, and the rotations about x and y); the rank is that of the
        remaining rows at a generic configuration.
        """
        rng = np.random.default_rng(7)
        jacobians = [self.jacobian(self.random_configuration(rng)) for _ in range(3)]
        structure = {}
        for position_only in (True, False):
            candidates = np.arange(3 if position_only else 6)
            used = np.max([np.abs(J[candidates]).max(axis=1) for J in jacobians], axis=0)
            rows = candidates[used > 1e-12]
            rank = 0
            for J in jacobians:
                sv = np.linalg.svd(J[rows], compute_uv=False) if rows.size else np.zeros(0)
                rank = max(rank, int(np.sum(sv > 1e-9 * max(1.0, sv.max(initial=0.0)))))
            structure[position_only] = (rows, rank)
        return structure

    def planar_reach(self) -> tuple[float, float] | None:
        """Workspace annulus (r_min, r_max) [m] about the first joint, for planar arms.

        r_max is the sum of the link lengths; r_min is max(0, 2·l_longest − Σl). None for arms
        that are not planar.
        """
        if self.link_lengths is None:
            return None
        total = float(sum(self.link_lengths))
        return max(0.0, 2.0 * max(self.link_lengths) - total), total

    def reach(self) -> float:
        """Reach [m]: the largest distance of the tool from the first joint's origin within the
        joint limits (cached).

        Planar arms: r_max of :meth:`planar_reach`, exact. Other arms: from the best of 128
        configurations (the tool driven toward far points in directions spread over the
        sphere), the tool is pushed outward along its own direction, a step δ at a time (the
        limits respected; δ halved whenever the step cannot be taken), until δ < 1e-7 m: a
        local maximum of the distance, which the spread of starts makes the global one in
        practice (never more than the true reach). The search's result is kept on disk
        (:func:`kinplan.model.extent.stored_reach`) and read back by later processes.
        """
        cached = self.__dict__.get("_reach")
        if cached is not None:
            return cached
        annulus = self.planar_reach()
        if annulus is not None:
            self._reach = annulus[1]
            return self._reach
        self._reach = stored_reach(self)
        return self._reach

    def shoulder_distance(self, position: Sequence[float] | np.ndarray) -> float:
        """Distance [m] of a position (base frame) from the first joint's origin."""
        origin = self.model.jointPlacements[1].translation
        return float(np.linalg.norm(np.asarray(position, dtype=float) - origin))

    def task_rows(self, position_only: bool) -> np.ndarray:
        """Rows of the tool Jacobian the arm acts on ([0, 1] for a planar arm's position)."""
        return self._task[checks.flag(position_only, "position_only")][0]

    def task_rank(self, position_only: bool) -> int:
        """How many independent tool motions the arm has (2 for a planar arm's position)."""
        return self._task[checks.flag(position_only, "position_only")][1]

    def default_position_only(self) -> bool:
        """Position only for arms that cannot control a full 6-D pose (fewer than 6 joints)."""
        return self.nq < 6

    def manipulability(
        self, q: Sequence[float] | np.ndarray, position_only: bool | None = None
    ) -> float:
        """Yoshikawa manipulability of the task Jacobian.

        The product of the r largest singular values of the task Jacobian, r the task's rank at a
        generic configuration: sqrt(det(J Jᵀ)) for a full-rank 6-D task (UR, panda), and
        sqrt(det(Jᵀ J)) for arms with fewer joints than task rows, so the planar 2R gives
        l1·l2·|sin θ2| [m²]. The task is position-only for arms with fewer than 6 joints unless
        ``position_only`` says otherwise.
        """
        if position_only is None:
            position_only = self.default_position_only()
        rows, rank = self._task[checks.flag(position_only, "position_only")]
        return float(manipulability_of(self.jacobian(q)[rows], rank))

    # ------------------------------------------------------------------ inverse kinematics
    def ik(
        self,
        target: pin.SE3 | Sequence[float] | np.ndarray,
        q_seed: Sequence[float] | np.ndarray | None = None,
        position_only: bool = False,
        *,
        position_tolerance: float = 1e-6,
        rotation_tolerance: float = 1e-6,
        max_iterations: int = 40,
        max_restarts: int = 40,
    ) -> IKResult:
        """Joint configuration that puts the tool at ``target``.

        Arms with a closed form (planar 2R, UR family, spherical-wrist 6R arms, panda) get the
        solution nearest ``q_seed`` directly (:attr:`ik_solver`'s ``description`` says which).
        Others iterate from ``q_seed`` (default: :meth:`neutral`) and, when that attempt fails,
        restart from a deterministic low-discrepancy set of configurations. Starting
        near a solution, it returns the solution on the seed's branch. Results always lie within
        the joint limits.

        Args:
            target: Tool pose (``pin.SE3`` or 4×4 matrix) or tool position (3-vector, implies
                position only) in the base frame [m].
            q_seed: Start configuration, shape (nq,).
            position_only: Ignore the target's orientation.
            position_tolerance: Success threshold on the position error [m].
            rotation_tolerance: Success threshold on the rotation error [rad].
            max_iterations: Iterations per attempt.
            max_restarts: Restarts after the seeded attempt fails (0: only the seed).

        Returns:
            IKResult; failure is ``success=False`` with the best ``q`` found, never an exception.

        Raises:
            InputError: malformed target or seed (wrong size, NaN, inf, not numbers, a matrix
                that is not a rotation), a tolerance that is not a finite number > 0, counts that
                are not integers (``max_iterations`` ≥ 1, ``max_restarts`` ≥ 0).
        """
        position, rotation = parse_target(target, "target")
        if rotation is None or checks.flag(position_only, "position_only"):
            rotation = None
        if q_seed is None:
            seed = self.neutral()
        else:  # a seed far beyond the limits (1e300 rad) only needs to say which side it is on
            seed = np.minimum(  # as np.clip, at a third of its cost on a few values
                np.maximum(self.check_q(q_seed, "q_seed"), self.lower - _TAU), self.upper + _TAU
            )
        position_tolerance = checks.number(
            position_tolerance, "position_tolerance", positive=True, unit="m"
        )
        rotation_tolerance = checks.number(
            rotation_tolerance, "rotation_tolerance", positive=True, unit="rad"
        )
        max_iterations = checks.count(max_iterations, "max_iterations", minimum=1)
        max_restarts = checks.count(max_restarts, "max_restarts", minimum=0)
        closed_form = self.closed_form_ik
        if closed_form is not None and rotation is None and closed_form.needs_rotation:
            closed_form = None  # a position-only target: the numerical solver
        result = self._ik.solve_checked(
            position,
            rotation,
            seed,
            position_tolerance,
            rotation_tolerance,
            max_iterations,
            max_restarts,
            closed_form,
        )
        unbounded = self._unbounded
        if unbounded.size:  # continuous joints: the equivalent angle nearest the seed
            turns = np.round((result.q[unbounded] - seed[unbounded]) / _TAU)
            result.q = result.q.copy()
            result.q[unbounded] -= _TAU * turns
        return result

    # ------------------------------------------------------------------ batch IK (issue 19)
    def ik_batch(
        self,
        targets: np.ndarray | Sequence[pin.SE3],
        q_seed: Sequence[float] | np.ndarray | None = None,
        position_only: bool = False,
        *,
        position_tolerance: float = 1e-6,
        rotation_tolerance: float = 1e-6,
        max_iterations: int = 40,
        max_restarts: int = 40,
        threads: int | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`ik` for many targets at once, vectorised over the targets.

        Arms with a closed form (planar 2R, UR family, panda) run it on all targets at once
        and keep per target the solution nearest its seed, as :meth:`ik` does (the panda's θ7
        search stage by stage over the targets); other arms run the damped least-squares
        iteration of :meth:`ik` on all targets at once, restarting the failed ones from the
        same Halton configurations (see :mod:`kinplan.ik.batch`). A target the closed form
        cannot reach within the limits fails without numerical attempts. An (N, 4, 4) array is
        the fastest form of the targets (a list of ``pin.SE3`` costs ~0.6 µs a target to
        convert).

        Args:
            targets: Tool poses, an (N, 4, 4) array of homogeneous matrices or a list of
                ``pin.SE3``, or tool positions (N, 3) [m] (position only), in the base frame.
            q_seed: One start configuration (nq,) for all targets or one per target (N, nq)
                (default :meth:`neutral`).
            position_only: Ignore the targets' orientations.
            position_tolerance: Success threshold on the position error [m].
            rotation_tolerance: Success threshold on the rotation error [rad].
            max_iterations: Iterations per numerical attempt.
            max_restarts: Numerical restarts after the seeded attempt fails.
            threads: Threads that share the targets (the answers are the same on any
                number, q to the last bits of rounding). Default: one per core for 8,192
                targets or more when called from the main thread (``KINPLAN_THREADS`` sets
                the number), else one — called from Dask's workers or another thread pool,
                the cores are busy already (see :mod:`kinplan.ik.batch_threads`).

        Returns:
            (q, success): configurations (N, nq) within the limits (for a failure the best one
            found, or the seed clipped into the limits) and (N,) booleans.

        Raises:
            InputError: targets of another shape, not finite, rotations that are not
                rotations, seeds of the wrong size; tolerances and counts as :meth:`ik`;
                ``threads`` not a positive integer.
        """
        from kinplan.ik.batch_kinematics import batch_seeds, parse_targets  # on first use

        positions, rotations = parse_targets(targets)
        if checks.flag(position_only, "position_only"):
            rotations = None
        seeds = batch_seeds(self, q_seed, len(positions))
        position_tolerance = checks.number(
            position_tolerance, "position_tolerance", positive=True, unit="m"
        )
        rotation_tolerance = checks.number(
            rotation_tolerance, "rotation_tolerance", positive=True, unit="rad"
        )
        max_iterations = checks.count(max_iterations, "max_iterations", minimum=1)
        max_restarts = checks.count(max_restarts, "max_restarts", minimum=0)
        q, success = self.batch_solver.solve(
            positions, rotations, seeds, position_tolerance, rotation_tolerance,
            max_iterations, max_restarts, threads=threads,
        )  # fmt: skip
        unbounded = self._unbounded
        if unbounded.size:  # continuous joints: the equivalent angle nearest the seed
            q[:, unbounded] -= _TAU * np.round((q[:, unbounded] - seeds[:, unbounded]) / _TAU)
        return q, success

    @property
    def batch_solver(self) -> BatchSolver:
        """The solver behind :meth:`ik_batch` (:class:`kinplan.ik.batch.BatchSolver`), built
        on first use."""
        if "_batch_solver" not in self.__dict__:
            from kinplan.ik.batch import BatchSolver  # the batch solvers load on first use

            self._batch_solver = BatchSolver(self)
        return self._batch_solver

    def jacobian_time_variations(
        self, q: np.ndarray, qd: np.ndarray, jacobians: np.ndarray | None = None
    ) -> np.ndarray:
        """J̇ of the tool Jacobian (world-aligned, like :meth:`jacobian`) at many samples.

        Without mimic joints: :func:`jacobian_time_variation` from the Jacobians alone (no
        kinematics pass). A mimic joint makes a Jacobian column the sum of two joints' columns,
        which that formula cannot split: then Pinocchio computes the joint's J̇ in the WORLD
        frame sample by sample, moved to the tool point here (Pinocchio 3.4–4.1's
        ``getFrameJacobianTimeVariation`` in ``LOCAL_WORLD_ALIGNED`` is wrong for mimic models:
        its columns past the mimic joint are off by up to 0.3 m/s per rad/s).

        Args:
            q: Joint positions (N, nq) [rad or m].
            qd: Joint velocities (N, nq) [rad/s or m/s].
            jacobians: The tool Jacobians (N, 6, nq) at q, if known.

        Returns:
            J̇, shape (N, 6, nq) (per second).
        """
        if not self.mimic_joints:
            if jacobians is None:
                jacobians = np.array([self.jacobian(row) for row in q]).reshape(-1, 6, self.nq)
            return jacobian_time_variation(jacobians, qd)
        return mimic_jacobian_time_variations(self.model, self.data, self.tip_id, q, qd)

    @property
    def ik_solver(self) -> IKSolver:
        """The robot's numerical IK solver (owns its ``pin.Data``; see :class:`IKSolver`). Its
        ``description`` says which solver :meth:`ik` uses: the closed form the arm's screw axes
        fit, or numerical and why no closed form fits."""
        self.closed_form_ik  # noqa: B018 - found once; it sets the description
        return self._ik

    def reference_manipulability(self, position_only: bool) -> float:
        """Median manipulability over a fixed low-discrepancy set of 256 configurations within
        the limits (continuous joints within [−π, π]): the arm's typical value, which singularity
        thresholds are a share of. Cached per task."""
        cache = self._reference_manipulability
        if position_only not in cache:
            lower, upper = finite_bounds(self.lower, self.upper)
            values = [
                self.manipulability(lower + (upper - lower) * halton(i, self.nq), position_only)
                for i in range(1, 257)
            ]
            cache[position_only] = float(np.median(values))
        return cache[position_only]

    @property
    def closed_form_ik(self) -> AnalyticIK | None:
        """The closed-form IK solver of this arm (planar 2R, UR family, spherical wrist, panda),
        or None.

        Built on first use from the model's geometry and checked against its FK
        (:func:`kinplan.ik.analytic_solver_for`).
        """
        if not hasattr(self, "_closed_form"):
            from kinplan.ik.closed_form import closed_form_report  # the closed forms load here

            self._closed_form, self._ik.description = closed_form_report(self)
        return self._closed_form

    def limit_overrides(self) -> dict[str, dict[str, float]]:
        """The robot's joint limits as ``load_robot(limits=...)`` overrides (finite values only:
        continuous joints stay unbounded, unknown speeds stay unknown), to rebuild the same
        robot from its URDF."""
        limits: dict[str, dict[str, float]] = {}
        for k, name in enumerate(self.joint_names):
            entry = {}
            for key, values in (
                ("lower", self.lower),
                ("upper", self.upper),
                ("velocity", self.velocity_limit),
                ("acceleration", self.acceleration_limit),
            ):
                if np.isfinite(values[k]):
                    entry[key] = float(values[k])
            if entry:
                limits[name] = entry
        return limits

    def with_tool(
        self, pose: pin.SE3 | np.ndarray | Sequence[float], body: Body | None = None
    ) -> Robot:
        """This robot with a tool on its flange (the current tip frame): a new Robot whose tip
        is the tool centre point, so FK, IK, Jacobians and paths all work at the TCP, and whose
        tool body (if given) collides like a link in a :class:`kinplan.WorkCell` and is drawn
        by the viewer (see :mod:`kinplan.model.tool`).

        Args:
            pose: The TCP in the flange frame: ``pin.SE3``, 4×4 matrix or position 3-vector [m]
                (e.g. ``kinplan.cell.xyz_rpy((0, 0, 0.3), (0, -45, 0))``).
            body: The tool's collision body in the flange frame, a :class:`kinplan.cell.Body`
                (``Body.cylinder(0.012, 0.3, pose)``, ``Body.mesh("torch.stl", scale=0.001)``),
                or None.

        Returns:
            The new robot; ``robot.tool`` describes the tool (:class:`kinplan.model.tool.Tool`).

        Raises:
            CellError: a pose that is not a pose, a body that is not a ``Body``.
        """
        made = tool_urdf(self, pose, body)
        tooled = Robot(
            made.spec,
            made.tool.tcp_link,
            locked_joints=self.locked_joints or None,
            base_pose=None if self.base_pose.isIdentity() else self.base_pose,
            limits=self.limit_overrides(),
        )
        tooled.tool = made.tool
        body_link = made.tool.body_link
        tooled.tool_links = self.tool_links + ((body_link,) if body_link else ())
        tooled.source_urdf_path = self.source_urdf_path or Path(self.urdf_path)
        return tooled


def load_robot(
    source: str | os.PathLike[str],
    tip: str | None = None,
    *,
    locked_joints: Mapping[str, float] | None = None,
    base_pose: pin.SE3 | np.ndarray | None = None,
    limits: Mapping[str, Mapping[str, float]] | None = None,
    package_dirs: Sequence[str | os.PathLike[str]] | None = None,
) -> Robot:
    """Load a robot arm.

    Continuous joints become unbounded revolute joints (``lower = -inf``, ``upper = +inf``),
    mimic joints follow their master (not in ``q``), a floating or planar root joint is held at
    ``base_pose`` (see :mod:`kinplan.model.urdf_model`).

    Args:
        source: A bundled robot (``"planar_2r"``), an example-robot-data arm (``"ur3"``,
            ``"ur5"``, ``"ur10"``, ``"panda"``) or the path of a URDF file.
        tip: Tool frame (link or frame name). Default: ``tool0`` for UR arms, ``panda_hand_tcp``
            for the panda, ``tip`` for planar arms, otherwise the last link of the only chain
            (gripper joints — names with gripper, finger, jaw — left out and held at 0).
        locked_joints: Joints held at a value, {name: value [rad or m]}; they leave ``q``.
        base_pose: Pose of the URDF's root link in the world (``pin.SE3`` or 4×4 matrix);
            every pose of the robot is then expressed in the world. Default identity.
        limits: Overrides of the URDF's limits, {joint: {"lower": .., "upper": .., "velocity":
            .., "acceleration": ..}} (any subset; [rad or m, /s, /s²]). Joints without usable
            limits in the URDF load with them.
        package_dirs: Extra folders searched for ``package://`` and relative mesh paths (the
            URDF's own folder and example-robot-data's always are).

    Raises:
        RobotNotFoundError: unknown name (the message lists the known ones) or missing file.
        URDFError: malformed XML, a URDF Pinocchio rejects, several chains without ``tip``, a
            floating joint inside the chain; a joint of the chain without usable limits (no
            ``<limit>``, lower ≥ upper, a velocity of 0), with the axis 0 0 0, or an offset
            beyond 10 km.
        FrameError: ``tip`` is not a frame of the robot, or several chains and no ``tip`` (the
            message lists the candidate tool frames).
        InputError: ``source`` is not a string or path, ``tip`` not a string; malformed
            ``locked_joints``, ``base_pose``, ``limits`` or ``package_dirs`` (unknown joint
            names are listed with the known ones); a locked value outside its joint's limits; a
            base pose more than 10 km from the world origin.
    """
    if isinstance(source, os.PathLike):
        try:
            source = os.fsdecode(os.fspath(source))
        except (TypeError, ValueError):
            pass  # reported below
    if not isinstance(source, str) or not source.strip() or "\0" in source:
        raise InputError(
            f"source must be a robot name ({', '.join(known_names())}) or the path of a URDF "
            f"file (a str or os.PathLike), got {checks.describe(source)}"
        )
    if tip is not None:
        tip = checks.text(tip, "tip (a frame or link name)")
    try:
        spec = resolve_source(source)
    except (OSError, RuntimeError, ValueError) as exc:  # a name too long, ~nobody/, ...
        shown = source if len(source) <= 80 else source[:77] + "..."
        reason = (getattr(exc, "strerror", None) or str(exc)).rstrip(".")
        raise RobotNotFoundError(
            f"cannot use {shown!r} as a robot ({reason}); give a robot name "
            f"({', '.join(known_names())}) or the path of a URDF file"
        ) from exc
    if package_dirs is not None:
        if isinstance(package_dirs, (str, os.PathLike)):
            package_dirs = [package_dirs]
        if not isinstance(package_dirs, Sequence):
            raise InputError(
                f"package_dirs must be a list of folders, got {checks.describe(package_dirs)}"
            )
        extra = tuple(Path(checks.file_path(d, "package_dirs entry")) for d in package_dirs)
        spec = dataclasses.replace(spec, package_dirs=extra + tuple(spec.package_dirs))
    return Robot(spec, tip, locked_joints=locked_joints, base_pose=base_pose, limits=limits)


def planar_arm(
    lengths: Sequence[float] | np.ndarray,
    lower: float | Sequence[float] | None = None,
    upper: float | Sequence[float] | None = None,
    velocity_limit: float | Sequence[float] | None = None,
    name: str | None = None,
) -> Robot:
    """A planar arm with ``len(lengths)`` revolute joints about z, tool at the last link's end.

    Args:
        lengths: Link lengths [m] (e.g. ``[1.0, 0.25]``).
        lower: Lower position limits [rad] (default −π).
        upper: Upper position limits [rad] (default +π).
        velocity_limit: Speed limits [rad/s] (default 2π).
        name: Robot name (default ``planar_<n>r``).

    Raises:
        InputError: ``lengths`` not a non-empty list of finite numbers > 0; limits that are not
            a number or one number per joint, or ``lower`` ≥ ``upper``; a non-positive velocity
            limit; ``name`` not a string.
    """
    lengths = checks.vector(lengths, "lengths (link lengths)", unit="m")
    if lengths.size == 0 or np.any(lengths <= 0):
        raise InputError(f"link lengths must be finite and > 0 m, got {lengths.tolist()}")
    for value, what, unit in (
        (lower, "lower", "rad"),
        (upper, "upper", "rad"),
        (velocity_limit, "velocity_limit", "rad/s"),
    ):
        if value is not None and not isinstance(value, (int, float, np.integer, np.floating)):
            checks.vector(value, f"{what} (a number, or one per joint)", lengths.size, unit)
        elif value is not None:
            checks.number(value, what, unit=unit)
    name = f"planar_{lengths.size}r" if name is None else checks.text(name, "name")
    text = planar_arm_urdf(
        lengths, name=name, lower=lower, upper=upper, velocity_limit=velocity_limit
    )
    path = write_planar_arm(text)
    return Robot(
        RobotSpec(name=name, urdf_path=path, package_dirs=(path.parent,), default_tip="tip")
    )
