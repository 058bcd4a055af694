"""Robot models: a serial chain of a URDF, with forward kinematics, Jacobians and IK.

:func:`load_robot` builds a :class:`Robot` from a bundled name, an example-robot-data name or a
URDF path; :func:`planar_arm` from link lengths. Kinematics come from Pinocchio: the robot keeps
one ``pin.Model`` (reduced to the chain from the URDF root to the tool frame) and reuses its own
``pin.Data``.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan.errors import FrameError, InputError, URDFError
from kinplan.ik import IKResult, IKSolver
from kinplan.planar import planar_arm_urdf, write_planar_arm
from kinplan.sources import RobotSpec, resolve_source

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_ONES3 = np.ones(3)
_ONE_DOF_JOINTS = {
    "JointModelRX",
    "JointModelRY",
    "JointModelRZ",
    "JointModelRevoluteUnaligned",
    "JointModelPX",
    "JointModelPY",
    "JointModelPZ",
    "JointModelPrismaticUnaligned",
}


def _root_link(urdf_path: Path) -> tuple[str, str]:
    """Parse the URDF's XML; return (robot name, root link name)."""
    try:
        root = ET.parse(urdf_path).getroot()
    except ET.ParseError as exc:
        raise URDFError(f"{urdf_path} is not valid XML ({exc}); fix the file") from exc
    if root.tag != "robot":
        raise URDFError(f"{urdf_path} is not a URDF: its root element is <{root.tag}>, not <robot>")
    links = [link.get("name") for link in root.findall("link")]
    children = {child.get("link") for child in root.findall("joint/child")}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise URDFError(
            f"{urdf_path} must have exactly one root link (a link that is no joint's child); "
            f"found {roots or 'none'}"
        )
    return root.get("name", urdf_path.stem), roots[0]


def _build_model(urdf_path: Path) -> pin.Model:
    try:
        return pin.buildModelFromUrdf(str(urdf_path))
    except (RuntimeError, ValueError) as exc:
        raise URDFError(f"Pinocchio could not read {urdf_path}: {exc}") from exc


def _body_frames(model: pin.Model) -> list[str]:
    return [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.name != "universe"]


def _default_tip(model: pin.Model, urdf_path: Path) -> str:
    """The last link of the only chain; an error listing the chain ends if there are several."""
    parents = {model.parents[j] for j in range(1, model.njoints)}
    leaves = [j for j in range(1, model.njoints) if j not in parents]
    if not leaves:
        raise URDFError(f"{urdf_path} has no movable joint; kinplan plans for arms with joints")
    ends = []
    for j in leaves:
        bodies = [
            f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j
        ]
        ends.append(bodies[-1])
    if len(ends) > 1:
        raise URDFError(
            f"{urdf_path} has several kinematic chains ending at {', '.join(ends)}; "
            "choose one with tip=<link name>"
        )
    return ends[0]


