"""kinplan over every arm URDF of example-robot-data and the hand-written URDFs of tests/urdf/.

Each arm of :data:`CASES` is loaded with the tool frame, locked joints, limits and base pose a
user would choose (the table says why), then checked:

* FK equals yourdfpy's (an independent URDF reader; mimic joints follow their master there
  too) with the locks and the base pose applied, to 1e-9 (metres and rotation-matrix entries),
  at random configurations;
* the tool Jacobian equals central finite differences of FK (step 1e-6) to 1e-6;
* IK succeeds (its default tolerances: 1e-6 m, 1e-6 rad) on ≥ 99.5 % of random reachable
  targets (FK of random configurations), each seeded from another random configuration; a
  failure is reported with its target;
* a short straight line (≤ 5 cm in 1 s) from a comfortable configuration is followed ``ok``;
* (slow run only) its playback page is written and stays within 10 MB.

The default run checks :data:`QUICK` (a fixed subset, fewer samples: a few seconds); the whole
corpus with 200 IK targets per arm runs with ``pytest -m slow`` (``make soak``, CI).
URDFs of example-robot-data that describe no arm are listed in :data:`NOT_ARMS` with the
reason, which is asserted; a new URDF in example-robot-data fails
:func:`test_every_example_robot_data_urdf_is_listed` until it is put in one of the tables.
"""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from conftest import TESTS

import cartesian
import kinplan
from kinplan import viewer
from kinplan.errors import FrameError, URDFError
from kinplan.model.sources import example_robot_data_dir

SHARE = example_robot_data_dir()
ROBOTS = SHARE / "example-robot-data" / "robots" if SHARE is not None else Path("missing")
HERE = TESTS / "urdf"

FK_TOLERANCE = 1e-9  # m, and entries of the rotation matrix
JACOBIAN_TOLERANCE = 1e-6  # m/rad or rad/rad, against central differences of step 1e-6
FD_STEP = 1e-6  # rad or m
IK_SUCCESS = 0.995  # share of the random reachable targets IK must reach
LINE_DURATION = 1.0  # s
LINE_LENGTH = (0.01, 0.05)  # m: 10 % of the tool's distance from the first joint, clipped
PAGE_BUDGET = 10_000_000  # bytes of a playback page (issue 13)


@dataclass(frozen=True)
class Case:
    """One arm: a URDF with the tool frame and settings a user would choose.

    Attributes:
        id: Test id.
        urdf: The file, relative to example-robot-data's ``robots/`` folder, or
            ``tests/urdf/<name>``.
        nq: Joints the arm plans with.
        reason: Why this tip and these settings.
        tip: Tool frame (None: kinplan's default).
        locked: Locked joints {name: value [rad or m]}.
        limits: Limit overrides.
        base_pose: (xyz [m], rpy [rad]) of the root in the world, or None.
        continuous: Expected continuous joints of the arm.
        mimic: Expected mimic joints of the arm.
        line_fails: Why no straight line can be followed (the tool's position task has rank
            1: it moves on a curve), else None.
    """

    id: str
    urdf: str
    nq: int
    reason: str
    tip: str | None = None
    locked: dict[str, float] = field(default_factory=dict)
    limits: dict[str, dict[str, float]] = field(default_factory=dict)
    base_pose: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    continuous: tuple[str, ...] = ()
    mimic: tuple[str, ...] = ()
    line_fails: str | None = None

    @property
    def path(self) -> Path:
        if self.urdf.startswith("tests/urdf/"):
            return HERE / self.urdf.removeprefix("tests/urdf/")
        return ROBOTS / self.urdf

    @property
    def pose(self) -> pin.SE3:
        if self.base_pose is None:
            return pin.SE3.Identity()
        xyz, rpy = self.base_pose
        return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz, dtype=float))


