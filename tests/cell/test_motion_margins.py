"""Every margin of the motion check applied exactly once, with its sign and unit (issue 26).

:func:`kinplan.cell.motion.check` certifies a segment between two samples for a pair of
threshold c when ``d_a + d_b − 2c ≥ M`` (the distance bound at both ends, each less c, covers the
motion bound M). Subtracting c once instead of twice certifies segments whose distance dips to
c/2 between the samples; such a bug survives tests whose between-sample cases all use c = 0 or
whose shortfalls are deeper than c/2, or whose motion bounds are loose (a UR5's lever arms are
several times its true speeds, so its dips are found anyway).

Here the motion bounds are tight: a prismatic slider carries a sphere past a small ball, and its
lever is exactly 1 m/m, so a dip between c/2 and c is within what a halved margin would accept.
The independent answer is the closed form of the distance of two spheres along the straight joint
segment (and dense sampling with the cell's own distance query, coal). Siblings: self pairs fail on
contact only (no margin) but do fail between samples; a tool body's extent is in its motion
bound; the first sample inside the margin is reported at that sample with its exact distance;
shortfalls deeper than ``TOLERANCE`` are never missed; the margin is in metres.

Tolerances: coal's sphere–sphere distance is analytic, equal to the closed form to 1e-12 m
(EXACT); failures are asserted real at 1e-12 m.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import kinplan
from kinplan.cell import TOLERANCE, Body, WorkCell, xyz_rpy

EXACT = 1e-12

SLIDER = """<?xml version="1.0"?>
<robot name="slider">
  <link name="base">
    <collision><origin xyz="{post_x} {post_y} 0"/><geometry><sphere radius="{post_r}"/></geometry>
    </collision>
  </link>
  <link name="carriage"/>
  <link name="head">
    <collision><geometry><sphere radius="{r}"/></geometry></collision>
  </link>
  <joint name="x" type="prismatic">
    <parent link="base"/><child link="carriage"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="z" type="prismatic">
    <parent link="carriage"/><child link="head"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>
"""
"""A gantry: ``x`` carries ``carriage``, ``z`` carries ``head`` (a sphere of radius r at the
head's origin, at (x, 0, z)). The base holds a post (a sphere of radius post_r at (post_x,
post_y, 0)): base and head are two links apart, so post–head is a self pair."""


def slider(folder: Path, r: float, post=(0.5, 0.5, 0.01)) -> kinplan.Robot:
    path = folder / "slider.urdf"
    post_x, post_y, post_r = post
    path.write_text(SLIDER.format(r=r, post_x=post_x, post_y=post_y, post_r=post_r))
    return kinplan.load_robot(path, tip="head")


def ball_cell(robot: kinplan.Robot, offset: float, radius: float) -> WorkCell:
    """The robot and a ball of ``radius`` centred at (0, offset, 0) [m]."""
    cell = WorkCell(robot)
    cell.add_sphere("ball", radius, xyz_rpy((0.0, offset, 0.0)))
    return cell


def joints(x) -> np.ndarray:
    """Samples (N, 2) of the gantry at head positions x (z = 0)."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    return np.column_stack([x, np.zeros_like(x)])


def ball_distance(x, offset: float, spheres: float) -> np.ndarray:
    """Closed form: head–ball distance [m] with the head at (x, 0, 0), the ball at (0, offset,
    0), radii summing to ``spheres``."""
    return np.hypot(np.asarray(x, dtype=float), offset) - spheres


def segment_minimum(xa: float, xb: float, offset: float, spheres: float) -> float:
    """Closed form: the smallest head–ball distance [m] along the straight segment xa → xb."""
    nearest = 0.0 if xa * xb <= 0.0 else min(abs(xa), abs(xb))
    return float(ball_distance(nearest, offset, spheres))


def dense_minimum(cell: WorkCell, qa: np.ndarray, qb: np.ndarray, kind: str, count: int = 2001):
    """The cell's own smallest distance of ``kind`` pairs along qa → qb, densely sampled [m]."""
    t = np.linspace(0.0, 1.0, count)[:, None]
    return min(
        p.distance for q in qa + t * (qb - qa) for p in cell.pair_distances(q) if p.kind == kind
    )


