"""Programs in a work cell: ``obstacles:``, ``tool:``, ``clearance:`` (issue 16)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import kinplan
from kinplan.program import ProgramError, parse_program, plan_program

HEAD = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
"""
POINTS = """\
points:
  a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.40, 0.10, 0.20], rpy_deg: [180, 0, 90]}
moves:
  - {ptp: a}
  - {lin: b, speed: 0.1}
"""


def _issues(text: str, tmp_path=None) -> dict[str, str]:
    with pytest.raises(ProgramError) as info:
        parse_program(text, base_dir=tmp_path)
    return {issue.path: issue.message for issue in info.value.issues}


def test_obstacles_and_tool_are_parsed(tmp_path):
    program = parse_program(
        HEAD
        + """\
tool: {xyz: [0, 0, 0.2], rpy_deg: [0, 0, 0],
       body: {cylinder: {radius: 0.015, length: 0.18}, xyz: [0, 0, 0.1]}}
clearance: 0.005
obstacles:
  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.30]}
  post:  {cylinder: {radius: 0.05, length: 0.6}, xyz: [-0.5, 0.5, 0.0], rpy_deg: [0, 0, 90]}
  ball:  {sphere: 0.05, xyz: [-0.6, -0.6, 0.3]}
"""
        + POINTS
    )
    cell = program.cell
    assert isinstance(cell, kinplan.WorkCell) and program.clearance == 0.005
    assert set(cell.obstacles) == {"table", "post", "ball"}
    assert cell.obstacles["table"].size == (1.2, 0.8, 0.04)
    np.testing.assert_allclose(cell.obstacles["post"].pose.translation, [-0.5, 0.5, 0.0])
    assert cell.obstacles["ball"].size == (0.05,)
    assert program.robot.tool is not None and program.robot.tool_links
    assert cell.robot is program.robot


def test_self_collision_is_checked_without_obstacles():
    program = parse_program(HEAD + POINTS)
    assert program.cell is not None and not program.cell.obstacles
    plan = plan_program(program)
    assert plan.ok, plan.reason
    assert plan.cell is program.cell
    assert math.isinf(plan.min_clearance) and 0 < plan.min_self_clearance < 1


def test_the_tool_tcp_is_where_with_tool_says():
    program = parse_program(HEAD + "tool: {xyz: [0.01, 0, 0.2], rpy_deg: [0, 20, 0]}\n" + POINTS)
    bare = kinplan.load_robot("ur5")
    tcp = pin.SE3(pin.rpy.rpyToMatrix(0, math.radians(20), 0), np.array([0.01, 0, 0.2]))
    q = program.start
    expected = bare.with_tool(tcp).fk(q)
    np.testing.assert_allclose(program.robot.fk(q).homogeneous, expected.homogeneous, atol=1e-9)
    np.testing.assert_allclose(
        program.robot.fk(q).homogeneous, (bare.fk(q) * tcp).homogeneous, atol=1e-9
    )
    plan = plan_program(program)  # the taught points are TCP poses
    assert plan.ok, plan.reason
    np.testing.assert_allclose(plan.tool_positions[-1], [0.40, 0.10, 0.20], atol=1e-4)