UR = "ur_description/urdf/"
TALOS = "talos_data/robots/"
TIAGO = "tiago_description/robots/"
TOOL0 = "tool0: the UR flange frame (REP-199); the gripper variants' gripper has no joints"
TIAGO_TORSO = {"torso_lift_joint": 0.15}
TIAGO_WHY = (
    "the torso lift (0.07 m/s or less) would make every line slow: locked at 0.15 m, the arm's 7 "
    "joints up to the tool flange arm_*tool_link"
)
TALOS_TORSO = {"torso_1_joint": 0.0, "torso_2_joint": 0.0}
TALOS_WHY = "one arm up to the gripper's base, the torso locked upright: a 7-dof arm"
PR2_WHY = (
    "the torso lift (0.013 m/s) locked at 0.1 m; the gripper's tool frame; forearm and wrist roll "
    "are continuous"
)
HUMANOID_WHY = "one arm of a humanoid, its waist or trunk locked: the arm's own joints"
PENDULUM_LIMITS = {
    "joint1": {"lower": -3.14, "upper": 3.14, "velocity": 5.0},
    "joint2": {"lower": -3.14, "upper": 3.14, "velocity": 5.0},
}
G1_WAIST = {"waist_yaw_joint": 0.0, "waist_roll_joint": 0.0, "waist_pitch_joint": 0.0}
ICUB_TORSO = {"torso_pitch": 0.0, "torso_roll": 0.0, "torso_yaw": 0.0}
ALEX_SPINE = {"SpineYaw": 0.0, "SpineRoll": 0.0, "SpinePitch": 0.0}
HUMAN_SPINE = {
    name: 0.0
    for name in (
        "middle_lumbar_Z",
        "middle_lumbar_X",
        "middle_thoracic_Z",
        "middle_thoracic_X",
        "middle_thoracic_Y",
    )
}
SIMPLE_WAIST = {"WAIST_P": 0.0, "WAIST_R": 0.0, "CHEST": 0.0}
KINOVA_CONTINUOUS = ("j2s6s200_joint_1", "j2s6s200_joint_4", "j2s6s200_joint_6")
ON_AXIS = (
    "its only tool frame, link2, lies on joint2's axis: joint2 does not move it, the tool moves "
    "on a circle and no straight line can be followed"
)

