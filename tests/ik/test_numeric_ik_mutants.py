"""The evaluation record of the numerical IK (IKSolver.evaluate, Evaluation.within) against
independent answers: the tolerance test against the Euclidean position error and the rotation
angle, and the Jacobian of a one-joint arm against the derivative of its tool position."""

from __future__ import annotations

import math

import numpy as np
import pytest

import kinplan
from kinplan.ik import IKSolver, frobenius_tolerance


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_within_tests_the_distance_along_every_axis_and_the_rotation_angle(axis):
    """A tool 3 mm off along one axis only (a zero offset on the others) meets a 4 mm
    tolerance and not a 2 mm one; a rotation 1 mrad off meets 2 mrad and not 0.5 mrad; the
    limits themselves are met."""
    arm = kinplan.planar_arm([0.5, 0.4, 0.3])
    solver = IKSolver(arm.model, arm.tip_id, arm.lower, arm.upper)
    q = np.array([0.3, -0.4, 0.2])
    pose = arm.fk(q)
    offset = np.zeros(3)
    offset[axis] = 3e-3
    rotation = pose.rotation.reshape(9).tolist()
    evaluation = solver.evaluate(q, (pose.translation + offset).tolist(), rotation)
    frobenius = frobenius_tolerance(1e-3)
    assert evaluation.within(4e-3**2, frobenius)
    assert not evaluation.within(2e-3**2, frobenius)
    distance2 = sum(d * d for d in evaluation.differences[:3])
    assert distance2 == pytest.approx(9e-6, rel=1e-9)
    assert evaluation.within(distance2, frobenius)  # the limit itself is met
    turned = pose.rotation @ np.array(
        [[math.cos(1e-3), -math.sin(1e-3), 0.0], [math.sin(1e-3), math.cos(1e-3), 0.0], [0, 0, 1]]
    )
    evaluation = solver.evaluate(q, pose.translation.tolist(), turned.reshape(9).tolist())
    assert evaluation.within(1e-12, frobenius_tolerance(2e-3))
    assert not evaluation.within(1e-12, frobenius_tolerance(5e-4))
    assert evaluation.within(1e-12, evaluation.differences[3])


def test_evaluate_of_a_one_joint_arm_gives_a_six_by_one_jacobian():
    arm = kinplan.planar_arm([0.7])
    solver = IKSolver(arm.model, arm.tip_id, arm.lower, arm.upper)
    q = np.array([0.4])
    evaluation = solver.evaluate(q, [0.0, 0.0, 0.0], None)
    assert evaluation.jacobian.shape == (6, 1)
    h = 1e-6
    rate = (arm.fk(q + h).translation - arm.fk(q - h).translation) / (2 * h)
    np.testing.assert_allclose(evaluation.jacobian[:3, 0], rate, atol=1e-9)
    np.testing.assert_allclose(evaluation.jacobian[3:, 0], [0.0, 0.0, 1.0], atol=1e-12)
    assert evaluation.differences[3] == 0.0  # position-only target
