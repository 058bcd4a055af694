"""Native URScript (issue 30): movej / movel / movec / movep with the program's speeds, blends,
TCP, payload and I/O, parsed back and compared with the plan; the controller model that checks
each move before it is written; the fallback to servoj and the refusal."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import REPOSITORY

import kinplan
from kinplan import export
from kinplan.apps.cli import main
from kinplan.errors import InputError
from kinplan.export.controller_model import (
    arc_track,
    blended_track,
    movej_samples,
    trapezoid_law,
)
from kinplan.program import load_program, parse_program, plan_program

DEMOS = Path(kinplan.__file__).parent / "demo_programs"
NUMBER = r"-?\d+(?:\.\d+)?"
POSE = r"p\[([^\]]*)\]"
MOVEL = re.compile(rf"^\s*movel\({POSE}, a=({NUMBER}), v=({NUMBER})\)$", re.M)
MOVEP = re.compile(rf"^\s*movep\({POSE}, a=({NUMBER}), v=({NUMBER}), r=({NUMBER})\)$", re.M)
MOVEJ = re.compile(rf"^\s*movej\(\[([^\]]*)\], a=({NUMBER}), v=({NUMBER})\)$", re.M)
# the controller's base frame in the UR descriptions: base_link turned by pi about z
BASE = pin.SE3(np.diag([-1.0, -1.0, 1.0]), np.zeros(3))


def numbers(text: str) -> np.ndarray:
    return np.array([float(x) for x in text.split(",")])


def pose_of(text: str) -> pin.SE3:
    values = numbers(text)
    return pin.SE3(pin.exp3(values[3:]), values[:3])


@pytest.fixture(scope="module")
def native_plan():
    plan = plan_program(load_program(DEMOS / "weld_native.yaml"))
    assert plan.ok, plan.reason
    return plan


@pytest.fixture(scope="module")
def native_script(native_plan):
    return export.urscript(native_plan)


def statements(script: str) -> list[str]:
    """The program's statements (comments dropped), in order."""
    lines = [line.split("  #")[0].strip() for line in script.splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def test_native_is_the_default_for_programs_and_has_no_servoj(native_plan, native_script):
    assert export.default_style(native_plan) == "native"
    assert "servoj(" not in native_script
    header = native_script.splitlines()[0]
    assert f"kinplan {kinplan.__version__}" in header and "weld_native.yaml" in header
    assert "native style" in header
    native_script.encode("ascii")
    assert not re.search(r"\d[eE][-+]?\d", native_script), "URScript has no exponents"


def test_native_program_is_50_times_smaller_than_the_servo_stream(native_plan, native_script):
    servo = export.urscript(native_plan, style="servo", period=0.008)
    assert len(servo) >= 50 * len(native_script), (len(servo), len(native_script))


def test_move_ends_are_the_plans_forward_kinematics(native_plan, native_script):
    """Each native move's target, read back, is the plan's end of that move: joints for movej
    (1e-9 rad), the TCP pose in the controller's base for movel/movep (1e-6 m, 1e-6 rad)."""
    robot = native_plan.robot
    body = statements(native_script)
    reports = [m for m in native_plan.moves if m.kind != "dwell"]
    commands = [s for s in body if s.startswith(("movej", "movel", "movec", "movep"))][1:]
    ends: list[np.ndarray | pin.SE3] = []
    for report in reports:
        q = native_plan.q[report.last]
        if report.kind == "ptp":
            ends.append(q)
        else:
            ends.append(BASE.inverse() * robot.fk(q))
    # a movep chain is one report: its last waypoint is the end
    chained = []
    for command in commands:
        if command.startswith("movep") and chained and chained[-1][0].startswith("movep"):
            chained[-1] = (chained[-1][0], command)
        else:
            chained.append((command, command))
    assert len(chained) == len(ends)
    for (_first, last), end in zip(chained, ends, strict=True):
        if last.startswith("movej"):
            np.testing.assert_allclose(numbers(MOVEJ.match(last).group(1)), end, atol=1e-9)
        else:
            pose = pose_of(re.search(POSE, last).group(1))
            np.testing.assert_allclose(pose.translation, end.translation, atol=1e-6)
            turn = np.linalg.norm(pin.log3(pose.rotation.T @ end.rotation))
            assert turn < 1e-6, turn


def test_speeds_and_accelerations_are_the_programs(native_plan, native_script):
    speeds = {float(v) for _, _, v in MOVEL.findall(native_script)}
    assert speeds == {0.05, 0.008}  # approach/retreat, the fillet
    chain = MOVEP.findall(native_script)
    assert len(chain) == 4 and {float(v) for _, _, v, _ in chain} == {0.01}
    assert [float(r) for *_, r in chain] == [0.015, 0.015, 0.015, 0.0]


def test_blend_radii_never_exceed_half_a_neighbouring_segment(native_plan, native_script):
    body = statements(native_script)
    k = next(i for i, s in enumerate(body) if s.startswith("movep"))
    approach = [st for st in body[:k] if st.startswith("movel(")][-1]  # where the chain starts
    before = pose_of(re.search(POSE, approach).group(1))
    points = [before.translation]
    radii = []
    for statement in body[k:]:
        if not statement.startswith("movep"):
            break
        match = MOVEP.match("  " + statement)
        points.append(pose_of(match.group(1)).translation)
        radii.append(float(match.group(4)))
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    for j, r in enumerate(radii[:-1]):
        assert r <= 0.5 * lengths[j] and r <= 0.5 * lengths[j + 1], (j, r, lengths)
    assert radii[-1] == 0.0


def test_tcp_and_payload_match_the_tool(native_script):
    match = re.search(rf"set_tcp\({POSE}\)", native_script)
    tcp = pose_of(match.group(1))
    np.testing.assert_allclose(tcp.translation, [0.085, 0.0, 0.2472], atol=1e-10)
    expected = pin.rpy.rpyToMatrix(0.0, math.radians(30.0), 0.0)
    np.testing.assert_allclose(tcp.rotation, expected, atol=1e-10)
    assert "set_payload(1.25, [0.03, 0.0, 0.11])" in native_script


def test_io_lines_sit_at_their_moves(native_plan, native_script):
    """Gas on before the first move; each seam's weld job (register 0), then arc on, after the
    approach's dwell, before the seam's movel; arc off after the seam's crater-fill dwell,
    before the retreat; gas off when the arm has arrived at rect_clear (a point's io:)."""
    body = statements(native_script)
    on, off = "set_standard_digital_out(0, True)", "set_standard_digital_out(0, False)"
    first_arc = body.index(on)
    assert body[first_arc - 2 : first_arc] == ["sleep(0.5)", "write_output_integer_register(0, 3)"]
    assert body[first_arc + 1].startswith("movel(")
    assert re.search(r"v=0\.008\)$", body[first_arc + 1])  # the fillet itself
    first_off = body.index(off)
    assert body[first_off - 1] == "sleep(0.5)" and body[first_off + 1].startswith("movel(")
    second_arc = body.index(on, first_arc + 1)
    assert body[second_arc - 2 : second_arc] == [
        "sleep(0.3)",
        "write_output_integer_register(0, 5)",
    ]
    assert body[second_arc + 1].startswith("movep(")
    gas = body.index("set_standard_digital_out(1, True)")
    assert body[gas - 1].startswith("movej(")  # after going to the start, before move 1
    gas_off = body.index("set_standard_digital_out(1, False)")
    assert gas_off > body.index(off, second_arc)
    assert body[gas_off - 1].startswith("movel(") and body[gas_off + 1].startswith("movej(")
    assert body.count(on) == 2 and body.count(off) == 2
    assert [e.kind for e in native_plan.io_events] == [
        "io", "job", "arc", "arc", "job", "arc", "arc", "io",
    ]  # fmt: skip


def test_a_move_without_native_form_becomes_servoj_with_its_reason():
    plan = plan_program(load_program(DEMOS / "weld_cell.yaml"))
    script = export.urscript(plan)
    assert "# move 3 as servoj: a woven seam" in script
    assert "# move 5 as servoj: a ptp through several points" in script
    assert "# move 7-10 as servoj: the tool turns" in script
    # the woven fillet's servoj targets are the plan's own motion at k · period from its start
    fillet = next(m for m in plan.moves if m.key == "moves[2]")
    lines = script.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("  # move 3:"))
    targets = []
    for line in lines[start + 2 :]:
        if not line.startswith("  servoj("):
            break
        targets.append(numbers(line.split("[")[1].split("]")[0]))
    count = math.ceil((fillet.t1 - fillet.t0) / 0.008 - 1e-6) + 1
    hold = math.ceil(2 * 0.1 / 0.008 - 1e-9)
    assert len(targets) == count + hold
    times = np.minimum(fillet.t0 + 0.008 * np.arange(count), fillet.t1)
    np.testing.assert_allclose(targets[:count], plan.sample(times)[0], atol=1e-9)
    with pytest.raises(InputError, match=r"move 3 \(woven fillet: lin to fillet_end, moves\[2\]\)"):
        export.urscript(plan, fallback="refuse")