CASES: list[Case] = [
    # --- UR family: the flange frame tool0
    *(
        Case(f"{name}", f"{UR}{name}.urdf", 6, TOOL0, "tool0")
        for name in (
            "ur3_robot",
            "ur3_joint_limited_robot",
            "ur3_gripper",
            "ur5_robot",
            "ur5_joint_limited_robot",
            "ur5_gripper",
            "ur10_robot",
            "ur10_joint_limited_robot",
        )
    ),
    Case(
        "panda",
        "panda_description/urdf/panda.urdf",
        7,
        "the default tip: the TCP between the fingers (finger joints off the chain, at 0)",
    ),
    Case(
        "panda_collision",
        "panda_description/urdf/panda_collision.urdf",
        7,
        "as panda: the same arm with collision-only geometry",
    ),
    Case(
        "kinova",
        "kinova_description/robots/kinova.urdf",
        6,
        "the default tip, j2s6s200_end_effector; joints 1, 4 and 6 are continuous",
        continuous=KINOVA_CONTINUOUS,
    ),
    Case(
        "z1",
        "z1_description/urdf/z1.urdf",
        6,
        "the default tip: the gripper's fixed half, the gripper joint left out",
    ),
    Case("xarm7", "xarm_description/urdf/xarm7.urdf", 7, "the default tip: link_eef"),
    Case(
        "so100",
        "so_arm_description/urdf/so100.urdf",
        5,
        "tip 'gripper' names a link and a joint: the link (the jaw's joint left out)",
        "gripper",
    ),
    Case(
        "so101",
        "so_arm_description/urdf/so101.urdf",
        5,
        "the TCP frame between the jaws (the jaw joint 'gripper' left out)",
        "gripper_frame_link",
    ),
    *(
        Case(
            f"baxter_{side}",
            "baxter_description/urdf/baxter.urdf",
            7,
            f"Baxter's {side} arm up to its gripper frame (the head off the chain)",
            f"{side}_gripper",
        )
        for side in ("left", "right")
    ),
    Case("tiago", f"{TIAGO}tiago.urdf", 7, TIAGO_WHY, "arm_tool_link", TIAGO_TORSO),
    Case("tiago_no_hand", f"{TIAGO}tiago_no_hand.urdf", 7, TIAGO_WHY, "arm_tool_link", TIAGO_TORSO),
    *(
        Case(
            f"tiago_dual_{side}",
            f"{TIAGO}tiago_dual.urdf",
            7,
            TIAGO_WHY,
            f"arm_{side}_tool_link",
            TIAGO_TORSO,
        )
        for side in ("left", "right")
    ),
    *(
        Case(
            f"tiago_pro_{side}",
            "tiago_pro_description/robots/tiago_pro.urdf",
            7,
            TIAGO_WHY,
            f"arm_{side}_tool_link",
            TIAGO_TORSO,
        )
        for side in ("left", "right")
    ),
    Case(
        "talos_left_arm",
        f"{TALOS}talos_left_arm.urdf",
        6,
        "the file's default tip: the wrist's force-sensor tool frame (the file starts after the "
        "first shoulder joint)",
    ),
    *(
        Case(
            f"{name}_{side}",
            f"{TALOS}{name}.urdf",
            7,
            TALOS_WHY
            + (
                "; the gripper's mimic joints (master on a sibling branch) are held"
                if "full" in name
                else ""
            ),
            f"gripper_{side}_base_link",
            TALOS_TORSO,
        )
        for name in (
            "talos_reduced",
            "talos_reduced_box",
            "talos_reduced_corrected",
            "talos_full_v2",
            "talos_full_v2_box",
        )
        for side in ("left", "right")
    ),
    *(
        Case(
            f"pr2_{side}",
            "pr2_description/urdf/pr2.urdf",
            7,
            PR2_WHY,
            f"{side[0]}_gripper_tool_frame",
            {"torso_lift_joint": 0.1},
            continuous=(f"{side[0]}_forearm_roll_joint", f"{side[0]}_wrist_roll_joint"),
        )
        for side in ("left", "right")
    ),
    *(
        Case(
            f"g1_{side}",
            "g1_description/urdf/g1_29dof_rev_1_0.urdf",
            7,
            HUMANOID_WHY,
            f"{side}_rubber_hand",
            G1_WAIST,
        )
        for side in ("left", "right")
    ),
    Case(
        "g1_with_hand_left",
        "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
        7,
        HUMANOID_WHY + "; the palm, the fingers off the chain",
        "left_hand_palm_link",
        G1_WAIST,
    ),
    *(
        Case(
            f"{name}_{side}",
            f"icub_description/robots/{name}.urdf",
            7,
            HUMANOID_WHY,
            tip,
            ICUB_TORSO,
        )
        for name in ("icub", "icub_reduced")
        for side, tip in (("left", "l_hand"), ("right", "r_hand"))
    ),
    Case(
        "romeo_left",
        "romeo_description/urdf/romeo.urdf",
        7,
        HUMANOID_WHY + "; the fingers' mimic joints (master on a sibling branch) are held",
        "l_wrist",
        {"TrunkYaw": 0.0},
    ),
    Case(
        "romeo_small_right",
        "romeo_description/urdf/romeo_small.urdf",
        7,
        HUMANOID_WHY,
        "r_wrist",
        {"TrunkYaw": 0.0},
    ),
    Case(
        "romeo_laas_small_left",
        "romeo_description/urdf/romeo_laas_small.urdf",
        7,
        HUMANOID_WHY + "; its effector frame",
        "LArm_effector",
        {"TrunkYaw": 0.0},
    ),
    Case(
        "alex_nub_left",
        "alex_description/urdf/alex_nub_hands.urdf",
        7,
        HUMANOID_WHY + "; the nub at the end of the gripper-yaw joint",
        "leftNub",
        ALEX_SPINE,
    ),
    Case(
        "alex_sake_right",
        "alex_description/urdf/alex_sake_hands.urdf",
        7,
        HUMANOID_WHY + "; the palm of the Sake hand",
        "RightSakePalmLink",
        ALEX_SPINE,
    ),
    Case(
        "alex_psyonic_left",
        "alex_description/urdf/alex_psyonic_hands.urdf",
        7,
        HUMANOID_WHY + "; the hand's base (finger mimic joints with a missing master are held)",
        "LeftPsyonicAbilityBaseLink",
        ALEX_SPINE,
    ),
    Case(
        "centauro_left",
        "centauro_description/urdf/centauro.urdf",
        6,
        "Centauro's first arm up to its ball end, the torso yaw locked",
        "arm1_8",
        {"torso_yaw": 0.0},
    ),
    Case(
        "human_right",
        "human_description/robots/human.urdf",
        8,
        HUMANOID_WHY + "; clavicle, shoulder, elbow and wrist: 8 joints",
        "right_hand",
        HUMAN_SPINE,
    ),
    *(
        Case(
            f"{name}_{side}",
            f"simple_humanoid_description/urdf/{name}.urdf",
            7,
            HUMANOID_WHY,
            f"{side[0]}_wrist",
            SIMPLE_WAIST,
        )
        for name in ("simple_humanoid", "simple_humanoid_classical")
        for side in ("left", "right")
    ),
    Case(
        "anymal_kinova",
        "anymal_b_simple_description/robots/anymal-kinova.urdf",
        6,
        "the Kinova arm on ANYmal, up to its end effector (the legs off the chain)",
        "j2s6s200_end_effector",
    ),
    Case(
        "b1_z1",
        "b1_description/urdf/b1-z1.urdf",
        6,
        "the Z1 arm on the B1 quadruped, up to the gripper's fixed half; the body stands 0.5 m "
        "high, turned",
        "gripperStator",
        base_pose=((0.2, -0.1, 0.5), (0.0, 0.0, 0.6)),
    ),
    *(
        Case(
            name,
            f"double_pendulum_description/urdf/{name}.urdf",
            2,
            "its joints have lower = upper = 0: limits given (±3.14 rad, 5 rad/s)",
            limits=PENDULUM_LIMITS,
            line_fails=ON_AXIS if name == "double_pendulum" else None,
        )
        for name in ("double_pendulum", "double_pendulum_simple")
    ),
    Case(
        "double_pendulum_continuous",
        "double_pendulum_description/urdf/double_pendulum_continuous.urdf",
        2,
        "the default tip; both joints continuous, velocity 0 in the URDF: 5 rad/s given",
        limits={"joint1": {"velocity": 5.0}, "joint2": {"velocity": 5.0}},
        continuous=("joint1", "joint2"),
        line_fails=ON_AXIS,
    ),
    Case(
        "finger_edu",
        "finger_edu_description/robots/finger_edu.urdf",
        3,
        "the default tip: the finger's tip (a finger robot: its joints are the arm)",
    ),
    Case(
        "asr_twodof",
        "asr_twodof_description/urdf/TwoDofs.urdf",
        2,
        "the default tip: a planar 2R arm",
    ),
    Case(
        "borinot_flying_arm_2",
        "borinot_description/urdf/borinot_flying_arm_2.urdf",
        2,
        "the default tip: the end effector of the drone's arm (planar)",
    ),
    Case(
        "hextilt_flying_arm_5",
        "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
        5,
        "the default tip: the gripper link of the drone's arm",
    ),
    # --- hand-written URDFs
    Case(
        "continuous_arm",
        "tests/urdf/continuous_arm.urdf",
        6,
        "three continuous joints, one without <limit>",
        continuous=("shoulder_pan_joint", "wrist_1_joint", "wrist_3_joint"),
    ),
    Case(
        "mimic_arm",
        "tests/urdf/mimic_arm.urdf",
        6,
        "a coupled second elbow on the chain; gripper fingers (one mimics the other) off it",
        mimic=("joint_3_coupled",),
    ),
    Case(
        "prismatic_gantry",
        "tests/urdf/prismatic_gantry.urdf",
        6,
        "two prismatic joints (rail, lift) then four revolute ones",
    ),
    Case(
        "fixed_between", "tests/urdf/fixed_between.urdf", 6, "fixed rotated adapters between joints"
    ),
    Case("skewed_axes", "tests/urdf/skewed_axes.urdf", 6, "skewed axes, rotated joint origins"),
    Case(
        "floating_root",
        "tests/urdf/floating_root.urdf",
        6,
        "a floating root held at a base pose off the origin",
        base_pose=((0.5, -0.2, 0.3), (0.1, -0.2, 0.7)),
    ),
    Case(
        "planar_root",
        "tests/urdf/planar_root.urdf",
        6,
        "a planar root (mobile base) held at a base pose on the floor",
        base_pose=((1.5, 2.0, 0.0), (0.0, 0.0, -2.0)),
    ),
    Case(
        "two_arms_left",
        "tests/urdf/two_arms.urdf",
        7,
        "the left arm with the shared waist joint free: 7 joints",
        "left_tool0",
    ),
    Case(
        "two_arms_right",
        "tests/urdf/two_arms.urdf",
        6,
        "the right arm up to its gripper, the waist locked (turned 0.4 rad)",
        "right_gripper_base",
        {"waist": 0.4},
    ),
]

