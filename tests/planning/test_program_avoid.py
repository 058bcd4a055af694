"""Programs: ``{ptp: p, avoid: true}`` and a program-wide ``avoid: true`` plan ptp moves around
the obstacles with kinplan.free_motion (issue 28)."""

from __future__ import annotations

import numpy as np
import pytest
from free_motion_cells import colliding_pairs, ur5_cell

from kinplan.program import ProgramError, parse_program, plan_program

CELL = """\
robot: ur5
obstacles:
  table: {box: [1.6, 1.2, 0.04], xyz: [0.3, 0.0, -0.02]}
  wall: {box: [0.02, 1.6, 1.2], xyz: [-0.55, 0.0, 0.6]}
  shelf_low: {box: [0.3, 0.5, 0.02], xyz: [0.5, -0.35, 0.25]}
  shelf_high: {box: [0.3, 0.5, 0.02], xyz: [0.5, -0.35, 0.55]}
  pillar: {cylinder: {radius: 0.05, length: 1.0}, xyz: [0.4, 0.35, 0.5]}
"""


@pytest.fixture(scope="module")
def pair():
    """A start and goal of the test cell whose straight joint move collides."""
    (start, goal), *_ = colliding_pairs(ur5_cell(), 1, seed=21)
    return start, goal


def program(pair, move: str, head: str = "") -> str:
    start, goal = (", ".join(f"{v:.12g}" for v in q) for q in pair)
    return (
        CELL
        + head
        + f"start: {{joints: [{start}]}}\npoints:\n  b: {{joints: [{goal}]}}\nmoves:\n  - {move}\n"
    )


def test_a_colliding_ptp_says_avoid_plans_around_it(pair):
    plan = plan_program(parse_program(program(pair, "{ptp: b}")))
    assert not plan.ok and plan.status == "collision"
    assert "avoid: true" in plan.reason


@pytest.mark.parametrize(
    ("move", "head"), [("{ptp: b, avoid: true}", ""), ("{ptp: b, speed: 0.8}", "avoid: true\n")]
)
def test_avoid_plans_the_ptp_around_the_obstacles(pair, move, head):
    plan = plan_program(parse_program(program(pair, move, head)))
    assert plan.ok, plan.reason
    (report,) = plan.moves
    assert "around the obstacles" in report.label and "waypoints" in report.label
    assert "waypoints" in plan.summary()
    np.testing.assert_allclose(plan.q[0], pair[0], atol=1e-12)
    np.testing.assert_allclose(plan.q[-1], pair[1], atol=1e-9)
    assert report.min_clearance > 0.0


def test_avoid_false_on_a_move_overrides_the_program(pair):
    plan = plan_program(parse_program(program(pair, "{ptp: b, avoid: false}", "avoid: true\n")))
    assert plan.status == "collision"


@pytest.mark.parametrize(
    ("move", "head", "where", "words"),
    [
        ("{ptp: b, avoid: 1}", "", "moves[0].avoid", "expected true or false"),
        ("{lin: b, avoid: true}", "", "moves[0].avoid", "ptp to one point"),
        ("{ptp: b, avoid: true, duration: 2}", "", "moves[0].duration", "remove duration"),
        ("{ptp: b, avoid: true, profile: quintic}", "", "moves[0].profile", "remove profile"),
        ("{ptp: b, duration: 2}", "avoid: true\n", "moves[0].duration", "avoid: false"),
        ("{ptp: b}", "avoid: yes please\n", "avoid", "expected true or false"),
    ],
)
def test_bad_avoid_keys_are_reported(pair, move, head, where, words):
    with pytest.raises(ProgramError) as info:
        parse_program(program(pair, move, head))
    issues = {issue.path: issue.message for issue in info.value.issues}
    assert where in issues and words in issues[where], issues
