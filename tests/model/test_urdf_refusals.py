"""Real URDFs that load or are refused truthfully (issue 26): undeclared XML prefixes (airo-models'
UR5e/UR3e write ``drake:acceleration`` without ``xmlns:drake``), velocity limits of 0 (PUMA 560,
AL5D, SolidWorks exports), zero axes, absurd offsets and base poses, locked values beyond the
limits, and the ``limits=`` overrides.

Each case is a copy of an example-robot-data URDF modified the same way, written into tmp_path.
Tolerances: FK 1e-12 m / 1e-12 against the unmodified file (the same model: only rounding could
differ) and 1e-9 against yourdfpy (an independent reader).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

import kinplan
from kinplan.errors import InputError, URDFError
from kinplan.model.sources import example_robot_data_dir
from kinplan.model.urdf_model import MAX_OFFSET

ROBOTS = example_robot_data_dir() / "example-robot-data" / "robots"
UR5 = ROBOTS / "ur_description/urdf/ur5_robot.urdf"
PANDA = ROBOTS / "panda_description/urdf/panda.urdf"
PENDULUM = ROBOTS / "double_pendulum_description/urdf/double_pendulum.urdf"
UR5_JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
#: airo-models' UR5e acceleration limits [rad/s²], one per joint (written as drake:acceleration)
ACCELERATIONS = (3.1, 3.2, 3.3, 6.1, 6.2, 6.3)


def edited(source: Path, tmp_path: Path, *replacements: tuple[str, str], count: int = 1) -> Path:
    """A copy of ``source`` in tmp_path with each (regex, replacement) applied ``count`` times
    (0: everywhere); each must match."""
    text = source.read_text()
    for pattern, replacement in replacements:
        text, n = re.subn(pattern, replacement, text, count=count, flags=re.S)
        assert n >= 1, pattern
    path = tmp_path / source.name
    path.write_text(text)
    return path


def joint_limit(joint: str, attribute: str, value: str) -> tuple[str, str]:
    """A replacement that sets ``attribute`` of ``joint``'s <limit> to ``value``."""
    return (rf'(<joint name="{joint}".*?<limit [^>]*?{attribute}=)"[^"]*"', rf'\1"{value}"')


def with_drake_accelerations(tmp_path: Path) -> Path:
    """UR5 with airo-models' ``drake:acceleration`` on every <limit>, ``xmlns:drake`` not
    declared (as in airo-models' ur5e.urdf)."""
    replacements = [
        (rf'(<joint name="{joint}".*?<limit [^>]*?)/>', rf'\1 drake:acceleration="{a}"/>')
        for joint, a in zip(UR5_JOINTS, ACCELERATIONS)
    ]
    path = edited(UR5, tmp_path, *replacements)
    assert "xmlns:drake" not in path.read_text()
    return path


def q_samples(robot: kinplan.Robot, count: int = 20) -> list[np.ndarray]:
    rng = np.random.default_rng(26)
    return [robot.random_configuration(rng) for _ in range(count)]


# ------------------------------------------------------------------ undeclared XML prefixes
def test_undeclared_drake_prefix_loads_with_its_acceleration_limits(tmp_path):
    path = with_drake_accelerations(tmp_path)
    robot = kinplan.load_robot(path, tip="tool0")
    plain = kinplan.load_robot("ur5")
    assert robot.joint_names == plain.joint_names
    # drake:acceleration is Drake's joint acceleration limit: read as such, exactly
    np.testing.assert_array_equal(robot.acceleration_limit, ACCELERATIONS)
    np.testing.assert_array_equal(robot.velocity_limit, plain.velocity_limit)
    np.testing.assert_array_equal(robot.lower, plain.lower)
    # the same kinematics as the file without the attributes, and as yourdfpy reads it
    reference = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    for q in q_samples(robot):
        np.testing.assert_allclose(robot.fk(q).homogeneous, plain.fk(q).homogeneous, atol=1e-12)
        reference.update_cfg(dict(zip(robot.joint_names, q)))
        expected = reference.get_transform(frame_to="tool0", frame_from=robot.base_frame)
        np.testing.assert_allclose(robot.fk(q).homogeneous, expected, atol=1e-9)
    # an override still wins
    faster = kinplan.load_robot(path, tip="tool0", limits={"elbow_joint": {"acceleration": 9.0}})
    assert faster.acceleration_limit[2] == 9.0 and faster.acceleration_limit[0] == 3.1


