"""``kinplan reach ROBOT --cell PROGRAM.yaml``: the map counts only IK solutions clear of the
program's obstacles (issue 28): nothing under the table the robot stands on."""

from __future__ import annotations

import numpy as np
import pytest

from kinplan.apps.cli import main
from kinplan.scale.reach import ReachMap

PROGRAM = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
obstacles:
  table: {box: [1.6, 1.6, 0.04], xyz: [0.0, 0.0, -0.02]}
points:
  a: {joints_deg: [0, -90, 90, -90, -90, 0]}
moves:
  - {ptp: a}
"""


def test_reach_with_a_cell_leaves_out_the_poses_under_the_table(tmp_path, capsys):
    program = tmp_path / "cell.yaml"
    program.write_text(PROGRAM)
    common = ["reach", "ur5", "--resolution", "0.2", "--orientations", "4"]
    assert main([*common, "-o", str(tmp_path / "free.npz")]) == 0
    assert main([*common, "-o", str(tmp_path / "cell.npz"), "--cell", str(program)]) == 0
    free, cell = ReachMap.load(tmp_path / "free.npz"), ReachMap.load(tmp_path / "cell.npz")
    np.testing.assert_array_equal(free.centers, cell.centers)
    under = free.centers[:, 2] < -0.05  # voxel centres below the table top
    assert np.any(free.index[under] > 0)  # the bare arm reaches under the table
    assert np.all(cell.index[under] == 0)  # not through it
    assert np.all(cell.index <= free.index + 1e-12)


def test_reach_cell_without_obstacles_is_refused(tmp_path, capsys):
    program = tmp_path / "bare.yaml"
    program.write_text(PROGRAM.replace("obstacles:\n  table", "tablets:\n  table"))
    code = main(["reach", "ur5", "-o", str(tmp_path / "m.npz"), "--cell", str(program)])
    assert code != 0
    assert "has no obstacles" in capsys.readouterr().err


@pytest.mark.parametrize("missing", ["nowhere.yaml"])
def test_reach_cell_missing_file_is_a_one_line_error(tmp_path, capsys, missing):
    code = main(["reach", "ur5", "-o", str(tmp_path / "m.npz"), "--cell", str(tmp_path / missing)])
    assert code != 0
    assert "cannot read" in capsys.readouterr().err
