"""Capability maps: right answers on arms with known workspaces, files, pictures, orientations.

The engines (in-process, LocalCluster, remote scheduler) are tested in test_engines.py.
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest
from conftest import REPOSITORY, TESTS

import kinplan
from kinplan.errors import KinplanError
from kinplan.scale.reach import ReachMap, capability_map, orientation_set


def test_orientation_sets_are_rotations_spread_over_the_group():
    rotations = orientation_set(64)
    assert rotations.shape == (64, 3, 3)
    np.testing.assert_allclose(
        rotations @ np.swapaxes(rotations, 1, 2), np.tile(np.eye(3), (64, 1, 1)), atol=1e-12
    )
    np.testing.assert_allclose(np.linalg.det(rotations), 1.0, atol=1e-12)
    # spread: every tool z axis has a neighbour within 45°, and no two are the same
    z = rotations[:, :, 2]
    cosines = z @ z.T - 2.0 * np.eye(64)
    assert cosines.max(axis=1).min() > np.cos(np.radians(45))
    assert np.all(np.abs(z.mean(axis=0)) < 0.1)
    np.testing.assert_array_equal(orientation_set(64), rotations)  # deterministic


@pytest.mark.parametrize("cone", [0.0, 20.0, 90.0])
def test_cone_orientations_keep_the_tool_axis_within_the_cone(cone):
    direction = np.array([0.2, -0.3, -1.0])
    rotations = orientation_set(32, direction, cone)
    unit = direction / np.linalg.norm(direction)
    angles = np.degrees(np.arccos(np.clip(rotations[:, :, 2] @ unit, -1, 1)))
    assert angles.max() <= cone + 1e-9
    np.testing.assert_allclose(np.linalg.det(rotations), 1.0, atol=1e-12)
    rolls = np.arctan2(rotations[:, 1, 0], rotations[:, 0, 0])
    assert np.ptp(rolls) > np.pi  # the roll about the axis is spread


def test_orientation_set_rejects_bad_input():
    with pytest.raises(kinplan.InputError):
        orientation_set(0)
    with pytest.raises(kinplan.InputError, match="non-zero"):
        orientation_set(4, [0, 0, 0], 10)
    with pytest.raises(kinplan.InputError):
        orientation_set(4, [0, 0, 1], 200)


@pytest.mark.parametrize("lengths", [(1.0, 1.0), (1.0, 0.25)])
def test_planar_map_is_the_annulus(lengths):
    robot = kinplan.planar_arm(lengths)
    r_min, r_max = robot.planar_reach()
    reach_map = capability_map(robot, resolution=0.1)
    assert reach_map.orientations == 1 and reach_map.shape[2] == 1
    r = np.linalg.norm(reach_map.centers[:, :2], axis=1)
    clear = (np.abs(r - r_max) > 1e-6) & (np.abs(r - r_min) > 1e-6)
    inside = (r > r_min) & (r < r_max)
    np.testing.assert_array_equal(reach_map.index[clear], inside[clear].astype(float))
    assert reach_map.info["method"] == "closed-form"
    # the lecture's manipulability l1·l2·|sin θ2| at the solution found
    k = int(np.argmax(reach_map.manipulability))
    assert reach_map.manipulability[k] <= lengths[0] * lengths[1] + 1e-12


def test_ur5_map_counts_what_ik_reaches():
    robot = kinplan.load_robot("ur5")
    reach_map = capability_map(robot, resolution=0.25, orientations=6)
    rotations = orientation_set(6)
    assert reach_map.info["poses"] == 6 * reach_map.info["solved_voxels"]
    assert np.all(
        np.linalg.norm(reach_map.centers[reach_map.reachable] - reach_map.shoulder, axis=1)
        <= robot.reach()
    )
    rng = np.random.default_rng(0)
    for k in rng.choice(len(reach_map.index), 12, replace=False):
        centre = reach_map.centers[k]
        results = [robot.ik(pin.SE3(R, centre)) for R in rotations]
        assert reach_map.index[k] == sum(r.success for r in results) / 6, centre
        if any(r.success for r in results):
            best = max(robot.manipulability(r.q) for r in results if r.success)
            np.testing.assert_allclose(reach_map.manipulability[k], best, rtol=1e-9)
            assert reach_map.branches[k] != 0
        else:
            assert reach_map.manipulability[k] == 0.0 and reach_map.branches[k] == 0


def test_torch_down_cone_map_in_front_of_the_ur5():
    robot = kinplan.load_robot("ur5")
    region = ((0.3, 0.6), (-0.15, 0.15), (0.0, 0.3))
    down = capability_map(robot, 0.1, 8, region=region, direction=(0, 0, -1), cone_deg=20)
    assert down.direction.tolist() == [0.0, 0.0, -1.0] and down.cone_deg == 20.0
    assert down.index.min() == 1.0  # a table in front of the arm: torch down everywhere
    up = capability_map(robot, 0.1, 8, region=((0.0, 0.1), (0.0, 0.1), (1.3, 1.4)))
    assert up.index.max() == 0.0  # beyond the reach


def test_numerical_arm_map_uses_the_batch_solver(tmp_path):

    robot = kinplan.load_robot(TESTS / "urdf" / "skewed_axes.urdf")
    reach_map = capability_map(robot, resolution=0.3, orientations=2)
    assert reach_map.info["method"] == "levenberg-marquardt"
    assert reach_map.reachable.any()
    assert not reach_map.branches.any()  # no branch information without a closed form


def test_save_load_round_trip(tmp_path):
    robot = kinplan.load_robot("ur5")
    reach_map = capability_map(robot, resolution=0.3, orientations=4)
    path = reach_map.save(tmp_path / "maps" / "ur5.npz")
    loaded = ReachMap.load(path)
    for name in ("centers", "index", "manipulability", "branches"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(reach_map, name))
    assert (loaded.robot, loaded.tip, loaded.resolution) == ("ur5", "tool0", 0.3)
    assert loaded.kinplan_version == kinplan.__version__ and loaded.shape == reach_map.shape
    assert loaded.info["urdf_sha256"] == reach_map.info["urdf_sha256"]
    meta = json.loads(str(np.load(path)["meta"]))
    assert meta["robot"] == "ur5" and meta["resolution"] == 0.3 and meta["kinplan_version"]
    assert [p.name for p in path.parent.iterdir()] == ["ur5.npz"]  # no temporary left
    assert loaded.lookup(reach_map.centers[5]) == reach_map.index[5]
    assert loaded.lookup([[50.0, 0, 0]]).tolist() == [0.0]


def test_interrupted_save_leaves_no_file(tmp_path, monkeypatch):
    robot = kinplan.load_robot("planar_2r")
    reach_map = capability_map(robot, resolution=0.5)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        reach_map.save(tmp_path / "map.npz")
    assert list(tmp_path.iterdir()) == []


def test_load_refuses_other_files(tmp_path):
    other = tmp_path / "other.npz"
    np.savez(other, x=np.zeros(3))
    with pytest.raises(KinplanError, match="not a kinplan reachability map"):
        ReachMap.load(other)
    with pytest.raises(KinplanError, match="no map file"):
        ReachMap.load(tmp_path / "missing.npz")


def test_png_slices_and_meshcat_page(tmp_path):
    robot = kinplan.load_robot("ur5")
    reach_map = capability_map(robot, resolution=0.25, orientations=4)
    values, extent, plane = reach_map.slice("y")
    assert values.shape == (reach_map.shape[2], reach_map.shape[0])
    assert plane == pytest.approx(reach_map.shoulder[1], abs=0.125)
    png = reach_map.save_png(tmp_path / "slice.png", axes=("z", "y", "x"))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = reach_map.save_html(tmp_path / "map.html", robot=robot).read_text()
    assert "MeshCat.Viewer" in page and "handle_command_bytearray" in page
    assert "ur5" in page and "http://" not in page.split("<script>")[0]


def test_cell_obstacles_remove_reach(tmp_path):
    robot = kinplan.load_robot("ur5")
    region = ((0.35, 0.55), (-0.1, 0.1), (0.1, 0.2))
    free = capability_map(robot, 0.1, 4, region=region, direction=(0, 0, -1), cone_deg=10)
    cell = kinplan.WorkCell(robot)
    cell.add_box("block", (0.4, 0.4, 0.4), pin.SE3(np.eye(3), np.array([0.45, 0.0, 0.1])))
    blocked = capability_map(
        robot, 0.1, 4, region=region, cell=cell, direction=(0, 0, -1), cone_deg=10
    )
    assert free.index.min() == 1.0
    assert blocked.index.max() == 0.0  # the tool would be inside the block
    assert blocked.info["cell"] == ["block"]


def test_bad_arguments():
    robot = kinplan.load_robot("planar_2r")
    with pytest.raises(kinplan.InputError):
        capability_map(robot, resolution=0.0)
    with pytest.raises(kinplan.InputError, match="region"):
        capability_map(robot, region=((1, 0), (0, 1), (0, 1)))
    with pytest.raises(kinplan.InputError, match="engine"):
        capability_map(robot, resolution=0.5, engine="spark")
    with pytest.raises(kinplan.InputError, match="Robot"):
        capability_map("planar_2r")


def test_the_example_runs(tmp_path):
    import importlib.util

    path = REPOSITORY / "examples" / "reach_map.py"
    spec = importlib.util.spec_from_file_location("reach_map_example", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    maps = example.main(tmp_path, resolution=0.3, orientations=4)
    assert (tmp_path / "reach_ur5.png").is_file()
    both = maps["every"].reachable & maps["down"].reachable
    assert both.any()