def test_declared_drake_prefix_reads_the_same(tmp_path):
    path = with_drake_accelerations(tmp_path)
    text = path.read_text().replace("<robot ", '<robot xmlns:drake="http://drake.mit.edu" ', 1)
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="tool0")
    np.testing.assert_array_equal(robot.acceleration_limit, ACCELERATIONS)


def test_robot_with_undeclared_prefix_gets_a_tool_and_a_cell(tmp_path):
    # with_tool writes the URDF again and the cell reads its geometry: both see the prefix
    robot = kinplan.load_robot(with_drake_accelerations(tmp_path), tip="tool0")
    tooled = robot.with_tool(pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1])))
    np.testing.assert_array_equal(tooled.acceleration_limit, ACCELERATIONS)
    cell = kinplan.WorkCell(robot)
    assert math.isfinite(cell.distance(np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])))


def test_other_undeclared_prefixes_load(tmp_path):
    path = edited(
        UR5,
        tmp_path,
        (r'<joint name="elbow_joint" type="revolute">', '<joint name="elbow_joint" type="revolute" '
         'gazebo:implicit="true"><sdf:note kind="x"/>'),
    )  # fmt: skip
    robot = kinplan.load_robot(path, tip="tool0")
    assert robot.nq == 6 and np.all(np.isinf(robot.acceleration_limit))


@pytest.mark.parametrize(
    ("replacement", "reason"),
    [
        # an undeclared prefix and another error: the other error is reported, at its place
        ((r"(<joint name=\"elbow_joint\")", r'<drake:x a="1">\1'), "mismatched tag: line"),
        ((r"<link name=\"forearm_link\">", '<link name="forearm_link" a="1" a="2">'),
         "duplicate attribute: line"),
        ((r"</robot>", ""), "no element found: line"),
        ((r"<link name=\"forearm_link\">", "<link name=\"forearm_link\"><<"),
         "not well-formed (invalid token): line"),
    ],
    ids=["prefix-and-unclosed", "duplicate-attribute", "truncated", "bad-token"],
)  # fmt: skip
def test_other_malformed_xml_is_still_refused_for_its_reason(tmp_path, replacement, reason):
    path = edited(UR5, tmp_path, replacement)
    with pytest.raises(URDFError, match=re.escape(f"is not valid XML ({reason}")) as raised:
        kinplan.load_robot(path, tip="tool0")
    assert "unbound prefix" not in str(raised.value) and "fix the file" in str(raised.value)


def test_error_behind_an_undeclared_prefix_is_reported_at_its_line(tmp_path):
    # the line expat reports when the prefix is declared by hand: the declaration kinplan adds
    # goes into the <robot> tag, so the line numbers stay the file's
    path = edited(UR5, tmp_path, (r"(<joint name=\"elbow_joint\")", r'<drake:x a="1">\1'))
    declared = path.read_text().replace("<robot ", '<robot xmlns:drake="urn:d" ', 1)
    with pytest.raises(ET.ParseError) as expected:
        ET.fromstring(declared)
    line = expected.value.position[0]
    with pytest.raises(URDFError, match=rf"mismatched tag: line {line}, column"):
        kinplan.load_robot(path, tip="tool0")


# ----------------------------------------------------------------------- velocity limit 0
def test_velocity_zero_is_refused_naming_the_joint_and_the_remedy(tmp_path):
    path = edited(UR5, tmp_path, joint_limit("elbow_joint", "velocity", "0"))
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(path, tip="tool0")
    message = str(raised.value)
    assert "elbow_joint (velocity 0)" in message
    assert "limits={'elbow_joint': {'velocity': ..}}" in message
    assert "locked_joints=" in message
    assert "shoulder" not in message  # only the joint at fault
    # both remedies work as printed
    given = kinplan.load_robot(path, tip="tool0", limits={"elbow_joint": {"velocity": 2.5}})
    assert given.velocity_limit[2] == 2.5 and given.velocity_limit[0] == 3.15
    locked = kinplan.load_robot(path, tip="tool0", locked_joints={"elbow_joint": 1.0})
    assert locked.nq == 5 and "elbow_joint" not in locked.joint_names
    # off the chain it does not matter: the arm up to the shoulder loads
    assert kinplan.load_robot(path, tip="upper_arm_link").nq == 2


