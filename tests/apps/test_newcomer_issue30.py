"""What a newcomer tripped on (issue 30): UR e-Series names, move counting with weld_cell.yaml,
the collision instant in the playback's caption, obstacle colours."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY

import kinplan
from kinplan.errors import RobotNotFoundError
from kinplan.program import parse_program, plan_program

EXAMPLES = REPOSITORY / "examples" / "programs"


@pytest.mark.parametrize("name", ["ur3e", "ur5e", "ur10e", "ur16e"])
def test_e_series_name_without_a_urdf_names_the_path_to_pass(name, monkeypatch, tmp_path):
    empty = tmp_path / "example-robot-data"
    (empty / "robots").mkdir(parents=True)
    monkeypatch.setenv("EXAMPLE_ROBOT_DATA_DIR", str(empty))
    with pytest.raises(RobotNotFoundError) as info:
        kinplan.load_robot(name)
    message = str(info.value)
    pretty = name[:-1].upper() + "e"
    assert f"no URDF of the {pretty} in the installed packages" in message
    assert f"give the path of a {pretty} URDF file" in message and f"{name}.urdf" in message
    assert "unknown robot" not in message


def test_e_series_name_loads_where_the_installed_packages_have_its_urdf(monkeypatch, tmp_path):
    share = tmp_path / "example-robot-data"
    folder = share / "robots" / "ur_description" / "urdf"
    folder.mkdir(parents=True)
    ur5 = kinplan.load_robot("ur5")
    shutil.copy(ur5.urdf_path, folder / "ur5e_robot.urdf")
    monkeypatch.setenv("EXAMPLE_ROBOT_DATA_DIR", str(share))
    robot = kinplan.load_robot("ur5e")
    assert robot.name == "ur5e" and robot.tip_frame == "tool0" and robot.nq == 6
    assert Path(robot.urdf_path).name == "ur5e_robot.urdf"
    q = np.array([0.1, -1.2, 1.1, -1.4, -1.5, 0.2])
    np.testing.assert_allclose(robot.fk(q).homogeneous, ur5.fk(q).homogeneous, atol=1e-12)


@pytest.fixture(scope="module")
def weld_cell_plan():
    from kinplan.program import load_program

    plan = plan_program(load_program(EXAMPLES / "weld_cell.yaml"))
    assert plan.ok, plan.reason
    return plan


def test_moves_are_counted_as_the_file_lists_them(weld_cell_plan):
    """weld_cell.yaml has 12 moves: its dwells belong to their moves and moves 7-10, blended
    into one motion, are numbered as in the file (the issue saw 13/12 and `ok: 7 moves`)."""
    plan = weld_cell_plan
    assert plan.move_count == 12 == plan.moves_done
    assert [m.numbers for m in plan.moves] == [
        "1", "2", "2", "3", "3", "4", "5", "6", "6", "7–10", "10", "11", "12",
    ]  # fmt: skip
    assert plan.summary().splitlines()[-2].startswith("total: 12 moves")
    assert repr(plan).startswith("ProgramPlan(ur5, 12 moves")
    assert plan.description == "12 moves"


def test_a_failed_blended_motion_names_its_moves():
    text = """robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.4, -0.1, 0.2], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.4, 0.1, 0.2]}
  far: {xyz: [-0.4, 0.1, 0.2]}
moves:
  - {ptp: a, dwell: 0.2}
  - {lin: b, blend: 0.01, name: front face}
  - {lin: far}
"""
    plan = plan_program(parse_program(text))
    assert not plan.ok
    assert plan.reason.startswith("moves 2–3 (front face, moves[1..2]): "), plan.reason
    assert plan.moves_done == 1 and plan.move_count == 3


def test_batch_table_counts_the_files_moves(capsys):
    from kinplan.apps.cli import main

    assert main(["run", str(EXAMPLES / "weld_cell.yaml"), str(EXAMPLES / "lecture_2r.yaml")]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if "weld_cell.yaml" in line)
    assert "12/12" in row, row


def test_batch_table_keeps_a_long_paths_file_name_whole(tmp_path, capsys):
    """CI found it: a path longer than the table's room was folded over two lines, the file
    name split. The table keeps the last folders and the whole file name behind '…/'."""
    import shutil

    from kinplan.apps.cli import main

    deep = tmp_path / ("a_rather_long_folder_name_" * 3) / "cell_programs"
    deep.mkdir(parents=True)
    program = deep / "lecture_2r.yaml"
    shutil.copy(EXAMPLES / "lecture_2r.yaml", program)
    assert main(["run", str(program), str(program)]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if "lecture_2r.yaml" in line]
    assert len(rows) == 2, rows
    assert all("…/cell_programs/lecture_2r.yaml" in row and "3/3" in row for row in rows), rows


def test_caption_gives_the_instant_the_bodies_turn_red():
    """A ptp folding the UR5 into its base, sampled coarsely: the failure lies between two
    samples; the caption's time is the instant the playback shows the bodies red (rounded up
    to the millisecond), not the last good sample's."""
    import math
    import re

    from kinplan.viewer.playback import playback

    text = """robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  folded: {joints_deg: [0, -10, 170, -90, -90, 0]}
moves:
  - {ptp: folded, duration: 3.0}
"""
    plan = plan_program(parse_program(text), dt=0.05)
    assert plan.status == "collision"
    played = playback(plan.robot, plan, 30.0)
    assert played.collision is not None
    printed = float(re.search(r"\(t = (\d+\.\d+) s\)", played.caption[0]).group(1))
    assert printed == math.ceil(played.collision.t * 1000 - 1e-6) / 1000
    assert played.collision.t <= printed < played.collision.t + 1e-3
    assert played.t[-1] == pytest.approx(played.collision.t, abs=1e-9)
    assert plan.events[0].t <= played.collision.t  # the last good sample is not later