#: URDFs of example-robot-data that hold no arm: (file, reason, error of a default load, text
#: the error message holds).
LEGS = "legs only (a legged robot): several chains, no arm"
NOT_ARMS: list[tuple[str, str, type[Exception], str]] = [
    ("ur_description/urdf/ur3.urdf", "an empty xacro output", URDFError, "has no <link>"),
    (
        "hector_description/robots/quadrotor_base.urdf",
        "a drone body",
        URDFError,
        "no movable joint",
    ),
    ("iris_description/robots/iris_simple.urdf", "a drone body", URDFError, "no movable joint"),
    ("iris_description/robots/iris.urdf", "a drone: rotor joints", FrameError, "iris__rotor_0"),
    *(
        (f"allegro_hand_description/urdf/allegro_{side}_hand.urdf", "a hand", FrameError, "tip")
        for side in ("left", "right")
    ),
    ("a1_description/urdf/a1.urdf", LEGS, FrameError, "FL_foot"),
    ("alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf", LEGS, FrameError, "FOOT"),
    ("anymal_b_simple_description/robots/anymal.urdf", LEGS, FrameError, "LF_FOOT"),
    ("anymal_c_simple_description/urdf/anymal.urdf", LEGS, FrameError, "LF_FOOT"),
    ("b1_description/urdf/b1.urdf", LEGS, FrameError, "FL_foot"),
    ("bolt_description/robots/bolt.urdf", LEGS, FrameError, "FL_FOOT"),
    ("go1_description/urdf/go1.urdf", LEGS, FrameError, "FL_foot"),
    ("go2_description/urdf/go2.urdf", LEGS, FrameError, "FL_foot"),
    ("hyq_description/robots/hyq_no_sensors.urdf", LEGS, FrameError, "lf_foot"),
    ("laikago_description/urdf/laikago.urdf", LEGS, FrameError, "FL_foot"),
    ("quadruped_description/urdf/quadruped.urdf", LEGS, FrameError, "FL_contact"),
    ("solo_description/robots/solo.urdf", LEGS, FrameError, "FL_FOOT"),
    ("solo_description/robots/solo12.urdf", LEGS, FrameError, "FL_FOOT"),
]

