"""Loading real URDFs (issue 13): continuous and mimic joints, locked joints, limit overrides,
base poses, tool frames; against yourdfpy (an independent URDF reader), finite differences and
the full model.

Tolerances: FK 1e-12 m against the same model (only rounding differs) and 1e-9 against
yourdfpy; finite differences as stated at each test.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from conftest import TESTS

import cartesian
import kinplan
from kinplan.errors import FrameError, InputError, URDFError
from kinplan.model.sources import example_robot_data_dir

ROBOTS = example_robot_data_dir() / "example-robot-data" / "robots"
HERE = TESTS / "urdf"
TIAGO = ROBOTS / "tiago_description/robots/tiago.urdf"
PENDULUM = ROBOTS / "double_pendulum_description/urdf/double_pendulum.urdf"
SO100 = ROBOTS / "so_arm_description/urdf/so100.urdf"
UR5 = ROBOTS / "ur_description/urdf/ur5_robot.urdf"
TAU = 2.0 * math.pi


def reference(path: Path) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)


def reference_pose(urdf: yourdfpy.URDF, robot: kinplan.Robot, q, fixed=None) -> np.ndarray:
    """yourdfpy's tool pose (4×4) with the robot's joints at q, ``fixed`` joints at their value
    and every other actuated joint at 0 (mimic joints follow their master)."""
    cfg = dict.fromkeys(urdf.actuated_joint_names, 0.0)
    cfg.update(fixed or {})
    cfg.update(zip(robot.joint_names, q))
    urdf.update_cfg(cfg)
    return urdf.get_transform(frame_to=robot.tip_frame, frame_from=robot.base_frame)


def edited_urdf(source: Path, tmp_path: Path, *replacements: tuple[str, str]) -> Path:
    """A copy of ``source`` with each (regex, replacement) applied once."""
    text = source.read_text()
    for pattern, replacement in replacements:
        text, count = re.subn(pattern, replacement, text, count=1, flags=re.S)
        assert count == 1, pattern
    path = tmp_path / source.name
    path.write_text(text)
    return path


def fd_rates(values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Central differences d(values)/dt at the interior samples."""
    return (values[2:] - values[:-2]) / (t[2:] - t[:-2])[:, None]


# ------------------------------------------------------------------------ continuous joints
def test_continuous_joints_are_unbounded():
    robot = kinplan.load_robot(ROBOTS / "kinova_description/robots/kinova.urdf")
    assert robot.continuous_joints == ["j2s6s200_joint_1", "j2s6s200_joint_4", "j2s6s200_joint_6"]
    for k, name in enumerate(robot.joint_names):
        unbounded = name in robot.continuous_joints
        assert (robot.lower[k] == -np.inf and robot.upper[k] == np.inf) == unbounded
    q = robot.neutral()
    q[[0, 3, 5]] = [7.0, -9.0, 20.0]  # beyond ±2π: still within the (absent) limits
    assert robot.within_limits(q)


def test_continuous_joint_is_never_wrapped_along_a_follow_plan():
    """The tool turns about the last (continuous) joint's axis past ±π: the joint goes on."""
    robot = kinplan.load_robot(HERE / "continuous_arm.urdf")
    q0 = np.array([0.3, -1.2, 1.5, -1.8, -1.4, 2.9])
    start = robot.fk(q0)
    axis = robot.jacobian(q0)[3:, 5]  # the last joint's axis in the world frame
    end = pin.SE3(pin.exp3(0.6 * axis) @ start.rotation, start.translation + [0.01, 0.0, 0.0])
    plan = cartesian.follow(robot, cartesian.Line(start, end), duration=2.0, q_seed=q0)
    assert plan.ok, plan.events
    last = plan.q[:, 5]
    assert last[-1] > math.pi + 0.3  # past +π, not wrapped to −π
    assert np.abs(np.diff(plan.q, axis=0)).max() < 0.05  # no 2π jump anywhere (rad per sample)


def test_ik_returns_the_continuous_equivalent_nearest_the_seed():
    robot = kinplan.load_robot(HERE / "continuous_arm.urdf")
    q_target = np.array([0.4, -1.1, 1.4, -1.9, -1.3, 0.2])
    shift = np.array([2 * TAU, 0, 0, -TAU, 0, 3 * TAU])  # whole turns of the continuous joints
    seed = q_target + shift + 0.05
    result = robot.ik(robot.fk(q_target), q_seed=seed)
    assert result.success
    np.testing.assert_allclose(result.q, q_target + shift, atol=1e-5)


