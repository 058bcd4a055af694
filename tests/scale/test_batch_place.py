"""Batch planning (plan_many, `kinplan run A B`) and robot placement (place, `kinplan place`)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
import yaml
from conftest import REPOSITORY

import kinplan
from kinplan.apps.cli import main
from kinplan.program import load_program, parse_program, plan_program, run_program
from kinplan.scale.batch import plan_many
from kinplan.scale.placement import heat_map, place, with_base_pose

EXAMPLES = REPOSITORY / "examples" / "programs"


def test_plan_many_agrees_with_run_program(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("robot: ur5\nstart: {joints: [0, 0]}\npoints: {}\nmoves: []\n")
    paths = [EXAMPLES / "lecture_2r.yaml", bad, EXAMPLES / "weld_unreachable.yaml"]
    summaries = plan_many(paths)
    assert [s.path for s in summaries] == [str(p) for p in paths]
    first, invalid, failed = summaries
    plan = run_program(EXAMPLES / "lecture_2r.yaml")
    assert first.ok and first.status == "ok" and first.robot == "planar_2r"
    assert (first.moves, first.moves_ok, first.samples) == (3, 3, len(plan.t))
    assert first.duration == pytest.approx(plan.duration)
    assert first.min_manipulability == pytest.approx(plan.manipulability.min())
    assert 0.0 < first.joint_margin < math.pi
    assert not invalid.ok and invalid.status == "invalid" and "start" in invalid.reason
    expected = run_program(EXAMPLES / "weld_unreachable.yaml")
    assert not failed.ok and failed.status == expected.status and failed.reason == expected.reason
    assert failed.moves_ok == sum(m.ok for m in expected.moves) < failed.moves


def test_plan_many_misuse(tmp_path):
    with pytest.raises(kinplan.KinplanError, match="cannot read the program"):
        plan_many([tmp_path / "missing.yaml"])
    with pytest.raises(kinplan.InputError):
        plan_many([])
    with pytest.raises(kinplan.InputError):
        plan_many([EXAMPLES / "lecture_2r.yaml"], dt=0.0)


def test_with_base_pose_replaces_or_adds_and_keeps_the_rest():
    text = (EXAMPLES / "panda_on_table.yaml").read_text()
    new = with_base_pose(text, (0.4, 0.1, 0.75), (0, 0, 90))
    assert yaml.safe_load(new)["base_pose"] == {"xyz": [0.4, 0.1, 0.75], "rpy_deg": [0, 0, 90]}
    assert new.count("base_pose:") == 1 and "# A panda on a table" in new
    assert new.replace(new.splitlines()[5], "") == text.replace(text.splitlines()[5], "")
    block = "robot: ur5  # the arm\nbase_pose:\n  xyz: [1, 2, 3]\n  rpy_deg: [0, 0, 0]\nstart: {}\n"
    replaced = with_base_pose(block, (0, 0, 0.5), (0, 0, 45))
    assert yaml.safe_load(replaced) == {
        "robot": "ur5",
        "base_pose": {"xyz": [0, 0, 0.5], "rpy_deg": [0, 0, 45]},
        "start": {},
    }
    added = with_base_pose("robot: ur5  # the arm\nstart: {}\n", (0.1, -0.0, 0), (0, 0, 0))
    assert added.splitlines()[1] == "base_pose: {xyz: [0.1, 0, 0], rpy_deg: [0, 0, 0]}"
    with pytest.raises(kinplan.InputError, match="robot"):
        with_base_pose("start: {}\n", (0, 0, 0), (0, 0, 0))


def test_place_ranks_planned_poses_first_and_writes_the_best(tmp_path):
    search = place(EXAMPLES / "lecture_2r.yaml", x=(-0.2, 0.2), y=(-0.1, 0.0), step=0.1)
    assert len(search.placements) == 5 * 2
    keys = [p.rank_key for p in search.placements]
    assert keys == sorted(keys)
    ok = [p for p in search.placements if p.ok]
    assert ok and all(p.margin > 0 for p in ok)
    assert all(not p.ok for p in search.placements[len(ok) :])
    # a shift toward +x puts the final point (-1.366, 1.366) beyond the 2 m reach
    assert all(p.xyz[0] <= 0.0 for p in ok)
    best = search.best
    written = search.write_best(tmp_path / "best.yaml")
    program = load_program(written)
    np.testing.assert_allclose(program.robot.base_pose.translation, best.xyz, atol=1e-12)
    plan = run_program(written)
    assert plan.ok and plan.manipulability.min() == pytest.approx(best.min_manipulability)
    png = heat_map(search, tmp_path / "heat.png")
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_place_keeps_roll_pitch_and_default_z_yaw():
    search = place(EXAMPLES / "panda_on_table.yaml", x=(0.5,), y=(0.2,))
    (only,) = search.placements
    assert only.xyz == pytest.approx((0.5, 0.2, 0.75)) and only.rpy_deg == pytest.approx(
        (0, 0, 180)
    )
    assert only.ok
    original = run_program(EXAMPLES / "panda_on_table.yaml")
    assert only.duration == pytest.approx(original.duration)


def test_place_misuse(tmp_path):
    with pytest.raises(kinplan.InputError, match="range"):
        place(EXAMPLES / "lecture_2r.yaml", x=(1.0, 0.0), y=(0.0,))
    with pytest.raises(kinplan.InputError, match="candidate"):
        place(EXAMPLES / "lecture_2r.yaml", x=(0, 100), y=(0, 100), step=0.01)
    bad = tmp_path / "bad.yaml"
    bad.write_text("robot: planar_2r\nstart: {joints: [0]}\npoints: {}\nmoves: []\n")
    with pytest.raises(kinplan.KinplanError, match="does not validate"):
        place(bad, x=(0.0,), y=(0.0,))


def test_cli_run_several_programs(capsys):
    ok = [str(EXAMPLES / "lecture_2r.yaml"), str(EXAMPLES / "ur5_pick_place.yaml")]
    assert main(["run", *ok]) == 0
    out = capsys.readouterr().out
    assert "2 programs" in out and "ok: 2 programs planned" in out
    assert main(["run", *ok, str(EXAMPLES / "weld_unreachable.yaml")]) == 1
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1
    assert captured.err.startswith("kinplan: error: 1 of 3 programs failed; ")
    assert main(["run", *ok, "--html", "x.html"]) == 1
    assert "one PROGRAM.yaml" in capsys.readouterr().err
    assert main(["run", ok[0], "--jobs", "0"]) == 2


def test_cli_place_and_reach(tmp_path, capsys):
    best = tmp_path / "best.yaml"
    code = main(
        ["place", str(EXAMPLES / "lecture_2r.yaml"), "--x", "-0.1", "0.1", "--y", "0"]
        + ["--step", "0.1", "-o", str(best), "--png", str(tmp_path / "heat.png")]
    )
    assert code == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "2 of 3 base poses plan" in out and f"wrote {best}" in out
    assert parse_program(best.read_text(), base_dir=EXAMPLES).robot.base_pose != pin.SE3.Identity()
    code = main(
        [
            "place",
            str(EXAMPLES / "lecture_2r.yaml"),
            "--x",
            "1",
            "--y",
            "1",
            "-o",
            str(tmp_path / "x.yaml"),
        ]
    )
    assert code == 1 and not (tmp_path / "x.yaml").exists()
    assert "no base pose of the grid plans" in capsys.readouterr().err
    out_map = tmp_path / "m.npz"
    code = main(
        ["reach", "ur5", "-o", str(out_map), "--resolution", "0.3", "--orientations", "4"]
        + ["--direction", "0", "0", "-1", "--cone-deg", "30", "--png", str(tmp_path / "s")]
        + ["--html", str(tmp_path / "m.html")]
    )
    assert code == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "tool z within 30°" in out and f"wrote {out_map}" in out
    assert (tmp_path / "s.png").is_file() and (tmp_path / "m.html").is_file()
    assert main(["reach", "ur5", "-o", str(out_map), "--cone-deg", "20"]) == 1
    assert "--cone-deg needs --direction" in capsys.readouterr().err


PILLAR_CELL = """robot: ur5
obstacles:
  pillar: {box: [0.1, 0.1, 1.0], xyz: [0.0, 0.0, 0.5]}
