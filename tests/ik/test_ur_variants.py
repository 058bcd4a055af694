"""UR-like URDF variants get the UR closed form and its fast paths (issue 29), recognised from
the screw axes (axes 2 ∥ 3 ∥ 4), not from names: prefixed joint and link names, e-Series
lengths, another tool frame, π/2 written rounded (as airo-models' UR5e)."""

from __future__ import annotations

import re
from unittest.mock import patch

import numpy as np
import pinocchio as pin
import pytest
from ik_checks import contains, pose_errors

import kinplan
from kinplan.ik import URIK, near_wrist_kernel
from kinplan.ik.base import ClosedFormIK

#: UR5e lengths [m] put into the UR5 file: (UR5 text, UR5e text).
E_SERIES = [
    ('xyz="0.0 0.0 0.089159"', 'xyz="0.0 0.0 0.1625"'),
    ('xyz="0.0 -0.1197 0.425"', 'xyz="0.0 -0.1197 0.425"'),
    ('xyz="0.0 0.0 0.39225"', 'xyz="0.0 0.0 0.3922"'),
    ('xyz="0.0 0.093 0.0"', 'xyz="0.0 0.1333 0.0"'),
    ('xyz="0.0 0.0 0.09465"', 'xyz="0.0 0.0 0.0997"'),
    ('xyz="0.0 0.0823 0.0"', 'xyz="0.0 0.0996 0.0"'),
]


def variant(text: str, kind: str) -> tuple[str, str]:
    """(URDF text, tool frame) of one variant of the UR5 file."""
    tip = "tool0"
    if kind == "prefixed":
        text = re.sub(r'(name|link)="', r'\1="left_arm_', text)
        tip = "left_arm_tool0"
    elif kind == "e_series":
        for old, new in E_SERIES:
            assert old in text
            text = text.replace(old, new)
    elif kind == "rounded":
        text = text.replace("1.57079632679", "1.570796327")
    elif kind == "wrist_rounded":  # axis 6 4e-10 rad off perpendicular to axis 5, as airo's UR5e
        wrist = re.search(r'<joint name="wrist_3_joint".*?</joint>', text, flags=re.S)
        assert wrist is not None
        joint = wrist.group(0)
        text = text.replace(joint, joint.replace('rpy="0.0 0.0 0.0"', 'rpy="4e-10 0.0 0.0"'))
    elif kind == "welding_tool":
        torch = (
            '<link name="torch_tcp"/><joint name="torch_joint" type="fixed">'
            '<parent link="tool0"/><child link="torch_tcp"/>'
            '<origin xyz="0.02 -0.01 0.31" rpy="0.1 0.6 -0.3"/></joint></robot>'
        )
        text = text.replace("</robot>", torch)
        tip = "torch_tcp"
    return text, tip


@pytest.mark.parametrize(
    "kind", ["prefixed", "e_series", "rounded", "wrist_rounded", "welding_tool"]
)
def test_ur_variant_gets_the_fast_paths(tmp_path, kind):
    ur5 = kinplan.load_robot("ur5")
    text, tip = variant(ur5.urdf_path.read_text(), kind)
    path = tmp_path / f"ur5_{kind}.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip=tip)
    solver = robot.closed_form_ik
    assert isinstance(solver, URIK), robot.ik_solver.description
    assert solver._fast is not None, "the single-pose fast path"
    assert "UR family" in robot.ik_solver.description
    assert robot.batch_solver.method(False) == "closed-form"
    rng = np.random.default_rng(4)
    count = 200
    qs = np.array([robot.random_configuration(rng) for _ in range(count)])
    seeds = np.array([robot.random_configuration(rng) for _ in range(count)])
    targets = np.array([robot.fk(q).homogeneous for q in qs])
    loop = []
    for target, seed in zip(targets, seeds):
        result = robot.ik(pin.SE3(target), seed)
        assert result.success and result.method == "analytic"
        loop.append(result.q)
    _, _, _, left = solver.nearest_many(targets[:, :3, 3], targets[:, :3, :3], seeds)
    assert left.mean() < 0.05  # the array form of the fast path, not the all-branch path
    q, success = robot.ik_batch(targets, seeds)
    assert success.all()
    np.testing.assert_allclose(q, np.array(loop), atol=1e-9)


def test_rounded_ur_solutions_are_the_fast_path_polished(tmp_path):
    """Axes 4e-10 from orthonormal (airo's UR5e writes π/2 rounded one way on joint 5, the other
    on joint 6): ``solutions()`` lists the fast path's
    branches, each Newton-polished on the URDF's screws, instead of the vectorised path:
    over 300 random poses the same number of solutions, each of the vectorised path's within
    1e-5 rad of one (those miss the pose by up to ~1e-9 m: ill-conditioned near the wrist
    singularity), the generating configuration among them, and every polished solution at
    the target by Pinocchio's FK to 1e-12 m and rad; the vectorised path is taken only near
    singularities (at most 5 %)."""
    if not near_wrist_kernel.available():
        pytest.skip("numba switched off (KINPLAN_JIT=0): solutions() takes the vectorised path")
    ur5 = kinplan.load_robot("ur5")
    text, tip = variant(ur5.urdf_path.read_text(), "wrist_rounded")
    path = tmp_path / "ur5_wrist_rounded.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip=tip)
    solver = robot.closed_form_ik
    assert isinstance(solver, URIK) and not solver._fast_exact and solver._screws is not None
    rng = np.random.default_rng(6)
    vectorised = ClosedFormIK.solutions
    calls = []

    def counted(self, position, rotation):
        calls.append(1)
        return vectorised(self, position, rotation)

    with patch.object(ClosedFormIK, "solutions", counted):
        for _ in range(300):
            q = robot.random_configuration(rng)
            target = robot.fk(q)
            mine = solver.solutions(target.translation, target.rotation)
            theirs = vectorised(solver, target.translation, target.rotation)
            assert len(mine) == len(theirs)
            assert all(contains(mine, s, 1e-5) for s in theirs)
            assert contains(mine, q, 1e-7)
            for s in mine:
                position, rotation = pose_errors(robot, s, target)
                assert position <= 1e-12 and rotation <= 1e-12, (position, rotation)
    assert len(calls) <= 15, len(calls)