def test_continuous_ur_keeps_its_closed_form_and_the_seed_equivalent(tmp_path):
    """A UR5 whose shoulder pan is continuous: the closed form still solves it (no NaN from the
    infinite limits), nearest the seed, whole turns included."""
    path = edited_urdf(
        UR5,
        tmp_path,
        (r'(<joint name="shoulder_pan_joint" type=)"revolute"', r'\1"continuous"'),
    )
    robot = kinplan.load_robot(path, tip="tool0")
    assert robot.continuous_joints == ["shoulder_pan_joint"]
    assert robot.closed_form_ik is not None
    q_target = np.radians([20, -100, 100, -90, -90, 10])
    seed = q_target + np.array([TAU, 0, 0, 0, 0, 0]) + 0.02
    result = robot.ik(robot.fk(q_target), q_seed=seed)
    assert result.success and result.method == "analytic"
    np.testing.assert_allclose(result.q, q_target + [TAU, 0, 0, 0, 0, 0], atol=1e-9)


# ------------------------------------------------------------------------------ mimic joints
def test_mimic_joint_follows_its_master_like_yourdfpy():
    robot = kinplan.load_robot(HERE / "mimic_arm.urdf")
    assert robot.nq == 6 and "joint_3_coupled" not in robot.joint_names
    assert robot.mimic_joints == {"joint_3_coupled": ("joint_3", -0.5, 0.2)}
    urdf = reference(robot.urdf_path)
    rng = np.random.default_rng(1)
    for _ in range(20):
        q = robot.random_configuration(rng)
        np.testing.assert_allclose(
            robot.fk(q).homogeneous, reference_pose(urdf, robot, q), atol=1e-9
        )
    # the coupling matters: ignoring it (the coupled joint at 0) puts the tool elsewhere
    q = np.array([0.2, 0.3, 1.0, 0.1, 0.4, 0.0])
    urdf.update_cfg(dict(zip(robot.joint_names, q)))
    coupled = urdf.get_transform("link_3b", "link_3")
    np.testing.assert_allclose(pin.log3(coupled[:3, :3]), [0, -0.5 * 1.0 + 0.2, 0], atol=1e-12)