def _chain_model(model: pin.Model, tip: str, urdf_path: Path) -> pin.Model:
    """Reduce ``model`` to the joints between the root and frame ``tip`` (the others locked)."""
    if not model.existFrame(tip):
        candidates = ", ".join(_body_frames(model))
        raise FrameError(f"no frame {tip!r} in {urdf_path.name}; links and frames: {candidates}")
    frame = model.frames[model.getFrameId(tip)]
    chain = set(model.supports[frame.parentJoint])
    for j in sorted(chain - {0}):
        kind = model.joints[j].shortname()
        if kind not in _ONE_DOF_JOINTS:
            raise URDFError(
                f"joint {model.names[j]!r} of {urdf_path.name} is {kind}: kinplan plans for serial "
                "arms of revolute (with limits) and prismatic joints; a floating or continuous "
                "joint is not supported on the tool's chain"
            )
    locked = [j for j in range(1, model.njoints) if j not in chain]
    if not locked:
        return model
    return pin.buildReducedModel(model, locked, pin.neutral(model))


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
        model: The Pinocchio model of the chain (shared, do not modify).
        package_dirs: Folders that resolve the URDF's ``package://`` mesh paths.
    """

    def __init__(self, spec: RobotSpec, tip: str | None = None):
        urdf_path = Path(spec.urdf_path)
        urdf_name, self.base_frame = _root_link(urdf_path)
        full = _build_model(urdf_path)
        self.tip_frame = tip or spec.default_tip or _default_tip(full, urdf_path)
        self.model = _chain_model(full, self.tip_frame, urdf_path)
        if self.model.nq == 0:
            raise URDFError(f"no movable joint between {self.base_frame!r} and {self.tip_frame!r}")
        self.name = spec.name or urdf_name
        self.urdf_path = urdf_path
        self.package_dirs = spec.package_dirs
        self.nq = self.model.nq
        self.joint_names = [self.model.names[j] for j in range(1, self.model.njoints)]
        self.tip_id = self.model.getFrameId(self.tip_frame)
        self.lower = np.array(self.model.lowerPositionLimit, dtype=float)
        self.upper = np.array(self.model.upperPositionLimit, dtype=float)
        velocity = np.array(self.model.velocityLimit, dtype=float)
        self.velocity_limit = np.where(velocity > 0, velocity, np.inf)
        bad = [n for n, lo, hi in zip(self.joint_names, self.lower, self.upper) if not lo < hi]
        if bad:
            raise URDFError(f"joints {bad} of {urdf_path.name} have no valid position limits")
        self.data = self.model.createData()
        self._ik = IKSolver(self.model, self.tip_id, self.lower, self.upper)
        self._task = self._task_structure()
        self.link_lengths = self._planar_link_lengths()

    def __repr__(self) -> str:
        return (
            f"Robot({self.name!r}, nq={self.nq}, tip={self.tip_frame!r}, base={self.base_frame!r})"
        )

    # ------------------------------------------------------------------ validation
    def check_q(self, q: Sequence[float] | np.ndarray, what: str = "q") -> np.ndarray:
        """``q`` as a float array of shape (nq,); InputError for a wrong size, NaN or inf."""
        arr = np.asarray(q, dtype=float)
        if arr.shape != (self.nq,):
            raise InputError(
                f"{what} must hold {self.nq} joint values for {self.name} "
                f"({', '.join(self.joint_names)}), got shape {arr.shape}"
            )
        if not math.isfinite(sum(arr.tolist())):  # finite only when every term is (floats: fast)
            raise InputError(f"{what} must be finite, got {arr}")
        return arr

    def within_limits(self, q: np.ndarray, tolerance: float = 1e-9) -> bool:
        """Whether ``q`` lies within the position limits (± ``tolerance``)."""
        return bool(np.all(q >= self.lower - tolerance) and np.all(q <= self.upper + tolerance))

    def neutral(self) -> np.ndarray:
        """Zero configuration moved into the limits (the default IK seed)."""
        return np.clip(np.zeros(self.nq), self.lower, self.upper)

    def random_configuration(self, rng: np.random.Generator) -> np.ndarray:
        """A configuration drawn uniformly within the limits with the caller's generator."""
        return rng.uniform(self.lower, self.upper)

    # ------------------------------------------------------------------ kinematics
    def fk(self, q: Sequence[float] | np.ndarray) -> pin.SE3:
        """Tool pose in the base (world) frame: a new ``pin.SE3`` each call."""
        q = self.check_q(q)
        pin.forwardKinematics(self.model, self.data, q)
        return pin.SE3(pin.updateFramePlacement(self.model, self.data, self.tip_id))

    def tool_positions(self, q: Sequence[Sequence[float]] | np.ndarray) -> np.ndarray:
        """Tool positions [m] in the base frame for joint rows ``q`` (N, nq): shape (N, 3),
        one FK pass per row."""
        rows = np.asarray(q, dtype=float)
        if rows.ndim != 2 or rows.shape[1] != self.nq or not np.all(np.isfinite(rows)):
            raise InputError(
                f"joint rows must have shape (N, {self.nq}) and finite values for {self.name}, "
                f"got shape {rows.shape}"
            )
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

    def _planar_link_lengths(self) -> list[float] | None:
        """Link lengths [m] if the arm is planar (revolute about parallel z axes, links in the
        xy-plane of the first joint), else None."""
        model = self.model
        if any(model.joints[j].shortname() != "JointModelRZ" for j in range(1, model.njoints)):
            return None
        offsets = [model.jointPlacements[j] for j in range(2, model.njoints)]
        offsets.append(model.frames[self.tip_id].placement)
        lengths = []
        for placement in offsets:
            if not np.allclose(placement.rotation, np.eye(3), atol=1e-12):
                return None
            if abs(placement.translation[2]) > 1e-12:
                return None
            lengths.append(float(np.linalg.norm(placement.translation)))
        return lengths

    def planar_reach(self) -> tuple[float, float] | None:
        """Workspace annulus (r_min, r_max) [m] about the first joint, for planar arms.

        r_max is the sum of the link lengths; r_min is max(0, 2·l_longest − Σl). None for arms
        that are not planar.
        """
        if self.link_lengths is None:
            return None
        total = float(sum(self.link_lengths))
        return max(0.0, 2.0 * max(self.link_lengths) - total), total

    def task_rows(self, position_only: bool) -> np.ndarray:
        """Rows of the tool Jacobian the arm acts on ([0, 1] for a planar arm's position)."""
        return self._task[position_only][0]

    def task_rank(self, position_only: bool) -> int:
        """How many independent tool motions the arm has (2 for a planar arm's position)."""
        return self._task[position_only][1]

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
        rows, rank = self._task[position_only]
        return manipulability_of(self.jacobian(q)[rows], rank)

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

        Arms with a closed form (planar 2R, UR family, panda) get the solution nearest ``q_seed``
        directly. Others iterate from ``q_seed`` (default: :meth:`neutral`) and, when that
        attempt fails, restart from a deterministic low-discrepancy set of configurations. Starting
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
            InputError: malformed target or seed (wrong size, NaN, inf).
        """
        position, rotation = parse_target(target)
        if rotation is None or position_only:
            rotation = None
        seed = self.neutral() if q_seed is None else self.check_q(q_seed, "q_seed")
        closed_form = self.closed_form_ik
        if closed_form is not None and rotation is None and closed_form.needs_rotation:
            closed_form = None  # a position-only target: the numerical solver
        return self._ik.solve(
            position,
            rotation,
            seed,
            position_tolerance=position_tolerance,
            rotation_tolerance=rotation_tolerance,
            max_iterations=max_iterations,
            max_restarts=max_restarts,
            closed_form=closed_form,
        )

    @property
    def closed_form_ik(self):
        """The closed-form IK solver of this arm (planar 2R, UR family, panda), or None.

        Built on first use from the model's geometry and checked against its FK
        (:func:`kinplan.analytic_ik.analytic_solver_for`).
        """
        if not hasattr(self, "_closed_form"):
            from kinplan.analytic_ik import analytic_solver_for

            self._closed_form = analytic_solver_for(self)
        return self._closed_form


def manipulability_of(J: np.ndarray, rank: int) -> float | np.ndarray:
    """Product of the ``rank`` largest singular values of ``J`` (0 when rank is 0).

    When ``rank`` is the smaller dimension of J this is sqrt(det(J Jᵀ)) (wide or square J) or
    sqrt(det(Jᵀ J)) (tall J), computed from the smaller Gram matrix.

    Args:
        J: A Jacobian (r, c), or a stack of them (N, r, c).
        rank: Its rank at a generic configuration.

    Returns:
        A float for one Jacobian, an array (N,) for a stack.
    """
    rows, cols = J.shape[-2:]
    if rank == 0:
        value = np.zeros(J.shape[:-2])
    elif rank == min(rows, cols):
        J_t = np.swapaxes(J, -1, -2)
        gram = J @ J_t if rows <= cols else J_t @ J
        value = np.sqrt(np.maximum(np.linalg.det(gram), 0.0))
    else:
        value = np.prod(np.linalg.svd(J, compute_uv=False)[..., :rank], axis=-1)
    return float(value) if J.ndim == 2 else value


def jacobian_time_variation(J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """J̇ of serial-chain tool Jacobians from the Jacobians and joint velocities alone (stacked).

    For the world-aligned tool Jacobian of a chain of 1-dof revolute and prismatic joints, as
    :meth:`Robot.jacobian` gives it (columns base to tip; rows [linear v; angular w]), column i
    changes at the rate
        ẇ_i = ω_i × w_i,    v̇_i = ω_i × v_i + w_i × Σ_(j ≥ i) q̇_j v_j,
    with ω_i = Σ_(j < i) q̇_j w_j the angular velocity of the link that carries joint i (the tool
    point's velocity relative to joint i's axis is ω_i × r_i + Σ_(j ≥ i) q̇_j v_j, and the Jacobi
    identity folds the two terms with r_i into ω_i × v_i). This is what Pinocchio's
    ``getFrameJacobianTimeVariation`` gives in ``LOCAL_WORLD_ALIGNED``, computed for many
    samples at once with no kinematics pass.

    Args:
        J: Tool Jacobians, shape (..., 6, nq).
        qd: Joint velocities [rad/s or m/s], shape (..., nq).

    Returns:
        J̇, shape (..., 6, nq) (per second).
    """
    v, w = J[..., :3, :], J[..., 3:, :]
    w_qd = w * qd[..., None, :]
    omega = np.cumsum(w_qd, axis=-1) - w_qd  # Σ over the joints before each column
    v_qd = v * qd[..., None, :]
    sigma = np.cumsum(v_qd[..., ::-1], axis=-1)[..., ::-1]  # Σ over the column and after
    return np.concatenate(
        [_cross_rows(omega, v) + _cross_rows(w, sigma), _cross_rows(omega, w)], axis=-2
    )


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of the columns of two stacks of 3-row matrices (..., 3, n)."""
    a0, a1, a2 = a[..., 0, :], a[..., 1, :], a[..., 2, :]
    b0, b1, b2 = b[..., 0, :], b[..., 1, :], b[..., 2, :]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-2)