#: The default run: a fixed subset that covers every loading feature.
QUICK = {
    "ur5_robot": "UR family, tool0",
    "panda": "default TCP, fingers off the chain",
    "kinova": "continuous joints",
    "z1": "default tip without the gripper joint",
    "so100": "a tip shared by a link and a joint",
    "tiago": "a locked torso, hand joints off the chain",
    "pr2_left": "continuous joints and a locked torso",
    "talos_full_v2_left": "mimic joints Pinocchio cannot couple, held",
    "b1_z1": "an arm on a legged base, at a base pose",
    "double_pendulum": "limit overrides; a tool on a joint axis",
    "finger_edu": "a finger robot (gripper-like joint names)",
    "mimic_arm": "a mimic joint on the chain",
    "prismatic_gantry": "prismatic joints",
    "skewed_axes": "skewed axes, IK across ±π limits",
    "floating_root": "a floating root at a base pose",
    "two_arms_right": "two arms on one torso, waist locked",
}


@dataclass(frozen=True)
class Sizes:
    """How many samples each check takes."""

    fk: int
    jacobian: int
    ik: int


QUICK_SIZES = Sizes(fk=10, jacobian=2, ik=50)
FULL_SIZES = Sizes(fk=50, jacobian=5, ik=200)
BY_ID = {case.id: case for case in CASES}


def _params():
    quick = [pytest.param(BY_ID[name], QUICK_SIZES, id=f"quick-{name}") for name in QUICK]
    full = [pytest.param(case, FULL_SIZES, id=case.id, marks=pytest.mark.slow) for case in CASES]
    return quick + full


PARAMS = _params()


def load(case: Case) -> kinplan.Robot:
    """The case's robot (loaded once per session)."""
    return _load(case.id)


@functools.cache
def _load(case_id: str) -> kinplan.Robot:
    case = BY_ID[case_id]
    return kinplan.load_robot(
        case.path,
        tip=case.tip,
        locked_joints=case.locked or None,
        limits=case.limits or None,
        base_pose=case.pose if case.base_pose is not None else None,
    )


@functools.cache
def _reference(urdf: str) -> yourdfpy.URDF:
    logging.getLogger("yourdfpy").setLevel(logging.ERROR)  # missing mimic masters are logged
    path = BY_ID[next(c.id for c in CASES if c.urdf == urdf)].path
    return yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)