def test_mimic_arm_follow_plan_rates_are_the_derivatives_of_its_samples():
    """q̇ = dq/dt and q̈ = dq̇/dt by central differences (2nd order in dt = 2 ms; the quintic
    profile keeps q̈ smooth): within 1e-3 of the peak rate."""
    robot = kinplan.load_robot(HERE / "mimic_arm.urdf")
    q0 = np.array([0.3, 0.4, 0.9, 0.2, 0.6, 0.1])
    start = robot.fk(q0)
    end = pin.SE3(start.rotation, start.translation + [0.05, 0.04, -0.03])
    plan = cartesian.follow(
        robot, cartesian.Line(start, end), duration=1.5, dt=0.002, profile="quintic", q_seed=q0
    )
    assert plan.ok, plan.events
    assert plan.max_deviation < 1e-6
    qd_fd, qdd_fd = fd_rates(plan.q, plan.t), fd_rates(plan.qd, plan.t)
    assert np.abs(plan.qd[1:-1] - qd_fd).max() < 1e-3 * np.abs(plan.qd).max()
    assert np.abs(plan.qdd[1:-1] - qdd_fd).max() < 1e-3 * np.abs(plan.qdd).max()
    # and the tool really is on the line: FK by yourdfpy (which applies the mimic relation)
    urdf = reference(robot.urdf_path)
    for q in plan.q[:: len(plan.q) // 10]:
        tool = reference_pose(urdf, robot, q)[:3, 3] - start.translation
        along = end.translation - start.translation
        off = tool - along * (tool @ along) / (along @ along)
        assert np.linalg.norm(off) < 1e-6


def test_mimic_jacobian_time_variation_is_the_derivative_of_the_jacobian():
    robot = kinplan.load_robot(HERE / "mimic_arm.urdf")
    rng = np.random.default_rng(3)
    h = 1e-6
    for _ in range(5):
        q, qd = robot.random_configuration(rng), rng.normal(size=robot.nq)
        expected = (robot.jacobian(q + h * qd) - robot.jacobian(q - h * qd)) / (2 * h)
        got = robot.jacobian_time_variations(q[None], qd[None])[0]
        np.testing.assert_allclose(got, expected, atol=1e-6)


def test_mimic_joint_whose_master_comes_later_on_the_chain_is_refused(tmp_path):
    """Pinocchio couples a mimic joint to a master it reaches first; one on the tool chain
    whose master comes after it cannot be planned: the message says how to go on."""
    text = (HERE / "mimic_arm.urdf").read_text()
    text = text.replace(
        '<mimic joint="joint_3" multiplier="-0.5" offset="0.2"/>',
        '<mimic joint="joint_4" multiplier="-0.5" offset="0.2"/>',
    )
    path = tmp_path / "late_master.urdf"
    path.write_text(text)
    with pytest.raises(URDFError, match=r"mimics 'joint_4', which comes after it") as raised:
        kinplan.load_robot(path)
    assert "locked_joints" in str(raised.value)
    robot = kinplan.load_robot(path, locked_joints={"joint_3_coupled": 0.1})
    assert robot.nq == 6


def test_uncoupled_gripper_mimic_joints_off_the_chain_are_held():
    """Talos' gripper joints mimic a master on a sibling branch (Pinocchio cannot couple them):
    the arm loads, its FK is yourdfpy's."""
    path = ROBOTS / "talos_data/robots/talos_full_v2.urdf"
    locks = {"torso_1_joint": 0.0, "torso_2_joint": 0.0}
    robot = kinplan.load_robot(path, tip="gripper_left_base_link", locked_joints=locks)
    assert robot.nq == 7
    urdf = reference(path)
    q = robot.random_configuration(np.random.default_rng(4))
    np.testing.assert_allclose(
        robot.fk(q).homogeneous, reference_pose(urdf, robot, q, locks), atol=1e-9
    )


# ------------------------------------------------------------------ IK where restarts fail
def test_ik_polishes_a_near_singular_target_the_damped_steps_leave_short():
    """Talos' arm at a configuration 5e-5 from singular (smallest singular value of J): the
    damped attempts stop 1.7e-5 m short; the undamped polish of the best one converges."""
    robot = kinplan.load_robot(ROBOTS / "talos_data/robots/talos_left_arm.urdf")
    q_target = np.array([1.9184, -0.1088, -0.177, -1.9936, -0.2453, 0.4317])
    seed = np.array([1.9583, 0.2135, -0.7235, -2.4944, 0.5865, 0.0201])
    assert np.linalg.svd(robot.jacobian(q_target), compute_uv=False)[-1] < 1e-4
    target = robot.fk(q_target)
    # the numerical solver itself (the arm's axes fit the 1-D search closed form, which ik uses)
    solve = robot.ik_solver.solve
    result = solve(target.translation, target.rotation, seed)
    assert result.success and result.attempts == 42  # the seed, 40 restarts, the polish
    np.testing.assert_allclose(robot.fk(result.q).translation, target.translation, atol=1e-6)
    assert not solve(target.translation, target.rotation, seed, max_restarts=0).success  # short
    assert robot.ik(target, q_seed=seed).success


def test_ik_turns_revolute_joints_into_their_limits_by_whole_turns():
    """Joints limited to ±π about skewed axes: from this seed, an attempt has to take a joint
    across ±π. Stopped at the limit it stalls; turned by a whole turn into the limits (the same
    tool pose) it converges at once, as every attempt of an IK solve does."""
    robot = kinplan.load_robot(HERE / "skewed_axes.urdf")
    q_target = np.array([2.6136, -1.6763, 2.3041, -1.7084, 1.4251, 1.8225])
    seed = np.array([-0.9519, -0.2149, 2.4377, -1.8321, -2.9224, 1.7718])
    target = robot.fk(q_target)
    solver = kinplan.ik.IKSolver(robot.model, robot.tip_id, robot.lower, robot.upper)
    clamped = solver.descend(seed, target.translation, target.rotation, 1e-6, 1e-6, 40)
    turned = solver.descend(seed, target.translation, target.rotation, 1e-6, 1e-6, 40, turn=True)
    assert not clamped[1] and clamped[2] > 0.1  # stalls 0.26 m away
    assert turned[1] and robot.within_limits(turned[0], tolerance=0.0)
    result = robot.ik(target, q_seed=seed)
    assert result.success and result.attempts == 1
    assert robot.within_limits(result.q, tolerance=0.0)
    np.testing.assert_allclose(robot.fk(result.q).homogeneous, target.homogeneous, atol=1e-6)
    np.testing.assert_allclose(result.q, turned[0], rtol=0, atol=1e-9)  # compiled: a rounding


# ---------------------------------------------------------------------------- locked joints
def test_locked_joint_fk_equals_the_full_model_at_the_locked_value():
    full = kinplan.load_robot(TIAGO, tip="arm_tool_link")
    locked = kinplan.load_robot(TIAGO, tip="arm_tool_link", locked_joints={"torso_lift_joint": 0.2})
    assert full.joint_names[0] == "torso_lift_joint" and full.nq == 8
    assert locked.nq == 7 and locked.joint_names == full.joint_names[1:]
    assert locked.locked_joints == {"torso_lift_joint": 0.2}
    rng = np.random.default_rng(5)
    for _ in range(10):
        q = locked.random_configuration(rng)
        np.testing.assert_allclose(
            locked.fk(q).homogeneous, full.fk(np.r_[0.2, q]).homogeneous, atol=1e-12
        )
        np.testing.assert_allclose(locked.jacobian(q), full.jacobian(np.r_[0.2, q])[:, 1:])


def test_locked_joint_errors_name_the_joints():
    with pytest.raises(InputError, match="no joint 'torso'.*torso_lift_joint"):
        kinplan.load_robot(TIAGO, tip="arm_tool_link", locked_joints={"torso": 0.1})
    with pytest.raises(InputError, match="floating or planar root joint is held at base_pose"):
        kinplan.load_robot(HERE / "floating_root.urdf", locked_joints={"root_joint": 0.0})
    with pytest.raises(InputError, match="locked_joints must be a dict"):
        kinplan.load_robot(TIAGO, tip="arm_tool_link", locked_joints=["torso_lift_joint"])
    with pytest.raises(URDFError, match="every joint of the chain is locked"):
        kinplan.load_robot(PENDULUM, locked_joints={"joint1": 0.0, "joint2": 0.0})


# ------------------------------------------------------------------------- limit overrides
def test_revolute_joint_without_limit_loads_with_limits(tmp_path):
    path = edited_urdf(
        UR5,
        tmp_path,
        (r'(<joint name="elbow_joint" type="revolute">.*?)<limit [^>]*/>', r"\1"),
    )
    with pytest.raises(URDFError, match="elbow_joint .*have no <limit>") as raised:
        kinplan.load_robot(path, tip="tool0")
    assert "limits=" in str(raised.value) and "locked_joints=" in str(raised.value)
    limits = {"elbow_joint": {"lower": -3.0, "upper": 3.0, "velocity": 2.0, "acceleration": 8.0}}
    robot = kinplan.load_robot(path, tip="tool0", limits=limits)
    k = robot.joint_names.index("elbow_joint")
    assert (robot.lower[k], robot.upper[k], robot.velocity_limit[k]) == (-3.0, 3.0, 2.0)
    assert robot.acceleration_limit[k] == 8.0
    assert np.all(np.isinf(np.delete(robot.acceleration_limit, k)))


def test_zero_range_joints_name_the_remedy_and_load_with_limits():
    # the pendulum's URDF says lower = upper = 0 and velocity = 0 (an exporter's "unknown")
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(PENDULUM)
    message = str(raised.value)
    assert "joint1 (range [0, 0], velocity 0)" in message
    assert "joint2 (range [0, 0], velocity 0)" in message
    assert "locked_joints={" in message
    # the remedy names every key still missing, for every joint: applied as printed, it loads
    keys = "{'lower': .., 'upper': .., 'velocity': ..}"
    assert f"limits={{'joint1': {keys}, 'joint2': {keys}}}" in message
    with pytest.raises(URDFError, match=r"joint1 \(velocity 0\); joint2 \(velocity 0\)"):
        kinplan.load_robot(
            PENDULUM, limits={n: {"lower": -2.0, "upper": 2.5} for n in ("joint1", "joint2")}
        )
    limits = {name: {"lower": -2.0, "upper": 2.5, "velocity": 3.0} for name in ("joint1", "joint2")}
    robot = kinplan.load_robot(PENDULUM, limits=limits)
    np.testing.assert_array_equal(robot.lower, [-2.0, -2.0])
    np.testing.assert_array_equal(robot.upper, [2.5, 2.5])
    np.testing.assert_array_equal(robot.velocity_limit, [3.0, 3.0])


def test_limit_overrides_replace_the_urdf_values_and_are_checked():
    robot = kinplan.load_robot("ur5", limits={"wrist_3_joint": {"velocity": 0.5}})
    base = kinplan.load_robot("ur5")
    assert robot.velocity_limit[5] == 0.5 and robot.lower[5] == base.lower[5]
    assert np.all(np.isinf(robot.acceleration_limit))
    with pytest.raises(InputError, match="unknown key 'speed'"):
        kinplan.load_robot("ur5", limits={"wrist_3_joint": {"speed": 0.5}})
    with pytest.raises(InputError, match="lower 1.0 must be below upper 0.5"):
        kinplan.load_robot("ur5", limits={"wrist_3_joint": {"lower": 1.0, "upper": 0.5}})
    with pytest.raises(InputError, match="no joint 'wrist_4_joint'"):
        kinplan.load_robot("ur5", limits={"wrist_4_joint": {"velocity": 1.0}})


# ------------------------------------------------------------------------------ base pose
def test_base_pose_moves_every_pose_into_the_world():
    base = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.8), np.array([0.5, -1.0, 0.3]))
    placed = kinplan.load_robot("ur5", base_pose=base)
    plain = kinplan.load_robot("ur5")
    rotate = np.kron(np.eye(2), base.rotation)  # [linear; angular] rows both rotate
    rng = np.random.default_rng(6)
    for _ in range(10):
        q = plain.random_configuration(rng)
        np.testing.assert_allclose(
            placed.fk(q).homogeneous, (base * plain.fk(q)).homogeneous, atol=1e-12
        )
        np.testing.assert_allclose(placed.jacobian(q), rotate @ plain.jacobian(q), atol=1e-12)
    target = base * plain.fk(np.radians([10, -100, 90, -80, -90, 30]))
    result = placed.ik(target)
    assert result.success
    np.testing.assert_allclose(placed.fk(result.q).homogeneous, target.homogeneous, atol=1e-6)


