"""Every bad input gets a KinplanError subclass whose message says what was wrong and what to do."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import kinplan
from kinplan.errors import FrameError, InputError, RobotNotFoundError, URDFError

TWO_CHAINS = """<?xml version="1.0"?>
<robot name="two_chains">
  <link name="base"/><link name="a"/><link name="b"/>
  <joint name="ja" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="jb" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
    <origin xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>
"""

FLOATING = """<?xml version="1.0"?>
<robot name="floating">
  <link name="world"/><link name="body"/><link name="arm"/>
  <joint name="free" type="floating"><parent link="world"/><child link="body"/></joint>
  <joint name="j1" type="revolute"><parent link="body"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>
"""


def write(tmp_path, text, name="robot.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_all_errors_derive_from_kinplan_error():
    for cls in (FrameError, InputError, RobotNotFoundError, URDFError, kinplan.InfeasibleError):
        assert issubclass(cls, kinplan.KinplanError)


def test_unknown_name_lists_known_robots():
    with pytest.raises(RobotNotFoundError, match="known robots: .*planar_2r.*ur5.*panda"):
        kinplan.load_robot("ur42")


def test_missing_file(tmp_path):
    with pytest.raises(RobotNotFoundError, match="does not exist"):
        kinplan.load_robot(tmp_path / "nothing.urdf")


def test_malformed_xml(tmp_path):
    path = write(tmp_path, "<robot name='x'><link name='a'></robot>")
    with pytest.raises(URDFError, match="not valid XML"):
        kinplan.load_robot(path)


def test_not_a_urdf(tmp_path):
    with pytest.raises(URDFError, match="not a URDF"):
        kinplan.load_robot(write(tmp_path, "<sdf version='1.6'/>"))


def test_several_chains_need_a_tip(tmp_path):
    path = write(tmp_path, TWO_CHAINS)
    with pytest.raises(FrameError, match="several kinematic chains.*tip=.*candidates: a, b"):
        kinplan.load_robot(path)
    robot = kinplan.load_robot(path, tip="b")
    assert robot.nq == 1 and robot.joint_names == ["jb"]


def test_floating_root_is_held_at_the_base_pose(tmp_path):
    """A floating root joint (a mobile base, a humanoid) is not in q: held at base_pose."""
    robot = kinplan.load_robot(write(tmp_path, FLOATING), tip="arm")
    assert robot.nq == 1 and robot.joint_names == ["j1"] and robot.held_root == "free"
    moved = kinplan.load_robot(
        write(tmp_path, FLOATING), tip="arm", base_pose=pin.SE3(np.eye(3), np.array([1, 2, 3]))
    )
    np.testing.assert_allclose(
        moved.fk([0.3]).translation, robot.fk([0.3]).translation + [1, 2, 3], atol=1e-15
    )


def test_unknown_tip_lists_frames():
    with pytest.raises(FrameError, match="no frame 'gripper'.*tool0"):
        kinplan.load_robot("ur5", tip="gripper")


@pytest.mark.parametrize(
    "q, message",
    [
        (np.zeros(5), "must hold 6 joint values"),
        (np.zeros((6, 1)), "must hold 6 joint values"),
        (np.array([0, 0, np.nan, 0, 0, 0]), "finite"),
        (np.array([0, 0, np.inf, 0, 0, 0]), "finite"),
    ],
)
def test_bad_joint_vectors(ur5, q, message):
    for method in (ur5.fk, ur5.jacobian, ur5.manipulability):
        with pytest.raises(InputError, match=message):
            method(q)
    with pytest.raises(InputError, match=message):
        ur5.ik(ur5.fk(np.zeros(6)), q_seed=q)


def test_bad_ik_targets(ur5):
    with pytest.raises(InputError, match="3-vector"):
        ur5.ik(np.zeros(4))
    with pytest.raises(InputError, match="finite"):
        ur5.ik(np.array([0.1, np.nan, 0.2]))
    with pytest.raises(InputError, match="not a rotation"):
        ur5.ik(np.eye(4) * 2)


def test_bad_planar_lengths():
    with pytest.raises(InputError, match="> 0"):
        kinplan.planar_arm([1.0, -0.5])
    with pytest.raises(InputError, match="link lengths"):
        kinplan.planar_arm([])
