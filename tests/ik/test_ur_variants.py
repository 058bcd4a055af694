"""UR-like URDF variants get the UR closed form and its fast paths (issue 29), recognised from
the screw axes (axes 2 ∥ 3 ∥ 4), not from names: prefixed joint and link names, e-Series
lengths, another tool frame, π/2 written rounded (as airo-models' UR5e)."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

import kinplan
from kinplan.ik import URIK

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
    elif kind == "welding_tool":
        torch = (
            '<link name="torch_tcp"/><joint name="torch_joint" type="fixed">'
            '<parent link="tool0"/><child link="torch_tcp"/>'
            '<origin xyz="0.02 -0.01 0.31" rpy="0.1 0.6 -0.3"/></joint></robot>'
        )
        text = text.replace("</robot>", torch)
        tip = "torch_tcp"
    return text, tip


@pytest.mark.parametrize("kind", ["prefixed", "e_series", "rounded", "welding_tool"])
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