def parse_target(
    target: pin.SE3 | Sequence[float] | np.ndarray, what: str = "an IK target"
) -> tuple[np.ndarray, np.ndarray | None]:
    """Split a pose into (position [m], rotation 3×3, or None for a position 3-vector).

    Args:
        target: A ``pinocchio.SE3``, a 4×4 homogeneous matrix or a position 3-vector [m].
        what: How the value is named in error messages.

    Raises:
        InputError: another shape, a non-finite value, or a matrix that is not a rotation.
    """
    if isinstance(target, pin.SE3):
        matrix = target.homogeneous  # a fresh copy: the views below are the caller's to keep
    else:
        matrix = np.array(target, dtype=float)
        if matrix.shape == (3,):
            if not math.isfinite(matrix @ _ONES3):  # finite only when every term is
                raise InputError(f"{what} must be finite, got position {matrix}")
            return matrix, None
        if matrix.shape != (4, 4):
            raise InputError(
                f"{what} must be a pinocchio.SE3, a 4×4 homogeneous matrix or a position "
                f"3-vector [m]; got an array of shape {matrix.shape}"
            )
    # plain floats: cheaper than numpy for a 4×4
    (a, b, c, x), (d, e, f, y), (g, h, i, z), _ = matrix.tolist()
    if not math.isfinite(a + b + c + d + e + f + g + h + i + x + y + z):  # NaN or inf in a term
        raise InputError(f"{what} must be finite, got\n{matrix}")
    # ‖RᵀR − I‖_F² from the columns' lengths and mutual products
    defect = (a * a + d * d + g * g - 1.0) ** 2 + (b * b + e * e + h * h - 1.0) ** 2
    defect += (c * c + f * f + i * i - 1.0) ** 2
    defect += 2.0 * ((a * b + d * e + g * h) ** 2 + (a * c + d * f + g * i) ** 2)
    defect += 2.0 * (b * c + e * f + h * i) ** 2
    if defect > 1e-12:  # ‖RᵀR − I‖_F > 1e-6
        raise InputError(f"the rotation of {what} is not a rotation matrix (RᵀR ≠ I)")
    return matrix[:3, 3], matrix[:3, :3]


