"""The pendant's process commands (issue 30): a tool on the flange, points reached by lin and
circ moves with weave and torch angles, the arc switched; the written program plans."""

from __future__ import annotations

import numpy as np
import pytest

import kinplan
from kinplan.apps.teach import TeachPendant
from kinplan.program import parse_program, plan_program

HOME = np.radians([0, -90, 90, -90, -90, 0])


@pytest.fixture
def pendant():
    return TeachPendant(kinplan.load_robot("ur5"), q_start=HOME)


def run(pendant, *lines):
    replies = [pendant.execute(line) for line in lines]
    for line, reply in zip(lines, replies, strict=True):
        assert not reply.text.startswith("error"), (line, reply.text)
    return replies


def test_a_taught_weld_with_tool_lin_circ_weave_torch_and_arc_plans(pendant):
    flange = pendant.robot.fk(HOME)
    run(pendant, "tool 0 0 0.2", "show")
    tcp = pendant.robot.fk(HOME)
    np.testing.assert_allclose(tcp.translation, flange.act(np.array([0, 0, 0.2])), atol=1e-12)
    run(
        pendant,
        "z -0.05", "r s0",
        "y 0.05", "r mid lin 0.02",
        "weave sine 1.5 2", "arc on",
        "y 0.05", "r seam_end lin 0.008",
        "weave off", "arc off",
        "x 0.03", "r around circ mid 0.01",
    )  # fmt: skip
    text = pendant.program_text()
    assert "tool: {xyz: [0, 0, 0.2], rpy_deg: [0, 0, 0]}" in text
    assert "tip: tool0" in text
    assert "- {lin: mid, speed: 0.02}" in text
    assert (
        "- {lin: seam_end, speed: 0.008, weave: {pattern: sine, amplitude: 0.0015, "
        "frequency: 2}, arc: on}" in text
    )
    assert "- {circ: around, via: mid, speed: 0.01, arc: off}" in text
    program = parse_program(text)
    assert [m.kind for m in program.moves] == ["ptp", "lin", "lin", "circ"]
    assert program.moves[2].arc is True and program.moves[3].arc is False
    assert program.moves[2].weave is not None and program.moves[2].weave.amplitude == 0.0015
    plan = plan_program(program)
    assert plan.ok, plan.reason
    # the recorded points are where the tool was taught: the program's TCP reaches them
    for name, q in pendant.points.items():
        np.testing.assert_allclose(
            program.robot.fk(program.points[name].joints).translation,
            pendant.robot.fk(q).translation, atol=1e-9,
        )  # fmt: skip


def test_torch_angles_are_written(pendant):
    run(pendant, "torch 45 10", "z -0.02", "r a lin")
    assert "- {lin: a, torch: {work_angle_deg: 45, travel_angle_deg: 10}}" in pendant.program_text()


@pytest.mark.parametrize(
    ("line", "fragment"),
    [
        ("tool 0 0", "usage: tool X Y Z [R P Y]"),
        ("tool 0 0 9", "between -2 and 2"),
        ("weave zigzag 1 2", "usage: weave sine|triangle|trapezoid"),
        ("weave sine 0 2", "amplitude [mm] must be between"),
        ("torch 95 0", "work angle [deg] must be between -89 and 89"),
        ("arc maybe", "usage: arc on | arc off"),
        ("r p1 circ nowhere", "a circ needs a recorded via point"),
        ("r p1 lin fast", "expected a number for the tool speed [m/s]"),
        ("r p1 spline", "usage: r [name] [ptp | lin [speed] | circ <via> [speed]]"),
    ],
)
def test_malformed_process_commands_say_what_to_type(pendant, line, fragment):
    reply = pendant.execute(line)
    assert reply.text.startswith("error: ") and fragment in reply.text, reply.text
    assert pendant.points == {}


def test_tool_off_and_help(pendant):
    run(pendant, "tool 0.1 0 0.2 0 30 0")
    assert "xyz [0.1, 0, 0.2] m, rpy [0, 30, 0] deg" in pendant.execute("tool").text
    run(pendant, "tool off")
    assert pendant.robot is pendant.flange_robot and pendant.tool_pose is None
    for command in ("tool", "weave", "torch", "arc"):
        assert pendant.execute(f"help {command}").text.startswith(command)


def test_a_cell_checks_the_jogs_and_goes_into_the_program(pendant, tmp_path):
    """``use_cell`` (``kinplan teach --cell``): a jog into an obstacle is refused, naming it;
    the taught program carries the obstacles and clearance and plans in that cell."""
    tcp = pendant.robot.fk(HOME).translation
    cell_program = tmp_path / "cell.yaml"
    cell_program.write_text(
        "robot: ur5\nobstacles:\n"
        f"  plate: {{box: [0.3, 0.3, 0.01], xyz: [{tcp[0]:.4f}, {tcp[1]:.4f}, "
        f"{tcp[2] - 0.12:.4f}], color: '#5b7fa6'}}\n"
        "clearance: 0.005\nstart: {joints_deg: [0, -90, 90, -90, -90, 0]}\n"
        "points: {a: {joints_deg: [0, -90, 90, -90, -90, 0]}}\nmoves: [{ptp: a}]\n"
    )
    assert "plate" in pendant.use_cell(cell_program)
    before = pendant.q.copy()
    reply = pendant.execute("z -0.2")
    assert reply.text.startswith("refused: ") and "plate" in reply.text, reply.text
    np.testing.assert_array_equal(pendant.q, before)  # did not move
    run(pendant, "z -0.05", "r above", "y 0.05", "r side lin 0.02")
    text = pendant.program_text()
    assert "obstacles:" in text and "plate:" in text and "clearance: 0.005" in text
    program = parse_program(text)
    assert list(program.cell.obstacles) == ["plate"] and program.clearance == 0.005
    assert program.obstacle_colors == {"plate": "#5b7fa6"}
    assert plan_program(program).ok


def test_a_cell_without_obstacles_is_refused(pendant, tmp_path):
    from kinplan.errors import KinplanError

    empty = tmp_path / "empty.yaml"
    empty.write_text("robot: ur5\n")
    with pytest.raises(KinplanError, match="has no obstacles"):
        pendant.use_cell(empty)