def test_native_style_needs_a_program_plan():
    robot = kinplan.load_robot("ur5")
    from kinplan import trajectory
    from kinplan.trajectory.motion import sampled

    q0 = np.radians([0, -90, 90, -90, -90, 0])
    motion = sampled(trajectory.quintic(q0, q0 + 0.2, 1.0), robot)
    assert export.default_style(motion) == "servo"
    with pytest.raises(InputError, match="native URScript style needs a program plan"):
        export.urscript(motion, style="native")
    with pytest.raises(InputError, match="style must be one of native, servo"):
        export.urscript(motion, style="movel")


def test_cli_urscript_style(tmp_path, capsys):
    program = REPOSITORY / "examples" / "programs" / "weld_native.yaml"
    native, servo = tmp_path / "n.script", tmp_path / "s.script"
    assert main(["run", str(program), "--urscript", str(native)]) == 0
    out = capsys.readouterr().out
    assert f"wrote {native} (URScript, native style: 10 native moves, 0 as servoj)" in out
    argv = ["run", str(program), "--urscript", str(servo), "--urscript-style", "servo"]
    assert main(argv) == 0
    assert "servoj targets every 0.008 s" in capsys.readouterr().out
    assert "servoj(" not in native.read_text() and "servoj(" in servo.read_text()


