"""The viewer reads a URDF the way the loader does (issue 26): airo-models' UR5e-style files with
``drake:acceleration`` and no ``xmlns:drake`` load *and* play in a saved page."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import kinplan
from kinplan import trajectory, viewer
from kinplan.viewer.elements import read_urdf_elements

sys.path.append(str(Path(__file__).resolve().parents[1] / "model"))
from test_urdf_refusals import with_drake_accelerations  # noqa: E402


def test_a_urdf_with_an_undeclared_prefix_plays(tmp_path):
    path = with_drake_accelerations(tmp_path)
    robot = kinplan.load_robot(path, tip="tool0")
    visuals, collisions = read_urdf_elements(path)
    assert visuals and "wrist_3_link" in collisions
    motion = trajectory.quintic(robot.neutral(), robot.neutral() + 0.2, 1.0)
    page = viewer.save_html(robot, motion, tmp_path / "ur5e.html")
    text = Path(page).read_text()
    assert len(text) > 1_000_000  # the UR meshes are in the page (they were not read before)
    assert np.isfinite(robot.acceleration_limit).all()