clearance: 0.01
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.45, 0.25, 0.3], rpy_deg: [180, 0, -90]}
  b: {xyz: [0.45, 0.45, 0.3]}
moves:
  - {ptp: a}
  - {lin: b, speed: 0.1}
"""


def test_placement_honours_the_programs_obstacles(tmp_path):
    """Issue 28: the program's obstacles stay in the world while the base moves. A base on the
    pillar collides at once, one beside it comes inside the 10 mm clearance on the way, and
    the base poses that plan keep the clearance; re-planning the best one as a program gives
    its figures back."""
    program = tmp_path / "pillar.yaml"
    program.write_text(PILLAR_CELL, encoding="utf-8")
    search = place(program, x=[0.0, 0.3], y=[-0.2, 0.0], step=0.1)
    by_xy = {p.xyz[:2]: p for p in search.placements}
    for y in (-0.2, -0.1, 0.0):
        on_it = by_xy[(0.0, y)]
        assert not on_it.ok and "collides with pillar" in on_it.reason and on_it.clearance < 0
        assert "collision at s = 0.00" in on_it.reason  # the start itself
        near = by_xy[(0.2, y)]
        assert not near.ok and "of pillar" in near.reason and "inside the clearance" in near.reason
        assert 0 < near.clearance < 0.01
    fine = [p for p in search.placements if p.ok]
    assert fine and all(p.clearance >= 0.01 for p in fine)
    best = search.placements[0]
    assert best.ok and best.xyz[:2] == (0.3, -0.2)
    again = plan_program(parse_program(with_base_pose(PILLAR_CELL, best.xyz, best.rpy_deg)))
    assert again.ok and again.min_clearance == pytest.approx(best.clearance, abs=1e-12)