# ----------------------------------------------------------------------------------------------
# the controller model, against closed forms
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("length", "v", "a"), [(1.0, 0.5, 2.0), (0.01, 0.5, 2.0), (2.0, 1.0, 1.0)])
def test_trapezoid_law_is_the_closed_form(length, v, a):
    t, s = trapezoid_law(length, v, a, step=1e-4)
    reach = v * v / a
    total = length / v + v / a if reach <= length else 2 * math.sqrt(length / a)
    assert t[-1] == pytest.approx(total, rel=1e-12) and s[-1] == pytest.approx(length)
    speed = np.diff(s) / np.diff(t)
    assert speed.max() <= min(v, math.sqrt(a * length)) * (1 + 1e-9)
    assert np.all(np.abs(np.diff(speed) / 1e-4) <= a * 1.01)


def test_movej_is_joint_linear_on_the_leading_axis():
    q0, q1 = np.zeros(3), np.array([1.0, -0.5, 0.25])
    t, q = movej_samples(q0, q1, 1.0, 2.0, step=1e-3)
    assert t[-1] == pytest.approx(1.0 / 1.0 + 1.0 / 2.0)
    shares = (q - q0) / (q1 - q0)
    np.testing.assert_allclose(shares[:, 1], shares[:, 0], atol=1e-15)
    np.testing.assert_allclose(q[-1], q1, atol=1e-15)


def test_arc_passes_its_three_points():
    start = pin.SE3(np.eye(3), np.array([0.5, 0.0, 0.3]))
    end = pin.SE3(np.eye(3), np.array([0.3, 0.2, 0.3]))
    via = np.array([0.3 + 0.2 * math.cos(math.pi / 4), 0.2 * math.sin(math.pi / 4), 0.3])
    track = arc_track(start, via, end, 0.1, 1.0, 1e-3)
    centre = np.array([0.3, 0.0, 0.3])
    np.testing.assert_allclose(np.linalg.norm(track.positions - centre, axis=1), 0.2, atol=1e-12)
    assert track.length == pytest.approx(0.2 * math.pi / 2)
    assert np.min(np.linalg.norm(track.positions - via, axis=1)) < 1e-4


