"""Welding-grade program keys: blended lin/circ corners, weave, torch angles, dwell, and ptp
through several points (time_optimal with blend, spline); each checked on the planned motion
with the robot's own forward kinematics, plus the one-line errors of bad values."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from kinplan.program import ProgramError, load_program, plan_program

HEADER = """robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  home: {joints_deg: [0, -90, 90, -90, -90, 0]}
  mid: {joints_deg: [20, -80, 80, -90, -90, 0]}
  low: {joints_deg: [-20, -100, 100, -90, -90, 10]}
  above: {xyz: [0.35, -0.25, 0.18], rpy_deg: [180, 0, -90]}
  seam_start: {xyz: [0.35, -0.25, 0.10]}
  c1: {xyz: [0.35, -0.05, 0.10]}
  c2: {xyz: [0.49, -0.05, 0.10]}
  c3: {xyz: [0.49, -0.25, 0.10]}
moves:
"""
APPROACH = "  - {ptp: above}\n  - {lin: seam_start, speed: 0.05}\n"


def plan_text(tmp_path: Path, moves: str):
    path = tmp_path / "program.yaml"
    path.write_text(HEADER + moves)
    return plan_program(load_program(path))


def errors(tmp_path: Path, moves: str) -> dict[str, str]:
    path = tmp_path / "bad.yaml"
    path.write_text(HEADER + moves)
    with pytest.raises(ProgramError) as info:
        load_program(path)
    return {issue.path: issue.message for issue in info.value.issues}


def tool_speed(robot, plan, first: int, last: int) -> np.ndarray:
    positions = np.array([robot.fk(q).translation for q in plan.q[first : last + 1]])
    return np.linalg.norm(np.diff(positions, axis=0), axis=1) / np.diff(plan.t[first : last + 1])


def test_blended_corners_do_not_stop(tmp_path):
    plan = plan_text(
        tmp_path,
        APPROACH + "  - {lin: c1, speed: 0.04, blend: 0.02}\n"
        "  - {lin: c2, speed: 0.04, blend: 0.02}\n  - {lin: c3, speed: 0.04}\n",
    )
    assert plan.ok, plan.reason
    seam = plan.moves[-1]
    assert seam.key == "moves[2..4]" and seam.kind == "lin+lin+lin"
    speed = tool_speed(plan.robot, plan, seam.first, seam.last)
    t = plan.t[seam.first + 1 : seam.last + 1] - plan.t[seam.first]
    duration = seam.t1 - seam.t0
    cruise = (t > 0.6) & (t < duration - 0.6)  # outside the trapezoid's ramps
    assert speed[cruise].min() >= 0.5 * 0.04  # the issue: ≥ 50 % of cruise at the corners
    assert speed[cruise].min() >= 0.99 * 0.04  # in fact at cruise, arc-length timing
    positions = np.array([plan.robot.fk(q).translation for q in plan.q[seam.first : seam.last]])
    for corner in ([0.35, -0.05, 0.10], [0.49, -0.05, 0.10]):
        nearest = np.linalg.norm(positions - corner, axis=1).min()
        assert 0.002 < nearest <= 0.02  # cuts the corner, within the radius


def test_weave_key(tmp_path):
    plan = plan_text(
        tmp_path,
        APPROACH + "  - {lin: c1, speed: 0.01, weave: {pattern: triangle, amplitude: 0.002, "
        "frequency: 2.0}}\n",
    )
    assert plan.ok, plan.reason
    seam = plan.moves[-1]
    positions = np.array([plan.robot.fk(q).translation for q in plan.q[seam.first : seam.last + 1]])
    lateral = positions[:, 0] - 0.35  # the seam runs along y at x = 0.35
    assert np.abs(lateral).max() <= 0.002 + 1e-6
    assert np.abs(lateral).max() >= 0.002 - 1e-4
    crossings = np.count_nonzero(np.diff(np.sign(lateral[np.abs(lateral) > 1e-5])) > 0)
    # 0.2 m at 0.01 m/s and 2 Hz: a wavelength of 5 mm, 40 oscillations
    assert crossings in (39, 40)


def test_torch_key_holds_the_angles(tmp_path):
    seam = cartesian.Line([0.35, -0.25, 0.10], [0.35, -0.05, 0.10])
    angles = np.radians([20.0, 10.0, 0.0])
    start = cartesian.TorchOrientation(seam, [0, 0, 1], *angles).start
    rpy = np.degrees(pin.rpy.matrixToRpy(start.rotation))
    text = ", ".join(f"{a:.10f}" for a in rpy)
    moves = (
        "  - {ptp: torch_above}\n  - {lin: seam_start, speed: 0.05}\n"
        "  - {lin: c1, speed: 0.02, torch: {normal: [0, 0, 1], work_angle_deg: 20, "
        "travel_angle_deg: 10}}\n"
    )
    header = HEADER.replace(
        "moves:\n", f"  torch_above: {{xyz: [0.35, -0.25, 0.18], rpy_deg: [{text}]}}\nmoves:\n"
    )
    path = tmp_path / "torch.yaml"
    path.write_text(header + moves)
    plan = plan_program(load_program(path))
    assert plan.ok, plan.reason
    report = plan.moves[-1]
    for q in plan.q[report.first : report.last + 1 : 20]:
        axis = plan.robot.fk(q).rotation[:, 2]
        # the torch axis in the seam frame (t = +y, normal +z): sin θ, −sin φ cos θ, cos φ cos θ
        t, z0 = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, -1.0])
        y0 = np.cross(z0, t)
        work, travel = angles[0], angles[1]
        np.testing.assert_allclose(
            [axis @ t, axis @ y0, axis @ z0],
            [np.sin(travel), -np.sin(work) * np.cos(travel), np.cos(work) * np.cos(travel)],
            atol=1e-6,
        )


def test_torch_start_mismatch_names_the_orientation(tmp_path):
    plan = plan_text(
        tmp_path, APPROACH + "  - {lin: c1, speed: 0.02, torch: {work_angle_deg: 30}}\n"
    )
    assert not plan.ok
    assert "moves[2]" in plan.reason and "rpy_deg [" in plan.reason
    assert "approach point" in plan.reason


def test_dwell_holds_still(tmp_path):
    plan = plan_text(tmp_path, APPROACH + "  - {lin: c1, speed: 0.05, dwell: 0.75}\n")
    assert plan.ok, plan.reason
    dwell = plan.moves[-1]
    assert dwell.kind == "dwell" and dwell.key == "moves[2].dwell"
    assert dwell.t1 - dwell.t0 == pytest.approx(0.75, abs=1e-12)
    q = plan.q[dwell.first : dwell.last + 1]
    assert np.all(q == q[0]) and np.all(plan.qd[dwell.first : dwell.last + 1] == 0.0)


@pytest.mark.parametrize("profile", ["time_optimal", "spline"])
def test_ptp_through_several_points(tmp_path, profile):
    plan = plan_text(tmp_path, f"  - {{ptp: [mid, low, home], profile: {profile}}}\n")
    assert plan.ok, plan.reason
    assert len(plan.moves) == 1 and plan.moves[0].label == "ptp through mid, low to home"
    program = plan.program
    for name in ("mid", "low"):  # passes through every point exactly
        target = program.points[name].joints
        assert np.linalg.norm(plan.q - target, axis=1).min() < 0.02
        dense = plan.sample(np.linspace(0.0, plan.duration, 20001))[0]
        assert np.linalg.norm(dense - target, axis=1).min() < 1e-4
    np.testing.assert_allclose(plan.q[-1], program.points["home"].joints, atol=1e-12)
    limit = plan.robot.velocity_limit * 0.5  # the default ptp speed share
    assert np.all(np.abs(plan.qd) <= limit * (1 + 1e-6))
    if profile == "spline":  # no stop at the via points
        inner = (plan.t > 0.2 * plan.duration) & (plan.t < 0.8 * plan.duration)
        assert np.linalg.norm(plan.qd[inner], axis=1).min() > 1e-3


def test_spline_through_points_at_given_times(tmp_path):
    plan = plan_text(tmp_path, "  - {ptp: [mid, low, home], profile: spline, times: [2, 5, 7]}\n")
    assert plan.ok, plan.reason
    assert plan.duration == pytest.approx(7.0, abs=1e-12)
    q, qd, _ = plan.sample(np.array([2.0, 5.0, 7.0]))
    points = plan.program.points
    np.testing.assert_allclose(q, [points[n].joints for n in ("mid", "low", "home")], atol=1e-12)
    np.testing.assert_allclose(qd[-1], 0.0, atol=1e-12)
    too_fast = plan_text(
        tmp_path, "  - {ptp: [mid, low, home], profile: spline, times: [0.1, 0.2, 0.3]}\n"
    )
    assert not too_fast.ok and too_fast.moves[-1].status == "velocity_limit"


def test_time_optimal_blend_is_faster_and_deviates_at_most_the_blend(tmp_path):
    exact = plan_text(tmp_path, "  - {ptp: [mid, low, home]}\n")
    blended = plan_text(tmp_path, "  - {ptp: [mid, low, home], blend: 0.1}\n")
    assert exact.ok and blended.ok
    assert blended.duration < exact.duration
    low = exact.program.points["low"].joints
    t = np.linspace(0, blended.duration, 20001)
    k = int(np.argmin(np.linalg.norm(blended.sample(t)[0] - low, axis=1)))
    near = np.linspace(t[max(k - 1, 0)], t[min(k + 1, len(t) - 1)], 20001)  # refined there
    nearest = np.linalg.norm(blended.sample(near)[0] - low, axis=1).min()
    assert 0.01 < nearest <= 0.1 + 1e-9


@pytest.mark.parametrize(
    ("moves", "path", "fragment"),
    [
        ("  - {lin: c1, blend: 0.01}\n", "moves[0].blend", "nothing to blend into"),
        ("  - {lin: c1, blend: 0.01}\n  - {ptp: home}\n", "moves[0].blend", "not into a ptp"),
        ("  - {lin: c1, blend: 0.01, speed: 0.1}\n  - {lin: c2, speed: 0.2}\n", "moves[1].speed",
         "same speed"),
        ("  - {lin: c1, blend: 0.01, duration: 2}\n  - {lin: c2}\n", "moves[0].blend",
         "not duration"),
        ("  - {lin: c1, blend: -1}\n  - {lin: c2}\n", "moves[0].blend", "number >= 0"),
        ("  - {ptp: home, blend: 0.1}\n", "moves[0].blend", "several points"),
        ("  - {ptp: [mid, home], profile: spline, blend: 0.1}\n", "moves[0].blend",
         "time_optimal"),
        ("  - {ptp: [mid, home], profile: trapezoid}\n", "moves[0].profile", "time_optimal or"),
        ("  - {ptp: [mid, nowhere]}\n", "moves[0].ptp[1]", "unknown point 'nowhere'"),
        ("  - {ptp: []}\n", "moves[0].ptp", "non-empty list"),
        ("  - {lin: [c1, c2]}\n", "moves[0].lin", "expected the name of a point"),
        ("  - {lin: c1, weave: {amplitude: 0.002}}\n", "moves[0].weave", "needs frequency"),
        ("  - {lin: c1, weave: {amplitude: 0.002, frequency: 0}}\n", "moves[0].weave.frequency",
         "number > 0"),
        ("  - {lin: c1, weave: {amplitude: 0.002, frequency: 2, wobble: 1}}\n",
         "moves[0].weave.wobble", "unknown key"),
        ("  - {lin: c1, weave: {amplitude: 0.002, frequency: 2, pattern: zigzag}}\n",
         "moves[0].weave.pattern", "unknown pattern"),
        ("  - {lin: c1, duration: 3, weave: {amplitude: 0.002, frequency: 2}}\n",
         "moves[0].duration", "not a duration"),
        ("  - {ptp: c1, weave: {amplitude: 0.002, frequency: 2}}\n", "moves[0].weave",
         "not ptp"),
        ("  - {lin: c1, torch: {work_angle_deg: 95}}\n", "moves[0].torch.work_angle_deg",
         "strictly between -90 and 90"),
        ("  - {lin: c1, torch: {normal: [0, 0, 0]}}\n", "moves[0].torch.normal", "non-zero"),
        ("  - {lin: c1, torch: 45}\n", "moves[0].torch", "expected a mapping"),
        ("  - {lin: c1, dwell: -0.5}\n", "moves[0].dwell", "number >= 0"),
        ("  - {ptp: [mid, home], times: [1, 2]}\n", "moves[0].times", "profile spline"),
        ("  - {ptp: [mid, home], profile: spline, times: [1]}\n", "moves[0].times",
         "expected 2 numbers"),
        ("  - {ptp: [mid, home], profile: spline, times: [2, 1]}\n", "moves[0].times[1]",
         "must increase"),
        ("  - {ptp: [mid, home], profile: spline, times: [1, 2], duration: 3}\n",
         "moves[0].times", "not both"),
        ("  - {lin: c1, dwell: 1, blend: 0.01}\n  - {lin: c2}\n", "moves[0].dwell",
         "cannot dwell"),
    ],
)  # fmt: skip
def test_bad_welding_keys(tmp_path, moves, path, fragment):
    found = errors(tmp_path, moves)
    assert path in found and fragment in found[path], found


def test_bad_values_found_while_planning(tmp_path):
    too_wide = plan_text(
        tmp_path, APPROACH + "  - {lin: c1, blend: 0.15}\n  - {lin: c2}\n"
    )  # the second line is 0.14 m long
    assert not too_wide.ok and "larger than half the path" in too_wide.reason
    amplitude = plan_text(
        tmp_path, APPROACH + "  - {lin: c1, weave: {amplitude: 0.15, frequency: 1}}\n"
    )
    assert not amplitude.ok and "below half the seam length" in amplitude.reason