@pytest.mark.parametrize(
    ("entry", "path", "words"),
    [
        ("post: {cone: 0.1}", "obstacles.post.cone", "unknown key"),
        ("post: {xyz: [0, 0, 0]}", "obstacles.post", "exactly one shape"),
        ("table: {box: [1.2, -0.8, 0.04]}", "obstacles.table.box", "> 0"),
        ("post: {cylinder: {radius: -0.05, length: 0.6}}", "obstacles.post.cylinder", "> 0"),
        ("post: {cylinder: {radius: 0.05}}", "obstacles.post.cylinder", "radius"),
        ("ball: {sphere: 0.1, scale: 2}", "obstacles.ball.scale", "meshes only"),
        ("ball: {sphere: 0.1, xyz: [0, 0]}", "obstacles.ball.xyz", "3 numbers"),
        ("part: {mesh: nowhere.stl}", "obstacles.part.mesh", "no file"),
        ("ball: {sphere: -0.1}", "obstacles.ball.sphere", "> 0"),
        ("ball: {sphere: {radius: 0}}", "obstacles.ball.sphere", "> 0"),
        ("part: {mesh: block.stl, scale: -0.001}", "obstacles.part.scale", "> 0"),
    ],
)
def test_bad_obstacles_name_the_key_path(entry, path, words, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box((100.0, 100.0, 100.0)).export(tmp_path / "block.stl")
    issues = _issues(HEAD + f"obstacles:\n  {entry}\n" + POINTS, tmp_path)
    assert list(issues) == [path], issues
    assert words in issues[path]


def test_an_srdf_naming_unknown_links_is_one_line_naming_the_robot_key(tmp_path, capsys):
    """The SRDF found next to the program's URDF names a link the URDF does not have: the
    program's ``robot`` key is blamed, with the SRDF, the link and the URDF's links, in one
    line of `kinplan run`."""
    from test_cell import PROBE_URDF

    from kinplan.apps.cli import main

    (tmp_path / "probe.urdf").write_text(PROBE_URDF)
    (tmp_path / "probe.srdf").write_text(
        '<robot name="probe"><disable_collisions link1="arm" link2="claw"/></robot>'
    )
    text = (
        "robot: probe.urdf\ntip: finger\nstart: {joints: [0, 0.5, 0.5]}\n"
        "points:\n  a: {joints: [0.1, 0.5, 0.5]}\nmoves:\n  - {ptp: a}\n"
    )
    issues = _issues(text, tmp_path)
    assert list(issues) == ["robot"], issues
    for words in ("probe.srdf", "'claw'", "arm, base, finger, hand"):
        assert words in issues["robot"]
    program = tmp_path / "probe.yaml"
    program.write_text(text)
    assert main(["run", str(program)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "robot (line 1)" in err[0] and "'claw'" in err[0]


def test_an_unparsable_mesh_names_the_key_path(tmp_path):
    (tmp_path / "broken.stl").write_text("this is not a mesh\n")
    issues = _issues(HEAD + "obstacles:\n  part: {mesh: broken.stl}\n" + POINTS, tmp_path)
    assert list(issues) == ["obstacles.part.mesh"], issues


def test_a_mesh_relative_to_the_program_file(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.box((100.0, 100.0, 100.0)).export(tmp_path / "block.stl")
    program = parse_program(
        HEAD
        + "obstacles:\n  part: {mesh: block.stl, scale: 0.001, xyz: [-0.6, 0.6, 0.05]}\n"
        + POINTS,
        base_dir=tmp_path,
    )
    body = program.cell.obstacles["part"]
    assert body.shape == "mesh" and body.scale == (0.001, 0.001, 0.001)
    assert body.path == tmp_path / "block.stl"


@pytest.mark.parametrize(
    ("tool", "path"),
    [
        ("tool: 0.2", "tool"),
        ("tool: {xyz: [0, 0, 0.2], offset: 1}", "tool.offset"),
        ("tool: {xyz: [0, 0, 0.2], body: {cylinder: {radius: 0.01, length: -0.2}}}",
         "tool.body.cylinder"),
        ("tool: {xyz: [0, 0, 0.2], body: {pyramid: 1}}", "tool.body.pyramid"),
        ("clearance: -0.01", "clearance"),
    ],
)  # fmt: skip
def test_bad_tool_and_clearance_name_the_key_path(tool, path):
    issues = _issues(HEAD + tool + "\n" + POINTS)
    assert list(issues) == [path], issues


def test_a_lin_through_an_obstacle_fails_with_collision_naming_both_bodies():
    wall = "obstacles:\n  wall: {box: [0.08, 0.004, 0.1], xyz: [0.40, 0.0, 0.2]}\n"
    backwards = POINTS.replace("{ptp: a}", "{ptp: b}").replace("{lin: b,", "{lin: a,")
    program = parse_program(HEAD + wall + backwards)  # ptp on the +y side, lin across y = 0
    plan = plan_program(program)
    assert not plan.ok and plan.status == "collision"
    failed = plan.moves[-1]
    assert failed.key == "moves[1]" and failed.kind == "lin", plan.reason
    assert failed.collision is not None and failed.collision.bodies[1] == "wall"
    robot_body = failed.collision.bodies[0]
    assert robot_body in program.cell.robot_bodies
    assert plan.reason.startswith("move 2 (lin to a, moves[1]): collision at s = ")
    assert "wall" in plan.reason and robot_body in plan.reason
    # the samples kept are free of the wall
    assert all(
        p.distance > 0
        for q in plan.q
        for p in program.cell.pair_distances(q)
        if p.kind == "obstacle"
    )


def test_a_ptp_through_an_obstacle_is_caught():
    free = plan_program(parse_program(HEAD + POINTS))
    ptp = free.moves[0]
    middle = free.tool_positions[(ptp.first + ptp.last) // 2]
    xyz = ", ".join(f"{v:.4f}" for v in middle)
    program = parse_program(HEAD + f"obstacles:\n  ball: {{sphere: 0.04, xyz: [{xyz}]}}\n" + POINTS)
    plan = plan_program(program)
    assert plan.status == "collision" and len(plan.moves) == 1
    failed = plan.moves[0]
    assert failed.kind == "ptp" and failed.collision.bodies[1] == "ball"
    assert plan.reason.startswith("move 1 (ptp to a, moves[0]): collision at s = ")
    assert 0 < failed.fraction < 1
    assert plan.events[0].kind == "collision"


def test_min_clearance_is_reported_per_move_and_for_the_plan():
    program = parse_program(
        HEAD + "obstacles:\n  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.05]}\n" + POINTS
    )
    plan = plan_program(program)
    assert plan.ok, plan.reason
    rows = plan.summary_rows()
    assert all(0 < row["min_clearance"] < 1 for row in rows)
    assert plan.min_clearance == pytest.approx(min(row["min_clearance"] for row in rows))
    assert plan.min_clearance_pair[1] == "table"
    # the clearance along the plan is the cell's own distance at every sample
    assert plan.clearance.shape == plan.t.shape and np.all(np.isfinite(plan.clearance))
    for k in (0, len(plan.t) // 2, len(plan.t) - 1):
        exact = min(
            p.distance for p in program.cell.pair_distances(plan.q[k]) if p.kind == "obstacle"
        )
        assert plan.clearance[k] == pytest.approx(exact, abs=1e-6)
    assert plan.clearance.min() == pytest.approx(plan.min_clearance, abs=1e-9)


def test_clearance_margin_turns_a_near_miss_into_a_collision():
    text = HEAD + "obstacles:\n  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.05]}\n" + POINTS
    margin = plan_program(parse_program(text)).min_clearance + 0.01
    plan = plan_program(parse_program(text + f"clearance: {margin:.4f}\n"))
    assert plan.status == "collision" and "clearance" in plan.reason


def test_the_page_of_a_plan_in_a_cell_draws_its_obstacles_and_the_collision(tmp_path):
    from pages import objects, page_parts

    from kinplan import viewer

    free = plan_program(parse_program(HEAD + POINTS))
    ptp = free.moves[0]
    middle = free.tool_positions[(ptp.first + ptp.last) // 2]
    xyz = ", ".join(f"{v:.4f}" for v in middle)
    cell = (
        "obstacles:\n"
        "  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.05]}\n"
        "  post: {cylinder: {radius: 0.05, length: 0.6}, xyz: [-0.5, 0.5, 0.3]}\n"
        f"  ball: {{sphere: 0.04, xyz: [{xyz}]}}\n"
    )
    plan = plan_program(parse_program(HEAD + cell + POINTS))
    assert plan.status == "collision"
    link, obstacle = plan.moves[-1].collision.bodies
    assert obstacle == "ball"
    path = viewer.save_html(plan.robot, plan, tmp_path / "cell.html")
    commands, config = page_parts(path.read_text(encoding="utf-8"))
    drawn = objects(commands)
    for name in ("table", "post", "ball"):
        assert f"/kinplan/cell/{name}" in drawn
    assert "/kinplan/cell/collision" in drawn  # a red ball where the collision happened

    def colour(path):
        return drawn[path]["materials"][0]["color"]

    grey = colour("/kinplan/cell/table")
    # each workpiece stands out from the table and from the others (issue 30)
    colours = {colour(f"/kinplan/cell/{name}") for name in ("table", "post", "ball")}
    assert len(colours) == 3
    red = colour("/kinplan/cell/ball/hit")  # the obstacle hit: a red copy, from the instant on
    assert red not in colours and red == colour("/kinplan/cell/collision")
    assert grey == 0xA39D94  # a table: the supports' grey
    hits = [p for p in drawn if p.startswith("/kinplan/robot/") and p.endswith("/hit")]
    assert hits and all(p.startswith(f"/kinplan/robot/{link}") for p in hits)  # the link's parts
    assert all(colour(p) == red for p in hits)
    assert "cell" in config["layers"]
    assert f"collision: {link} – ball" in path.read_text(encoding="utf-8")  # the legend


def test_the_plot_of_a_plan_in_a_cell_shows_its_clearance():
    from kinplan.plot import plot_trajectory

    text = HEAD + "obstacles:\n  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.05]}\n" + POINTS
    plan = plan_program(parse_program(text))
    figure = plot_trajectory(plan)
    assert len(figure.axes) == 4 and "clearance" in figure.axes[3].get_ylabel()
    np.testing.assert_allclose(figure.axes[3].lines[0].get_ydata(), 1e3 * plan.clearance)
    assert len(plot_trajectory(plan_program(parse_program(HEAD + POINTS))).axes) == 3


def _table_rows(text: str) -> list[list[str]]:
    """The cells of every body row of a rich table printed by `kinplan run`."""
    return [[cell.strip() for cell in line.split("│")[1:-1]] for line in text.splitlines()
            if line.startswith("│")]  # fmt: skip


def test_run_summary_has_the_clearance_of_each_move_and_the_pair_in_the_total(capsys, tmp_path):
    """`kinplan run` on a program with obstacles: the clearance column [mm] is each move's
    min_clearance (a ball near the lin's end, the table far below), and the total row names
    the nearest pair; without obstacles there is no such column."""
    from kinplan.apps.cli import main

    cell = (
        "obstacles:\n"
        "  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.10]}\n"
        "  ball: {sphere: 0.03, xyz: [0.50, 0.12, 0.22]}\n"
    )
    path = tmp_path / "cell.yaml"
    path.write_text(HEAD + cell + POINTS)
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    header_line = next(line for line in out.splitlines() if line.startswith("┃"))
    header = [cell.strip() for cell in header_line.split("┃")[1:-1]]
    assert header[6] == "clearance [mm]"
    rows = _table_rows(out)
    plan = plan_program(parse_program(HEAD + cell + POINTS, base_dir=tmp_path))
    assert plan.ok and len(rows) == len(plan.moves) + 1
    values = [row[6] for row in rows]
    expected = [f"{1e3 * move.min_clearance:.1f}" for move in plan.moves]
    assert values[:-1] == expected
    assert float(values[0]) > float(values[1]) > 0  # the lin passes the ball
    assert plan.min_clearance_pair == ("wrist_3_link", "ball")
    assert values[-1] == f"{1e3 * plan.min_clearance:.1f} (wrist_3_link – ball)"
    assert rows[-1][1] == "total" and rows[-1][-1] == "ok"

    bare = tmp_path / "bare.yaml"
    bare.write_text(HEAD + POINTS)
    assert main(["run", str(bare)]) == 0
    out = capsys.readouterr().out
    assert "clearance" not in out
    assert all(len(row) == 7 for row in _table_rows(out))