# --------------------------------------------------------------- the clearance, subtracted twice
#: Head r 5 mm, ball 2 mm, clearance 20 mm; the ball 26 mm off the line (the head passes it at
#: 19 mm: 1 mm inside the margin), samples 7.4 mm either side of it (20.1 mm away).
R_HEAD, R_BALL, CLEARANCE, OFFSET, HALF = 0.005, 0.002, 0.02, 0.026, 0.0074


def test_dip_inside_the_clearance_between_two_samples_is_found(tmp_path):
    robot = slider(tmp_path, R_HEAD)
    cell = ball_cell(robot, OFFSET, R_BALL)
    spheres = R_HEAD + R_BALL
    q = joints([-HALF, HALF])
    ends = ball_distance([-HALF, HALF], OFFSET, spheres)
    lowest = segment_minimum(-HALF, HALF, OFFSET, spheres)
    # premises: both samples keep the clearance, the motion between them does not (by 1 mm,
    # less than c/2: a margin subtracted once would certify it, d_a + d_b − c ≥ M)
    assert np.all(ends > CLEARANCE) and lowest == pytest.approx(0.019, abs=EXACT)
    motion = 2 * HALF  # the lever of a prismatic joint is 1 m/m: M is the exact travel
    assert ends.sum() - CLEARANCE >= motion > ends.sum() - 2 * CLEARANCE
    # the independent answers agree with each other: closed form and the cell's coal distances
    assert dense_minimum(cell, q[0], q[1], "obstacle") == pytest.approx(lowest, abs=1e-8)
    for x, d in zip([-HALF, HALF], ends):
        (pair,) = cell.pair_distances(joints(x)[0])[-1:]
        assert pair.bodies == ("head", "ball") and pair.distance == pytest.approx(d, abs=EXACT)

    result = cell.check_motion(q, clearance=CLEARANCE)
    assert result.index == 1 and result.between and result.kind == "obstacle"
    assert result.bodies == ("head", "ball")
    # real, where it is said to be: the reported distance is the closed form at that place
    x = float(result.q[0])
    assert x == pytest.approx(-HALF + result.fraction * 2 * HALF, abs=EXACT)
    assert result.distance == pytest.approx(ball_distance(x, OFFSET, spheres), abs=EXACT)
    assert result.distance < CLEARANCE
    assert result.penetration == pytest.approx(CLEARANCE - result.distance, abs=EXACT)
    assert "(clearance 20 mm)" in result.describe()
    # without the margin (or with a margin the motion keeps) the same motion is free
    assert cell.check_motion(q).ok
    assert cell.check_motion(q, clearance=lowest - 10 * TOLERANCE).ok


@pytest.mark.parametrize(("before", "after"), [(0.0075, 0.012), (0.0075, 0.0155), (0.0125, 0.0075)])
def test_dip_off_the_middle_of_a_segment_is_found(tmp_path, before, after):
    """The dip between samples 2 and 3 of five, ``before`` and ``after`` it [m]: at an uneven
    fraction of the segment (the first bisection does not land on it)."""
    robot = slider(tmp_path, R_HEAD)
    cell = ball_cell(robot, OFFSET, R_BALL)
    spheres = R_HEAD + R_BALL
    step = before + after
    x = np.array([-before - 2 * step, -before - step, -before, after, after + step])
    distances = ball_distance(x, OFFSET, spheres)
    assert np.all(distances > CLEARANCE)
    assert distances[2] + distances[3] - CLEARANCE >= step  # a halved margin certifies it
    result = cell.check_motion(joints(x), clearance=CLEARANCE)
    assert result.index == 3 and result.between and result.bodies == ("head", "ball")
    assert result.distance == pytest.approx(ball_distance(result.q[0], OFFSET, spheres), abs=EXACT)
    assert result.distance < CLEARANCE