def load_robot(source: str | os.PathLike[str], tip: str | None = None) -> Robot:
    """Load a robot arm.

    Args:
        source: A bundled robot (``"planar_2r"``), an example-robot-data arm (``"ur3"``,
            ``"ur5"``, ``"ur10"``, ``"panda"``) or the path of a URDF file.
        tip: Tool frame (link or frame name). Default: ``tool0`` for UR arms, ``panda_hand_tcp``
            for the panda, ``tip`` for planar arms, otherwise the last link of the only chain.

    Raises:
        RobotNotFoundError: unknown name (the message lists the known ones) or missing file.
        URDFError: malformed XML, a URDF Pinocchio rejects, several chains without ``tip``, a
            floating or continuous joint on the chain.
        FrameError: ``tip`` is not a frame of the robot (the message lists the candidates).
    """
    return Robot(resolve_source(source), tip=tip)


def planar_arm(
    lengths: Sequence[float],
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
    """
    name = name or f"planar_{len(lengths)}r"
    text = planar_arm_urdf(
        lengths, name=name, lower=lower, upper=upper, velocity_limit=velocity_limit
    )
    path = write_planar_arm(text)
    return Robot(
        RobotSpec(name=name, urdf_path=path, package_dirs=(path.parent,), default_tip="tip")
    )