def test_floating_and_planar_roots_are_held_at_the_base_pose():
    base = pin.SE3(pin.rpy.rpyToMatrix(0.0, 0.0, 1.2), np.array([2.0, 1.0, 0.0]))
    for name, joint in (("floating_root", "root_joint"), ("planar_root", "base_joint")):
        robot = kinplan.load_robot(HERE / f"{name}.urdf", base_pose=base)
        assert robot.held_root == joint and robot.nq == 6
        urdf = reference(robot.urdf_path)
        q = robot.random_configuration(np.random.default_rng(7))
        expected = base.homogeneous @ reference_pose(urdf, robot, q)
        np.testing.assert_allclose(robot.fk(q).homogeneous, expected, atol=1e-9)


# ------------------------------------------------------------------------------ tool frames
def test_tip_shared_by_a_link_and_a_joint_is_the_link():
    """so100 has a link and a joint named 'gripper': tip='gripper' is the link."""
    robot = kinplan.load_robot(SO100, tip="gripper")
    assert robot.tip_frame == "gripper" and robot.nq == 5
    assert "gripper" not in robot.joint_names  # the jaw joint hangs below the link
    urdf = reference(SO100)
    q = robot.random_configuration(np.random.default_rng(8))
    np.testing.assert_allclose(robot.fk(q).homogeneous, reference_pose(urdf, robot, q), atol=1e-9)