@pytest.mark.parametrize("side", [1.0, -1.0], ids=["dip-in-the-second-half", "in-the-first"])
def test_dip_found_after_several_bisections(tmp_path, side):
    """A 15 cm step whose ends and first midpoint are far outside a 5 mm margin, passing 4 mm
    from a ball at x = 0 (head and ball 1 mm in radius: the distance falls at nearly the full
    motion bound, a V): only halves bounded by half their parent's motion are certified
    correctly; a half bounded by less (a quarter) is certified with the dip inside it."""
    robot = slider(tmp_path, 0.001)
    clearance, offset, spheres = 0.005, 0.006, 0.002
    cell = ball_cell(robot, offset, 0.001)
    x = side * np.array([-0.1, 0.05])
    ends = ball_distance(x, offset, spheres)
    middle = float(ball_distance(x.mean(), offset, spheres))
    assert ends.min() > 0.04 and middle > 0.02  # the first bisection finds nothing
    result = cell.check_motion(joints(x), clearance=clearance)
    assert result.index == 1 and result.between and result.bodies == ("head", "ball")
    assert result.distance == pytest.approx(ball_distance(result.q[0], offset, spheres), abs=EXACT)
    assert 0.004 - EXACT <= result.distance < clearance
    assert result.evaluations >= 5  # several levels of bisection


def test_check_agrees_with_the_closed_form_on_random_gantry_motions(tmp_path):
    """300 seeded motions (radii, clearance, offset, samples all random): ``ok`` exactly when the
    closed-form minimum over every straight segment keeps the clearance; a failure at the
    first sample or segment that does not, real where reported. Cases a margin subtracted once
    would certify are counted: the run must hold enough of them to catch that."""
    rng = np.random.default_rng(2626)
    robots: dict[float, kinplan.Robot] = {}
    blind = 0
    for case in range(300):
        r_head = float(rng.choice([0.002, 0.005, 0.01]))
        if r_head not in robots:
            (tmp_path / f"r{case}").mkdir()
            robots[r_head] = slider(tmp_path / f"r{case}", r_head)
        robot = robots[r_head]
        r_ball, clearance = rng.uniform(0.001, 0.01), rng.uniform(0.005, 0.03)
        spheres = r_head + r_ball
        if case % 2:  # anywhere near the ball
            offset = spheres + clearance * rng.uniform(0.4, 1.4)
            x = np.cumsum(rng.uniform(0.1, 1.2, 3) * clearance) + rng.uniform(-2, 0) * clearance
        else:  # grazing: passing the ball up to 15 % inside the margin, samples just outside
            clearance = max(clearance, 4 * spheres)
            offset = spheres + clearance * rng.uniform(0.85, 1.0)
            outside = math.sqrt((spheres + clearance) ** 2 - offset**2)  # |x| at the margin
            a, b = outside * rng.uniform(1.0, 1.15), outside * rng.uniform(1.0, 1.3)
            x = np.array([-a - (a + b) * rng.uniform(0.5, 1.5), -a, b]) * rng.choice([-1, 1])
        cell = ball_cell(robot, offset, r_ball)
        at = ball_distance(x, offset, spheres)
        lows = [segment_minimum(a, b, offset, spheres) for a, b in zip(x[:-1], x[1:])]
        # the first failing sample (k) or segment (k − 1 → k), with a band of TOLERANCE
        fails = [at[0] < clearance] + [low < clearance for low in lows]
        unsure = [abs(at[0] - clearance) < 2 * TOLERANCE] + [
            abs(low - clearance) < 2 * TOLERANCE for low in lows
        ]
        if any(unsure):
            continue
        for k in range(1, len(x)):
            blind += bool(
                at[k - 1] >= clearance
                and at[k] >= clearance
                and clearance / 2 <= lows[k - 1] < clearance
                and at[k - 1] + at[k] - clearance >= abs(x[k] - x[k - 1])
            )
        result = cell.check_motion(joints(x), clearance=clearance)
        expected = next((k for k, fail in enumerate(fails) if fail), None)
        assert result.index == expected, (case, x, lows, clearance)
        if expected is not None:
            assert result.bodies == ("head", "ball")
            assert result.distance == pytest.approx(
                ball_distance(result.q[0], offset, spheres), abs=EXACT
            )
            assert result.distance < clearance
    assert blind >= 50, blind