def test_every_joint_with_velocity_zero_is_listed(tmp_path):
    # a PUMA 560 / AL5D file: every joint's velocity is 0
    path = edited(UR5, tmp_path, (r'velocity="[^"]*"', 'velocity="0.0"'), count=0)
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(path, tip="tool0")
    message = str(raised.value)
    for joint in UR5_JOINTS:
        assert f"{joint} (velocity 0.0)" in message
    limits = {joint: {"velocity": 1.0} for joint in UR5_JOINTS}
    assert f"limits={limits}".replace("1.0", "..") in message
    robot = kinplan.load_robot(path, tip="tool0", limits=limits)
    np.testing.assert_array_equal(robot.velocity_limit, np.ones(6))


def test_limit_without_velocity_is_refused(tmp_path):
    # urdfdom (Pinocchio's reader) refuses it too: "limit has no velocity"
    path = edited(UR5, tmp_path, (r'(<joint name="elbow_joint".*?<limit [^>]*?) velocity="[^"]*"',
                                  r"\1"))  # fmt: skip
    with pytest.raises(URDFError, match=r"elbow_joint \(no velocity in its <limit>\)"):
        kinplan.load_robot(path, tip="tool0")
    robot = kinplan.load_robot(path, tip="tool0", limits={"elbow_joint": {"velocity": 2.0}})
    assert robot.velocity_limit[2] == 2.0


def test_continuous_joint_without_limit_has_an_unknown_speed(tmp_path):
    # the URDF spec makes <limit> optional for a continuous joint: no speed is known (inf), as
    # documented; with a <limit velocity="0"> it is refused like any other joint
    unlimited = (r'(<joint name="wrist_3_joint") type="revolute"(.*?)<limit [^>]*/>',
                 r'\1 type="continuous"\2')  # fmt: skip
    path = edited(UR5, tmp_path, unlimited)
    robot = kinplan.load_robot(path, tip="tool0")
    assert robot.continuous_joints == ["wrist_3_joint"] and robot.velocity_limit[5] == np.inf
    zero = edited(UR5, tmp_path, (r'(<joint name="wrist_3_joint") type="revolute"(.*?<limit [^>]*?'
                                  r'velocity=)"[^"]*"', r'\1 type="continuous"\2"0"'))  # fmt: skip
    with pytest.raises(URDFError, match=r"wrist_3_joint \(velocity 0\)"):
        kinplan.load_robot(zero, tip="tool0")


@pytest.mark.parametrize("value", ["0", "-2", "abc"])
def test_drake_acceleration_that_is_no_limit_is_refused(tmp_path, value):
    path = edited(
        UR5,
        tmp_path,
        (r'(<joint name="wrist_1_joint".*?<limit [^>]*?)/>', rf'\1 drake:acceleration="{value}"/>'),
    )
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(path, tip="tool0")
    assert f"wrist_1_joint (drake:acceleration {value})" in str(raised.value)
    assert "limits={'wrist_1_joint': {'acceleration': ..}}" in str(raised.value)
    robot = kinplan.load_robot(path, tip="tool0", limits={"wrist_1_joint": {"acceleration": 4.0}})
    assert robot.acceleration_limit[3] == 4.0


# --------------------------------------------------------------------------- zero axis
def test_zero_axis_is_refused_naming_the_joint(tmp_path):
    path = edited(UR5, tmp_path, (r'(<joint name="elbow_joint".*?)<axis xyz="[^"]*"/>',
                                  r'\1<axis xyz="0 0 0"/>'))  # fmt: skip
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(path, tip="tool0")
    message = str(raised.value)
    assert "joint 'elbow_joint'" in message and "axis 0 0 0" in message
    assert "<axis xyz" in message
    # a lock does not make it move: still refused on the chain
    with pytest.raises(URDFError, match="axis 0 0 0"):
        kinplan.load_robot(path, tip="tool0", locked_joints={"elbow_joint": 0.5})
    # off the chain, nothing uses it
    assert kinplan.load_robot(path, tip="upper_arm_link").nq == 2


