"""Programs are held to the same promise as plans: an `ok` program can be run, a refused one says
the speed it would need, however short its moves (issue 12)."""

from __future__ import annotations

import numpy as np
import pytest

from kinplan.program import parse_program, plan_program
from kinplan.trajectory.sampling import MIN_INTERVALS, joint_speeds

UR5_START = "start: {joints_deg: [0, -90, 90, -90, -90, 0]}"


def _plan(text: str):
    return plan_program(parse_program(f"robot: ur5\n{UR5_START}\n{text}"))


@pytest.mark.parametrize("duration", [0.001, 0.01, 0.1])
def test_a_ptp_too_short_for_its_joints_is_refused_with_the_speed_it_needs(duration):
    """A 90° ptp of the UR5's base joint needs 1.875 · (π/2) / T rad/s at its peak (quintic)
    or 1.5 · (π/2) / T (cubic), however few samples dt gives it."""
    for profile, peak_factor in (("quintic", 1.875), ("cubic", 1.5)):
        plan = _plan(
            "points: {a: {joints_deg: [90, -90, 90, -90, -90, 0]}}\n"
            f"moves: [{{ptp: a, duration: {duration}, profile: {profile}}}]"
        )
        assert not plan.ok and plan.moves[0].status == "velocity_limit"
        needed = peak_factor * (np.pi / 2) / duration
        assert plan.moves[0].peak_speed_ratio == pytest.approx(needed / 3.15, rel=1e-9)
        assert f"{needed:.4g} rad/s" in plan.reason


def test_a_lin_shorter_than_a_sample_is_refused_and_an_ok_one_is_executable():
    """A 2 cm line in 1 ms is sampled at T/16 and refused with the factor it is too fast (at
    least: 16 samples may miss the very peak); slowed a little more than that it is ok, and its
    samples keep every joint within its limit."""
    points = "points: {a: {xyz: [0.1, 0.3, 0.4]}}\n"
    fast = _plan(points + "moves: [{lin: a, duration: 0.001}]")
    assert not fast.ok and fast.moves[0].status == "velocity_limit"
    factor = fast.moves[0].peak_speed_ratio
    assert factor > 100 and f"at least {factor:.3g}" in fast.reason
    slow = _plan(points + f"moves: [{{lin: a, duration: {0.001 * factor * 1.1}}}]")
    assert slow.ok, slow.reason
    assert len(slow.t) > MIN_INTERVALS
    speeds = joint_speeds(slow.q, slow.qd, slow.t)
    assert np.all(speeds <= slow.robot.velocity_limit)


def test_random_programs_that_plan_ok_are_executable(ur5):
    """Seeded random UR5 programs (ptp to random joints with random durations and profiles, lin
    to nearby points at random speeds): every `ok` program plan keeps its joints within their
    limits and every joint speed — rates and mean speeds between samples — within its limit,
    and every refused one gives a one-line reason."""
    rng = np.random.default_rng(21)
    outcomes = {True: 0, False: 0}
    for _ in range(60):
        start = np.degrees(rng.uniform(0.8 * ur5.lower, 0.8 * ur5.upper))
        points, moves = {}, []
        tool = ur5.fk(np.radians(start)).translation
        for k in range(3):
            if rng.random() < 0.5:
                joints = np.degrees(rng.uniform(0.8 * ur5.lower, 0.8 * ur5.upper))
                points[f"p{k}"] = "{joints_deg: [" + ", ".join(f"{v:.3f}" for v in joints) + "]}"
                timing = f", duration: {rng.uniform(0.01, 3.0):.4f}" if rng.random() < 0.7 else ""
                profile = rng.choice(["trapezoid", "quintic", "cubic"])
                moves.append(f"{{ptp: p{k}{timing}, profile: {profile}}}")
            else:
                target = tool + rng.normal(scale=0.05, size=3)
                points[f"p{k}"] = "{xyz: [" + ", ".join(f"{v:.4f}" for v in target) + "]}"
                moves.append(f"{{lin: p{k}, speed: {rng.uniform(0.01, 2.0):.4f}}}")
        text = (
            "robot: ur5\nstart: {joints_deg: [" + ", ".join(f"{v:.3f}" for v in start) + "]}\n"
            "points:\n" + "".join(f"  {name}: {spec}\n" for name, spec in points.items())
            + "moves: [" + ", ".join(moves) + "]\n"
        )  # fmt: skip
        try:
            plan = plan_program(parse_program(text))
        except Exception as exc:  # a KinplanError for an invalid program is fine, nothing else
            from kinplan.errors import KinplanError

            assert isinstance(exc, KinplanError), (text, exc)
            continue
        outcomes[plan.ok] += 1
        if plan.ok:
            assert np.all(plan.q >= ur5.lower) and np.all(plan.q <= ur5.upper)
            speeds = joint_speeds(plan.q, plan.qd, plan.t)
            assert np.all(speeds <= ur5.velocity_limit), text
        else:
            assert plan.reason and "\n" not in plan.reason
    # random UR5 configurations often self-collide (programs check their work cell, issue 16)
    assert outcomes[True] > 3 and outcomes[False] > 5, outcomes