def test_circular_blend_of_a_right_angle():
    """A 90° corner blended within r: the arc of radius r tangent to both lines r from the
    corner, whose closest point is r (√2 − 1) from it."""
    start = pin.SE3(np.eye(3), np.zeros(3))
    corner, end = np.array([1.0, 0.0, 0.0]), np.array([1.0, 1.0, 0.0])
    track = blended_track(start, [corner, end], [0.2], np.eye(3), 0.05, 1.0, 1e-3)
    closest = np.min(np.linalg.norm(track.positions - corner, axis=1))
    assert closest == pytest.approx(0.2 * (math.sqrt(2) - 1), abs=1e-6)
    assert track.length == pytest.approx(2.0 - 0.4 + 0.2 * math.pi / 2)
    with pytest.raises(ValueError, match="more than half the segment after it"):
        blended_track(start, [corner, np.array([1.0, 0.3, 0.0])], [0.2], np.eye(3), 0.05, 1, 1e-3)


def test_a_replay_that_breaks_the_cell_is_not_written_natively():
    """The controller model's replay is checked against the plan's cell: an obstacle put where
    the flange passes in the middle of the seam after planning (the plan itself never saw it)
    makes that movel a servoj stream, the reason naming the obstacle, or a refusal."""
    text = """robot: ur5
tool: {xyz: [0, 0, 0.2]}
obstacles:
  table: {box: [1.0, 1.2, 0.04], xyz: [0.25, 0, -0.3], allowed: [base_link]}
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.4, -0.1, 0.2], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.4, 0.1, 0.2]}
moves:
  - {ptp: a}
  - {lin: b, speed: 0.05}
"""
    plan = plan_program(parse_program(text))
    assert plan.ok
    clean = export.urscript(plan)
    assert "servoj(" not in clean and len(MOVEL.findall(clean)) == 1
    seam = next(m for m in plan.moves if m.key == "moves[1]")
    middle = plan.q[(seam.first + seam.last) // 2]
    model = plan.robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, middle)
    flange = data.oMf[model.getFrameId("tool0")].translation
    plan.cell.add_box("intruder", [0.03, 0.03, 0.03], pin.SE3(np.eye(3), flange + [0, 0, 0.02]))
    script = export.urscript(plan)
    assert len(MOVEL.findall(script)) == 0 and "servoj(" in script
    (reason,) = [line for line in script.splitlines() if line.startswith("# move 2 as servoj")]
    assert "movel as the controller runs it" in reason and "intruder" in reason, reason
    assert "wrist_3_link collides with intruder" in reason
    with pytest.raises(InputError, match=r"cannot be written as a native move: .*intruder"):
        export.urscript(plan, fallback="refuse")


def test_a_free_motion_is_a_movej_only_where_the_straight_motion_is_clear():
    """``avoid: true`` plans around a post; the controller's movej would go straight through
    it, so the replay makes that move a servoj stream (the plan's own detour), saying why."""
    text = """robot: ur5
obstacles:
  table: {box: [1.0, 1.2, 0.04], xyz: [0.25, 0, -0.02], allowed: [base_link]}
  post: {box: [0.06, 0.06, 0.3], xyz: [0.42, 0.0, 0.15]}
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.4, -0.25, 0.2], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.4, 0.25, 0.2], rpy_deg: [180, 0, 90]}
moves:
  - {ptp: a}
  - {ptp: b, avoid: true}
"""
    plan = plan_program(parse_program(text))
    if not plan.ok:
        pytest.skip(f"the free motion was not found here: {plan.reason}")
    script = export.urscript(plan)
    (reason,) = [line for line in script.splitlines() if line.startswith("# move 2 as servoj")]
    assert "avoid: true" in reason and "collides with post" in reason, reason
    assert len(MOVEJ.findall(script)) == 2  # to the start, and move 1
    servo = [line for line in script.splitlines() if line.startswith("  servoj(")]
    end = numbers(servo[-1].split("[")[1].split("]")[0])
    np.testing.assert_allclose(end, plan.q[-1], atol=1e-9)  # the stream ends where the plan does