def test_zero_axis_of_a_prismatic_joint_is_refused(tmp_path):
    path = edited(PANDA, tmp_path, (r'(<joint name="panda_finger_joint1".*?)<axis xyz="[^"]*"/>',
                                    r'\1<axis xyz="0.0 0.0 0.0"/>'))  # fmt: skip
    with pytest.raises(URDFError, match="joint 'panda_finger_joint1' .* axis 0 0 0"):
        kinplan.load_robot(path, tip="panda_leftfinger")
    assert kinplan.load_robot(path, tip="panda_hand_tcp").nq == 7  # the finger is off the chain


# ------------------------------------------------------------------- offsets and base pose
@pytest.mark.parametrize("distance", [1e300, 2e4, MAX_OFFSET * (1 + 1e-9)])
def test_base_pose_beyond_the_bound_is_refused(distance):
    for pose in (
        pin.SE3(np.eye(3), np.array([distance, 0.0, 0.0])),
        np.block([[np.eye(3), np.array([[0.0], [distance], [0.0]])], [np.zeros((1, 3)), 1.0]]),
    ):
        with pytest.raises(InputError) as raised:
            kinplan.load_robot("ur5", base_pose=pose)
        message = str(raised.value)
        assert f"{distance:.4g} m from the world origin" in message
        assert "within 10000 m" in message


def test_base_pose_within_the_bound_loads():
    far = np.array([6000.0, -7000.0, 3000.0])  # 9.7 km
    assert np.linalg.norm(far) <= MAX_OFFSET
    robot = kinplan.load_robot("ur5", base_pose=pin.SE3(np.eye(3), far))
    plain = kinplan.load_robot("ur5")
    q = np.array([0.3, -1.2, 1.1, -0.4, 0.9, 0.2])
    # rounding at 10 km is ~2e-12 m: the placed pose is the plain one moved, to 1e-11 m
    np.testing.assert_allclose(robot.fk(q).translation, plain.fk(q).translation + far, atol=1e-11)


def test_non_finite_base_pose_is_refused():
    with pytest.raises(InputError, match="must be finite"):
        kinplan.load_robot("ur5", base_pose=np.array([[1, 0, 0, np.nan], [0, 1, 0, 0],
                                                       [0, 0, 1, 0], [0, 0, 0, 1.0]]))  # fmt: skip


@pytest.mark.parametrize("xyz", ["1e300 -0.1197 0.425", "0 2e4 0"])
def test_absurd_joint_origin_is_refused(tmp_path, xyz):
    path = edited(UR5, tmp_path, (r'(<joint name="elbow_joint".*?<origin [^>]*?xyz=)"[^"]*"',
                                  rf'\1"{xyz}"'))  # fmt: skip
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(path, tip="tool0")
    message = str(raised.value)
    assert "joint 'elbow_joint'" in message and "offsets up to 10000 m" in message


# ------------------------------------------------------------------------- locked joints
def test_locked_value_beyond_the_limits_is_refused_naming_them():
    with pytest.raises(InputError) as raised:
        kinplan.load_robot("ur5", locked_joints={"elbow_joint": 10})
    message = str(raised.value)
    assert "locked_joints['elbow_joint'] = 10 rad" in message
    assert "[-3.14159, 3.14159] rad" in message
    # the printed limits, pasted, are within the true ones (rounded inwards by %g? checked)
    lower, upper = (float(v) for v in re.search(r"\[(\S+), (\S+)\] rad", message).groups())
    robot = kinplan.load_robot("ur5", locked_joints={"elbow_joint": upper})
    assert robot.nq == 5
    kinplan.load_robot("ur5", locked_joints={"elbow_joint": lower})
    # at the limit exactly, and within a widened range
    kinplan.load_robot("ur5", locked_joints={"elbow_joint": math.pi - 1e-9})
    widened = {"elbow_joint": {"lower": -4.0, "upper": 4.0}}
    assert kinplan.load_robot("ur5", locked_joints={"elbow_joint": 3.5}, limits=widened).nq == 5
    with pytest.raises(InputError, match=r"\[-4, 4\] rad"):
        kinplan.load_robot("ur5", locked_joints={"elbow_joint": 4.5}, limits=widened)


def test_locked_prismatic_value_beyond_its_travel_is_refused_in_metres():
    tiago = ROBOTS / "tiago_description/robots/tiago.urdf"
    with pytest.raises(InputError, match=r"torso_lift_joint'\] = 0.5 m .* \[0, 0.35\] m"):
        kinplan.load_robot(tiago, tip="arm_tool_link", locked_joints={"torso_lift_joint": 0.5})
    kinplan.load_robot(tiago, tip="arm_tool_link", locked_joints={"torso_lift_joint": 0.35})