def test_free_motion_that_needs_bisection_is_ok(tmp_path):
    """Passing 1 mm outside the margin between two samples: the check must bisect (the ends
    do not certify the segment) and then certify it; applying the margin more than twice, or
    failing a midpoint that keeps the clearance, would refuse it."""
    robot = slider(tmp_path, R_HEAD)
    spheres = R_HEAD + R_BALL
    offset = spheres + CLEARANCE + 0.001
    cell = ball_cell(robot, offset, R_BALL)
    q = joints([-0.02, 0.015])
    ends = ball_distance([-0.02, 0.015], offset, spheres)
    assert ends.sum() - 2 * CLEARANCE < 0.035  # not certified by the ends
    result = cell.check_motion(q, clearance=CLEARANCE)
    assert result.ok
    assert result.evaluations > 2  # distances computed between the samples
    assert result.min_clearance == pytest.approx(ends.min(), abs=EXACT)  # at the samples
    assert dense_minimum(cell, q[0], q[1], "obstacle") >= CLEARANCE


def test_shortfall_ten_tolerances_deep_between_samples_is_found(tmp_path):
    robot = slider(tmp_path, R_HEAD)
    spheres = R_HEAD + R_BALL
    cell = ball_cell(robot, spheres + CLEARANCE - 10 * TOLERANCE, R_BALL)
    x = [-0.011, 0.013]
    assert np.all(ball_distance(x, spheres + CLEARANCE - 10 * TOLERANCE, spheres) > CLEARANCE)
    result = cell.check_motion(joints(x), clearance=CLEARANCE)
    assert result.index == 1 and result.between
    assert CLEARANCE - 10 * TOLERANCE - EXACT <= result.distance < CLEARANCE


def test_first_sample_inside_the_margin_is_reported_there(tmp_path):
    """A slow approach over 40 samples: the distance carried from the first sample falls
    below the margin before the pair is inside it; the pair is computed again and the first
    sample inside the margin is reported at that sample, with its exact distance (not at a
    configuration between samples, not later)."""
    robot = slider(tmp_path, R_HEAD)
    spheres = R_HEAD + R_BALL
    cell = ball_cell(robot, spheres + 0.005, R_BALL)
    x = np.linspace(-0.2, 0.0, 40)
    at = ball_distance(x, spheres + 0.005, spheres)
    first = int(np.argmax(at < CLEARANCE))
    assert first > 30 and at[first - 1] >= CLEARANCE + 1e-4
    result = cell.check_motion(joints(x), clearance=CLEARANCE)
    assert result.index == first and not result.between
    assert result.distance == pytest.approx(at[first], abs=EXACT)
    assert result.min_clearance == pytest.approx(at[first], abs=EXACT)
    full = cell.check_motion(joints(x), clearance=CLEARANCE, full=True)
    np.testing.assert_allclose(full.obstacle_distances, at, atol=EXACT, rtol=0)


# ----------------------------------------------------------------------------- self pairs
def test_self_pair_has_no_margin_between_samples(tmp_path):
    """The post (on the base) and the head are a self pair: passing 10 mm apart between two
    samples is free whatever the clearance (neighbouring links sit that close); only the
    obstacle margin counts."""
    post = (0.3, 0.027, 0.012)
    robot = slider(tmp_path, R_HEAD, post)
    cell = WorkCell(robot)
    assert ("base", "head") in cell.checked_pairs or ("head", "base") in cell.checked_pairs
    x = 0.3 + np.array([-0.0074, 0.0074])
    lowest = dense_minimum(cell, joints(x)[0], joints(x)[1], "self")
    assert lowest == pytest.approx(0.027 - 0.017, abs=1e-8)  # 10 mm at x = 0.3
    for clearance in (0.0, 0.02, 0.05):
        result = cell.check_motion(joints(x), clearance=clearance)
        assert result.ok, result.describe()
        assert result.min_self_clearance > lowest  # at the samples