def test_unknown_tip_lists_the_candidate_tool_frames():
    with pytest.raises(FrameError) as raised:
        kinplan.load_robot(TIAGO, tip="tool_link")
    message = str(raised.value)
    assert "no frame 'tool_link'" in message and "arm_tool_link" in message
    assert "--frames" in message
    assert "hand_index" not in message  # fingertips are no candidates
    with pytest.raises(FrameError, match="several kinematic chains") as raised:
        kinplan.load_robot(HERE / "two_arms.urdf")
    assert "left_tool0" in str(raised.value) and "right_tool0" in str(raised.value)
    assert "finger" not in str(raised.value)


@pytest.mark.parametrize(
    "urdf, tip, nq, gripper",
    [
        ("z1_description/urdf/z1.urdf", "gripperStator", 6, "jointGripper"),
        ("so_arm_description/urdf/so101.urdf", "gripper_link", 5, "gripper"),
        ("panda_description/urdf/panda.urdf", "panda_hand_tcp", 7, "panda_finger_joint1"),
        ("kinova_description/robots/kinova.urdf", "j2s6s200_end_effector", 6, None),
    ],
)
def test_default_tip_leaves_the_gripper_out(urdf, tip, nq, gripper):
    robot = kinplan.load_robot(ROBOTS / urdf)
    assert (robot.tip_frame, robot.nq) == (tip, nq)
    assert gripper not in robot.joint_names


def test_finger_robot_keeps_its_finger_joints():
    robot = kinplan.load_robot(ROBOTS / "finger_edu_description/robots/finger_edu.urdf")
    assert robot.nq == 3 and robot.tip_frame == "finger_tip_link"


def test_empty_urdf_says_so():
    with pytest.raises(URDFError, match="has no <link>"):
        kinplan.load_robot(ROBOTS / "ur_description/urdf/ur3.urdf")


# ------------------------------------------------------------------------------ package dirs
def test_package_dirs_come_first_and_are_checked(tmp_path):
    robot = kinplan.load_robot("ur5", package_dirs=[tmp_path])
    assert robot.package_dirs[0] == tmp_path
    with pytest.raises(InputError, match="package_dirs"):
        kinplan.load_robot("ur5", package_dirs=3)