def test_locked_joint_without_usable_limits_takes_any_value():
    # the remedy of a joint without usable limits is to lock it: any value is fine
    robot = kinplan.load_robot(
        PENDULUM, locked_joints={"joint1": 0.7}, limits={"joint2": {"lower": -1.0, "upper": 1.0,
                                                                    "velocity": 2.0}},
    )  # fmt: skip
    assert robot.nq == 1 and robot.locked_joints == {"joint1": 0.7}
    # continuous joints too
    kinova = ROBOTS / "kinova_description/robots/kinova.urdf"
    plain = kinplan.load_robot(kinova)
    joint = plain.continuous_joints[0]
    assert kinplan.load_robot(kinova, locked_joints={joint: 40.0}).nq == plain.nq - 1


# ------------------------------------------------------------------- limits= overrides
@pytest.mark.parametrize(
    ("entry", "text"),
    [
        ({"lower": math.nan}, "must be a finite number"),
        ({"upper": math.inf}, "must be a finite number"),
        ({"velocity": math.inf}, "must be a finite number"),
        ({"lower": 1.0, "upper": 0.5}, "lower 1.0 must be below upper 0.5"),
        ({"lower": 0.5, "upper": 0.5}, "lower 0.5 must be below upper 0.5"),
        ({"velocity": 0.0}, "must be > 0"),
        ({"velocity": -1.0}, "must be > 0"),
        ({"acceleration": 0.0}, "must be > 0"),
        ({"acceleration": -3.0}, "must be > 0"),
        ({"acceleration": math.nan}, "must be a finite number"),
        ({"velocity": True}, "must be a number"),
    ],
)
def test_limit_overrides_that_are_no_limits_are_refused(entry, text):
    with pytest.raises(InputError, match=re.escape(text)):
        kinplan.load_robot("ur5", limits={"elbow_joint": entry})


@pytest.mark.parametrize("upper", [1e300, 2e4])
def test_prismatic_travel_beyond_the_bound_is_refused(upper):
    tiago = ROBOTS / "tiago_description/robots/tiago.urdf"
    with pytest.raises(URDFError) as raised:
        kinplan.load_robot(
            tiago, tip="arm_tool_link", limits={"torso_lift_joint": {"upper": upper}}
        )
    message = str(raised.value)
    assert f"torso_lift_joint (travel [0, {upper:g}] m beyond ±10000 m)" in message
    assert "limits={'torso_lift_joint': {'lower': .., 'upper': ..}}" in message
    robot = kinplan.load_robot(
        tiago, tip="arm_tool_link", limits={"torso_lift_joint": {"upper": 0.5}}
    )
    assert robot.upper[0] == 0.5


def test_one_sided_override_against_the_urdf_range_is_refused():
    with pytest.raises(URDFError, match=r"elbow_joint \(range \[4, 3.14159\]\)"):
        kinplan.load_robot("ur5", limits={"elbow_joint": {"lower": 4.0}})


def test_one_bound_on_a_continuous_joint_is_refused():
    kinova = ROBOTS / "kinova_description/robots/kinova.urdf"
    joint = kinplan.load_robot(kinova).continuous_joints[0]
    with pytest.raises(InputError, match="continuous joint .* give both 'lower' and 'upper'"):
        kinplan.load_robot(kinova, limits={joint: {"lower": -1.0}})
    bounded = kinplan.load_robot(kinova, limits={joint: {"lower": -1.0, "upper": 2.0}})
    k = bounded.joint_names.index(joint)
    assert (bounded.lower[k], bounded.upper[k]) == (-1.0, 2.0)
    assert joint not in bounded.continuous_joints


def test_mimic_relation_that_is_not_a_number_is_refused(tmp_path):
    mimic = '<mimic joint="shoulder_lift_joint" multiplier="abc"/>'
    path = edited(UR5, tmp_path, (r'(<joint name="elbow_joint".*?)<axis', rf"\1{mimic}<axis"))
    with pytest.raises(URDFError, match=r"joint 'elbow_joint': its <mimic multiplier='abc'>"):
        kinplan.load_robot(path, tip="tool0")