def reference_pose(case: Case, robot: kinplan.Robot, q: np.ndarray) -> np.ndarray:
    """The tool pose (4×4) yourdfpy gives at ``q``: locked joints at their value, every other
    joint of the URDF at 0 (mimic joints follow their master), the root at the base pose."""
    urdf = _reference(case.urdf)
    cfg = dict.fromkeys(urdf.actuated_joint_names, 0.0)
    cfg.update(case.locked)
    cfg.update(zip(robot.joint_names, q))
    urdf.update_cfg(cfg)
    tool = urdf.get_transform(frame_to=robot.tip_frame, frame_from=robot.base_frame)
    return case.pose.homogeneous @ tool


def fk_error(case: Case, robot: kinplan.Robot, rng: np.random.Generator, count: int) -> float:
    """Largest |kinplan − yourdfpy| entry of the tool pose over ``count`` configurations."""
    worst = 0.0
    for _ in range(count):
        q = robot.random_configuration(rng)
        error = np.abs(robot.fk(q).homogeneous - reference_pose(case, robot, q)).max()
        worst = max(worst, float(error))
    return worst


def jacobian_error(robot: kinplan.Robot, rng: np.random.Generator, count: int) -> float:
    """Largest |J − J_fd| entry over ``count`` configurations (central differences of FK)."""
    worst = 0.0
    for _ in range(count):
        q = robot.random_configuration(rng)
        pose = robot.fk(q)
        J_fd = np.empty((6, robot.nq))
        for k in range(robot.nq):
            dq = np.zeros(robot.nq)
            dq[k] = FD_STEP
            plus, minus = robot.fk(q + dq), robot.fk(q - dq)
            J_fd[:3, k] = (plus.translation - minus.translation) / (2 * FD_STEP)
            J_fd[3:, k] = (
                pin.log3(plus.rotation @ pose.rotation.T)
                - pin.log3(minus.rotation @ pose.rotation.T)
            ) / (2 * FD_STEP)
        worst = max(worst, float(np.abs(robot.jacobian(q) - J_fd).max()))
    return worst


def ik_failures(robot: kinplan.Robot, rng: np.random.Generator, count: int) -> list[str]:
    """IK of ``count`` reachable targets (FK of random configurations), each seeded from
    another random configuration; the failures, described. Arms with fewer than 6 joints get
    position targets."""
    position_only = robot.default_position_only()
    failures = []
    for k in range(count):
        q_target = robot.random_configuration(rng)
        seed = robot.random_configuration(rng)
        pose = robot.fk(q_target)
        target = pose.translation if position_only else pose
        result = robot.ik(target, q_seed=seed, position_only=position_only)
        if not result.success:
            failures.append(
                f"#{k}: q_target {np.round(q_target, 4).tolist()} from seed "
                f"{np.round(seed, 4).tolist()}: errors {result.position_error:.2g} m, "
                f"{result.rotation_error:.2g} rad"
            )
    return failures


def comfortable(robot: kinplan.Robot, rng: np.random.Generator) -> np.ndarray:
    """The best-conditioned of 16 configurations drawn in the middle half of the joint ranges
    (continuous joints within ±π/2)."""
    lower = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)
    upper = np.where(np.isfinite(robot.upper), robot.upper, np.pi)
    middle, half = (lower + upper) / 2, (upper - lower) / 4
    candidates = middle + half * rng.uniform(-1.0, 1.0, size=(16, robot.nq))
    return max(candidates, key=robot.manipulability)


def follow_line(robot: kinplan.Robot, rng: np.random.Generator) -> cartesian.CartesianPlan:
    """A straight line of 1–5 cm (10 % of the tool's distance from the first joint) in 1 s from
    a comfortable configuration, along the direction the tool moves most easily (the first
    left singular vector of the position Jacobian), keeping the tool orientation when the arm
    has 6 joints or more."""
    q0 = comfortable(robot, rng)
    pose = robot.fk(q0)
    length = float(np.clip(0.1 * robot.shoulder_distance(pose.translation), *LINE_LENGTH))
    direction = np.linalg.svd(robot.jacobian(q0)[:3])[0][:, 0]
    end = pose.translation + length * direction
    if robot.default_position_only():
        line = cartesian.Line(pose.translation, end)
    else:
        line = cartesian.Line(pose, pin.SE3(pose.rotation, end))
    return cartesian.follow(robot, line, duration=LINE_DURATION, q_seed=q0)


def example_robot_data_urdfs() -> set[str]:
    return {str(path.relative_to(ROBOTS)) for path in ROBOTS.glob("*/*/*.urdf")}