def test_self_contact_between_samples_is_found(tmp_path):
    post = (0.3, 0.015, 0.012)  # centres 15 mm apart at x = 0.3, radii 17 mm: 2 mm deep
    robot = slider(tmp_path, R_HEAD, post)
    cell = WorkCell(robot)
    x = 0.3 + np.array([-0.0124, 0.0101])
    ends = np.hypot(x - 0.3, 0.015) - 0.017
    assert np.all(ends > 0)
    for clearance in (0.0, 0.02):
        result = cell.check_motion(joints(x), clearance=clearance)
        assert result.index == 1 and result.between and result.kind == "self"
        expected = math.hypot(result.q[0] - 0.3, 0.015) - 0.017
        assert result.distance == pytest.approx(expected, abs=EXACT) and result.distance <= 0
        assert result.penetration == pytest.approx(-result.distance, abs=EXACT)
        assert "clearance" not in result.describe()


# ------------------------------------------------------------------------------ lever arms
BOOM = """<?xml version="1.0"?>
<robot name="boom">
  <link name="base"/>
  <link name="boom">
    <collision><origin xyz="2 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <joint name="yaw" type="revolute">
    <parent link="base"/><child link="boom"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
</robot>
"""


def test_lever_arm_is_in_metres_per_radian(tmp_path):
    """A 2 m boom (a large arm's reach) turns 0.3 rad in one step; its head (r 5 cm) passes
    through a ball (r 5 cm) on its circle halfway and is 20 cm from it at both samples. The
    head moves 2 m per radian: a bound of 1 m per radian (the lever's length dropped) would
    certify the step (0.2 + 0.2 ≥ 0.3)."""
    path = tmp_path / "boom.urdf"
    path.write_text(BOOM)
    robot = kinplan.load_robot(path, tip="boom")
    cell = WorkCell(robot)
    cell.add_sphere("ball", 0.05, xyz_rpy((2.0, 0.0, 0.0)))
    q = np.array([[-0.15], [0.15]])
    ends = 2 * 2.0 * np.sin(0.075) - 0.1  # chord to the ball, less both radii [m]
    for row in q:
        assert cell.distance(row) == pytest.approx(ends, abs=EXACT)
    assert 2 * ends >= 0.3 * 1.0
    result = cell.check_motion(q)
    assert result.index == 1 and result.between and result.bodies == ("boom", "ball")
    angle = float(result.q[0])
    expected = 2 * 2.0 * abs(np.sin(angle / 2)) - 0.1
    assert result.distance == pytest.approx(expected, abs=EXACT) and result.distance <= 0


# ------------------------------------------------------------------------------ tool body
def test_tool_body_extent_is_in_its_motion_bound():
    """A bent torch: a 25 cm rod across the flange's axis. Turning only wrist 3 (by 1.2 rad in
    one step), the rod's far end sweeps through a ball that both samples leave 7 cm or more
    away; only a motion bound that includes the body's extent about the wrist's axis sees it
    (the flange itself turns in place)."""
    robot = kinplan.load_robot("ur5")
    rod = Body.cylinder(0.01, 0.25, xyz_rpy((0.125, 0.0, 0.08), (0, 90, 0)))
    tooled = robot.with_tool(xyz_rpy((0.25, 0.0, 0.08)), rod)
    home = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
    cell = WorkCell(tooled)
    cell.add_sphere("ball", 0.01, xyz_rpy(tooled.fk(home).translation))  # the rod's far end
    turn = np.array([0, 0, 0, 0, 0, 1.0])
    q = np.array([home - 0.4 * turn, home + 0.8 * turn])  # home at a third of the segment
    ends = [min(p.distance for p in cell.pair_distances(row) if "ball" in p.bodies) for row in q]
    assert min(ends) > 0.07
    assert dense_minimum(cell, q[0], q[1], "obstacle", 601) < -0.01
    result = cell.check_motion(q)
    assert result.index == 1 and result.between and result.bodies == ("tool", "ball")
    assert result.distance <= 0
    (pair,) = [p for p in cell.pair_distances(result.q) if p.bodies == ("tool", "ball")]
    assert pair.distance == pytest.approx(result.distance, abs=1e-9)
