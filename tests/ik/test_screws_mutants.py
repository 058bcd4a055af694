"""The joint choice shared by the closed forms (kinplan.ik.screws) against independent answers:
the single-value near_angle against the vectorised wrap_near of the batch path (random values,
exact and near ties at half a turn, values a rounding error beyond a limit), the vectorised
joint_choice_many against joint_choice on values with several branch axes and weights, and the
screw reading of a model against a joint that is not a revolute screw."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import TESTS, cached_robot

import kinplan
from kinplan.ik.screws import (
    LIMIT_TOL,
    TAU,
    joint_choice,
    joint_choice_many,
    near_angle,
    plane_basis,
    screws_at_zero,
    wrap_near,
)

URDF = TESTS / "urdf"


def _cases(rng: np.random.Generator, count: int, lower: float, upper: float):
    """(values, references within the limits): random, exact half-turn ties, near ties, and
    values a rounding error beyond a limit (plus whole turns)."""
    ref = rng.uniform(lower, upper, count) if np.isfinite(lower) else rng.uniform(-9, 9, count)
    values = rng.uniform(-12.0, 12.0, count)
    turns = TAU * rng.integers(-2, 3, count)
    values[:100] = ref[:100] + np.pi + turns[:100]
    values[100:200] = ref[100:200] - np.pi + turns[100:200]
    values[200:300] = ref[200:300] + np.pi - rng.choice([1e-10, 5e-10, 2e-9], 100) + turns[200:300]
    values[300:320] = np.pi / 2 + turns[300:320]  # c + ref = 0 at the tie
    ref[300:320] = -np.pi / 2
    if np.isfinite(lower):
        edge = rng.choice([-1.0, 1.0], 100) * rng.choice([0.0, 0.5 * LIMIT_TOL, 3e-12], 100)
        values[400:450] = lower + edge[:50] + turns[400:450]
        values[450:500] = upper + edge[50:] + turns[450:500]
    return values, ref


@pytest.mark.parametrize(
    ("lower", "upper"),
    [(-2 * np.pi, 2 * np.pi), (-np.pi, np.pi), (-2.9, 2.9), (-0.07, 3.75), (-9.0, 9.0)],
)
def test_near_angle_is_wrap_near_value_by_value(lower, upper):
    """The equivalent within the limits nearest the reference (ties at half a turn to the
    first of k − 1, k, k + 1), clipped onto a limit it exceeds by at most LIMIT_TOL, or none:
    the same as the batch path's wrap_near, to the last bit."""
    rng = np.random.default_rng(60)
    values, ref = _cases(rng, 1000, lower, upper)
    lo, hi = np.array([lower]), np.array([upper])
    batch = wrap_near(values[:, None], ref[:, None], lo, hi)[:, 0]
    for k in range(len(values)):
        single = near_angle(float(values[k]), float(ref[k]), lower, upper)
        if single is None:
            assert np.isnan(batch[k]), k
        else:
            assert single == batch[k], (k, values[k], ref[k], single, batch[k])
            assert lower <= single <= upper
    assert np.isnan(batch).sum() < len(values)
    # nearest: no other equivalent within the limits is nearer the reference
    found = np.flatnonzero(~np.isnan(batch))
    for shift in (-TAU, TAU):
        other = batch[found] + shift
        inside = (other >= lower) & (other <= upper)
        gap = np.abs(other - ref[found]) - np.abs(batch[found] - ref[found])
        assert np.all(gap[inside] >= -1e-12)


def test_joint_choice_many_on_several_branch_axes_and_weights():
    """Values shaped (2, 2, N) (θ4 branch × wrist branch × row, as the panda's batch search),
    with ties at half a turn: the q and weighted cost of joint_choice for each entry."""
    rng = np.random.default_rng(61)
    for lower, upper, weight in [(-2.9, 2.9, 2.0), (-np.pi, np.pi, 1.0), (-7.0, 7.0, 0.5)]:
        count = 300
        ref = rng.uniform(-9.0, 9.0, count)
        clipped = np.clip(ref, lower, upper)
        values = rng.uniform(-12.0, 12.0, (2, 2, count))
        values[0, 1, :80] = clipped[:80] + np.pi + TAU * rng.integers(-2, 3, 80)
        values[1, 0, 80:160] = clipped[80:160] - np.pi
        values[1, 1, 160:200] = lower - 0.5 * LIMIT_TOL
        q, cost = joint_choice_many(values, ref, clipped, lower, upper, weight)
        for index in np.ndindex(values.shape):
            row = index[-1]
            joint = (float(ref[row]), float(clipped[row]), lower, upper, weight)
            single = joint_choice(float(values[index]), joint)
            if single is None:
                assert cost[index] == np.inf, index
            else:
                assert q[index] == single[0], index
                assert cost[index] == pytest.approx(single[1], rel=1e-14, abs=1e-300)
                assert cost[index] == pytest.approx(weight * (q[index] - ref[row]) ** 2)


def test_only_revolute_serial_chains_have_screws():
    """A prismatic joint (no rotation axis) is no revolute screw; the stock arms' axes are
    unit, their points the points of the axes nearest the origin."""
    assert screws_at_zero(kinplan.load_robot(URDF / "prismatic_gantry.urdf")) is None
    for name in ("ur5", "panda"):
        robot = cached_robot(name)
        screws = screws_at_zero(robot)
        assert screws is not None
        np.testing.assert_allclose(np.linalg.norm(screws.directions, axis=1), 1.0, atol=1e-12)
        # the point of each axis nearest the origin: perpendicular to the axis
        assert np.abs(np.sum(screws.points * screws.directions, axis=1)).max() < 1e-12


@pytest.mark.parametrize("normal", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
def test_plane_basis_is_right_handed_and_orthonormal(normal):
    for n in (np.array(normal), np.array(normal) + [0.1, -0.2, 0.05]):
        n = n / np.linalg.norm(n)
        e, f = plane_basis(n)
        frame = np.column_stack([e, f, n])
        np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15)
        assert np.linalg.det(frame) == pytest.approx(1.0)