# ---------------------------------------------------------------------------------- tables
def test_every_example_robot_data_urdf_is_listed():
    """Every URDF of example-robot-data is an arm case or a listed non-arm (with its reason)."""
    listed = {case.urdf for case in CASES} | {entry[0] for entry in NOT_ARMS}
    found = example_robot_data_urdfs()
    assert found, f"no URDF under {ROBOTS}"
    assert not found - listed, f"URDFs in no table: {sorted(found - listed)}"
    assert not (listed - found) - {c.urdf for c in CASES if c.urdf.startswith("tests/")}


def test_quick_subset_is_in_the_table():
    assert set(QUICK) <= set(BY_ID)
    assert len(BY_ID) == len(CASES), "case ids must be unique"


@pytest.mark.parametrize(
    "urdf, reason, error, text", NOT_ARMS, ids=[entry[0].split("/")[-1] for entry in NOT_ARMS]
)
def test_not_arms_are_refused_for_their_reason(urdf, reason, error, text):
    """A non-arm loads with no tip only to be refused: no joints, or several chains (legs,
    rotors, fingers) whose ends are listed."""
    with pytest.raises(error) as raised:
        kinplan.load_robot(ROBOTS / urdf)
    message = str(raised.value)
    assert text in message, (reason, message)
    if error is FrameError:
        assert "several kinematic chains" in message and "candidates" in message


# ---------------------------------------------------------------------------------- the arms
@pytest.mark.parametrize("case, sizes", PARAMS)
def test_loads_with_the_chosen_settings(case: Case, sizes: Sizes):
    robot = load(case)
    assert robot.nq == case.nq, (case.reason, robot.joint_names)
    assert robot.tip_frame == (case.tip or robot.tip_frame)
    assert sorted(robot.continuous_joints) == sorted(case.continuous)
    assert sorted(robot.mimic_joints) == sorted(case.mimic)
    assert set(robot.locked_joints) == set(case.locked)
    assert not set(robot.joint_names) & set(case.locked)
    unbounded = [n for n, lo in zip(robot.joint_names, robot.lower) if lo == -np.inf]
    assert sorted(unbounded) == sorted(case.continuous)


@pytest.mark.parametrize("case, sizes", PARAMS)
def test_fk_equals_yourdfpy(case: Case, sizes: Sizes):
    robot = load(case)
    error = fk_error(case, robot, np.random.default_rng(11), sizes.fk)
    assert error < FK_TOLERANCE, f"{case.id}: FK differs from yourdfpy's by {error:.3g}"


@pytest.mark.parametrize("case, sizes", PARAMS)
def test_jacobian_equals_finite_differences(case: Case, sizes: Sizes):
    robot = load(case)
    error = jacobian_error(robot, np.random.default_rng(12), sizes.jacobian)
    assert error < JACOBIAN_TOLERANCE, f"{case.id}: Jacobian off by {error:.3g}"


@pytest.mark.parametrize("case, sizes", PARAMS)
def test_ik_reaches_random_reachable_targets(case: Case, sizes: Sizes):
    robot = load(case)
    failures = ik_failures(robot, np.random.default_rng(13), sizes.ik)
    success = 1.0 - len(failures) / sizes.ik
    assert success >= IK_SUCCESS, (
        f"{case.id}: IK success {success:.1%} < {IK_SUCCESS:.1%}; failures:\n" + "\n".join(failures)
    )


@pytest.mark.parametrize("case, sizes", PARAMS)
def test_short_line_is_followed(case: Case, sizes: Sizes):
    robot = load(case)
    plan = follow_line(robot, np.random.default_rng(14))
    if case.line_fails is not None:
        assert robot.task_rank(position_only=True) == 1, case.line_fails
        assert not plan.ok and plan.fraction < 1.0, case.line_fails
        return
    assert plan.ok, f"{case.id}: {plan.status}: " + "; ".join(e.message for e in plan.events)
    assert plan.max_deviation < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=[case.id for case in CASES])
def test_playback_page_is_written_within_budget(case: Case, tmp_path):
    robot = load(case)
    plan = follow_line(robot, np.random.default_rng(14))
    path = viewer.save_html(robot, plan, tmp_path / f"{case.id}.html")
    assert path.stat().st_size <= PAGE_BUDGET, f"{case.id}: {path.stat().st_size / 1e6:.1f} MB"
