"""Tests of kinplan.viewer: the self-contained HTML page and the MeshCat scene inside it.

The scene is read back from the page (the embedded msgpack commands) and checked against an
independent forward kinematics (yourdfpy), against the motion's own times and against the
plan's path. Motions are the real ``kinplan.trajectory`` / ``cartesian`` objects where that
matters, and small stand-ins with exactly the documented attributes elsewhere.
"""

from __future__ import annotations

import re
import types
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from pages import animation, objects, page_parts, transforms

import kinplan
from kinplan import viewer
from kinplan.errors import InputError, KinplanError
from kinplan.trajectory.motion import PlannedPath, no_waypoints, pose_to_track
from kinplan.viewer import commands as ms

UR5_Q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
UR5_Q1 = np.array([1.2, -1.0, 1.0, -1.5, -1.57, 0.5])
ALLOWED_URLS = {"http://www.w3.org/1999/xhtml"}  # XML namespace names in three.js, not loads


# ----------------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------------


def cubic_stand_in(q0, q1, duration: float, waypoints=None) -> types.SimpleNamespace:
    """A Trajectory stand-in: ``duration`` and ``sample(t) -> (q, qd, qdd)``."""
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)

    def sample(t):
        s = np.clip(np.asarray(t, float) / duration, 0.0, 1.0)
        h = 3 * s**2 - 2 * s**3
        q = q0 + np.multiply.outer(h, q1 - q0)
        return q, np.zeros_like(q), np.zeros_like(q)

    motion = types.SimpleNamespace(duration=duration, sample=sample)
    if waypoints is not None:
        motion.waypoints = waypoints
    return motion


def line_plan_stand_in(robot, q0, delta, duration: float, fail_at: float | None, dt=0.01):
    """A CartesianPlan stand-in: a straight tool line, stopped by an event at ``fail_at``.

    It has exactly what :class:`kinplan.trajectory.motion.SampledMotion` asks of a plan (no tool
    positions:
    the viewer computes them).
    """
    start = robot.fk(q0)
    p0, p1 = start.translation.copy(), start.translation + np.asarray(delta, float)
    path = types.SimpleNamespace(
        length=float(np.linalg.norm(p1 - p0)),
        position=lambda s: p0 + np.multiply.outer(np.atleast_1d(s), p1 - p0),
    )
    t = np.arange(0.0, duration + 1e-9, dt)
    s = t / duration
    n = len(t) if fail_at is None else int(np.searchsorted(s, fail_at))
    qs, q = [], np.asarray(q0, float)
    for sk in s[:n]:
        q = robot.ik(pin.SE3(start.rotation, path.position(sk)[0]), q_seed=q).q
        qs.append(q)
    events = []
    if fail_at is not None:
        events.append(
            types.SimpleNamespace(
                kind="unreachable",
                t=float(t[n]),
                s=float(s[n]),
                index=n,
                message=f"no IK solution at s = {s[n]:.2f}",
            )
        )
    q = np.array(qs).reshape(-1, robot.nq)
    return types.SimpleNamespace(
        kind="cartesian",
        description=f"Cartesian path {path.length:.3f} m",
        t=t[:n],
        q=q,
        qd=np.zeros_like(q),
        qdd=np.zeros_like(q),
        robot=robot,
        tool_positions=None,
        planned_paths=[PlannedPath(path, events[0].s if events else 1.0)],
        waypoints=no_waypoints(robot.nq),
        moves=(),
        ok=not events,
        status=events[0].kind if events else "ok",
        events=events,
        path=path,
    )


def visibility(commands: list[dict]) -> dict[str, tuple[np.ndarray, list[bool]]]:
    """path -> (key times, visible from each) of the page's visibility clips."""
    (command,) = [c for c in commands if c["type"] == "set_animation"]
    clips = {}
    for entry in command["animations"]:
        for track in entry["clip"]["tracks"]:
            if track["name"] == ".visible":
                clips[entry["path"]] = (ms.ext_array(track["times"], np.float32), track["values"])
    return clips


def yourdfpy_link_pose(robot, q, link: str) -> np.ndarray:
    """Pose of a URDF link's first visual in the base frame, by yourdfpy (independent FK)."""
    urdf = yourdfpy.URDF.load(
        str(robot.urdf_path),
        load_meshes=False,
        build_collision_scene_graph=False,
        load_collision_meshes=False,
    )
    urdf.update_cfg(dict(zip(robot.joint_names, np.asarray(q, dtype=float))))
    pose = urdf.get_transform(link, urdf.base_link)
    origin = urdf.link_map[link].visuals[0].origin
    return pose @ (np.eye(4) if origin is None else origin)


def quaternion_matrix(xyzw: np.ndarray) -> np.ndarray:
    x, y, z, w = (float(v) for v in xyzw)
    return pin.Quaternion(w, x, y, z).normalized().matrix()


@pytest.fixture(scope="module")
def real_trajectory():
    """kinplan.trajectory when it exists, else None."""
    try:
        from kinplan import trajectory
    except ImportError:
        return None
    return trajectory


# ----------------------------------------------------------------------------------------------
# The page
# ----------------------------------------------------------------------------------------------


def test_planar_trajectory_page_is_self_contained_and_animated(tmp_path, planar_2r):
    motion = cubic_stand_in([0.2, 0.5], [1.5, 1.2], duration=2.0)
    path = viewer.save_html(planar_2r, motion, tmp_path / "planar.html", fps=25)

    assert path == tmp_path / "planar.html" and path.is_file()
    text = path.read_text(encoding="utf-8")
    assert path.stat().st_size < 2_000_000, f"{path.stat().st_size} bytes"
    assert "MeshCat.Viewer" in text  # MeshCat's bundle is inline
    assert not re.search(r"<(script|img|iframe)[^>]*\ssrc\s*=|<link\b|@import", text)
    assert set(re.findall(r"https?://[^\s\"'<>)\\]*", text)) <= ALLOWED_URLS

    commands, config = page_parts(text)
    assert config["duration"] == pytest.approx(2.0)
    clips = animation(commands)
    robot_clips = [p for p in clips if p.startswith(viewer.LAYERS["robot"] + "/")]
    assert len(robot_clips) == 4  # two links, each a link cylinder and a joint housing
    assert viewer.LAYERS["tool"] in clips
    times = clips[robot_clips[0]]["times"]
    np.testing.assert_allclose(times, np.arange(51) / 25, atol=1e-6)  # real time, 25 key/s


def test_ur5_page_size_and_mesh_colours(tmp_path, ur5):
    path = viewer.save_html(ur5, cubic_stand_in(UR5_Q0, UR5_Q1, 3.0), tmp_path / "ur5.html")
    size = path.stat().st_size
    assert 1_500_000 < size < 6_000_000, f"{size} bytes"  # meshes inline, compactly
    commands, _ = page_parts(path.read_text(encoding="utf-8"))
    parts = {p: o for p, o in objects(commands).items() if p.startswith("/kinplan/robot/")}
    assert len(parts) == 7
    geometry = parts["/kinplan/robot/upper_arm_link_0"]["geometries"][0]
    assert geometry["type"] == "BufferGeometry"
    attributes = geometry["data"]["attributes"]
    assert attributes["position"]["type"] == "Float32Array"
    assert attributes["normal"]["type"] == "Int8Array"
    colours = ms.ext_array(attributes["color"]["array"], np.uint8).reshape(-1, 3)
    assert len(np.unique(colours, axis=0)) >= 2  # the DAE's materials (grey, blue cap)


def test_page_options_are_documented_layers(tmp_path, planar_2r):
    path = viewer.save_html(planar_2r, cubic_stand_in([0, 0], [1, 1], 1.0), tmp_path / "a.html")
    _, config = page_parts(path.read_text(encoding="utf-8"))
    assert set(config["layers"]) == {"robot", "tool", "path", "markers", "cell", "grid", "axes"}
    assert np.all(np.isfinite(config["camera_target"]))


# ----------------------------------------------------------------------------------------------
# Geometry placements: independent forward kinematics
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "q0", "q1", "links"),
    [
        ("ur5", UR5_Q0, UR5_Q1, ["upper_arm_link", "wrist_3_link"]),
        (
            "panda",
            [0, -0.5, 0, -2.0, 0, 1.6, 0.8],
            [1, 0.2, 0.3, -1.5, 0.2, 1.8, 0.5],
            ["panda_hand"],
        ),
        ("planar_2r", [0.3, 1.1], [1.5, -0.4], ["link2"]),
    ],
)
def test_placements_match_yourdfpy_and_robot_fk(tmp_path, name, q0, q1, links):
    robot = kinplan.load_robot(name)
    motion = cubic_stand_in(q0, q1, 2.0)
    path = viewer.save_html(robot, motion, tmp_path / f"{name}.html", fps=10)
    commands, _ = page_parts(path.read_text(encoding="utf-8"))

    placed = transforms(commands)  # the scene before the animation starts: q0
    for link in links:
        expected = yourdfpy_link_pose(robot, q0, link)
        np.testing.assert_allclose(placed[f"/kinplan/robot/{link}_0"], expected, atol=1e-5)
    np.testing.assert_allclose(placed["/kinplan/tool"], robot.fk(q0).homogeneous, atol=1e-5)

    clips = animation(commands)
    k = 13  # a key frame in the middle of the motion
    t_k = float(clips[viewer.LAYERS["tool"]]["times"][k])
    q_k = motion.sample(np.array([t_k]))[0][0]
    for link in links:
        clip = clips[f"/kinplan/robot/{link}_0"]
        expected = yourdfpy_link_pose(robot, q_k, link)
        np.testing.assert_allclose(clip["position"][k], expected[:3, 3], atol=1e-5)
        np.testing.assert_allclose(
            quaternion_matrix(clip["quaternion"][k]), expected[:3, :3], atol=1e-5
        )
    tool = clips[viewer.LAYERS["tool"]]
    np.testing.assert_allclose(tool["position"][k], robot.fk(q_k).translation, atol=1e-5)


# ----------------------------------------------------------------------------------------------
# Motions
# ----------------------------------------------------------------------------------------------


def test_cartesian_plan_with_event_draws_the_failure(tmp_path, ur5):
    plan = line_plan_stand_in(ur5, UR5_Q0, [0.0, 0.0, 0.3], duration=2.0, fail_at=0.6)
    path = viewer.save_html(ur5, plan, tmp_path / "plan.html", markers={"goal": [0.5, 0.1, 0.4]})
    text = path.read_text(encoding="utf-8")
    commands, config = page_parts(text)

    assert config["duration"] == pytest.approx(plan.t[-1])
    assert "unreachable at 60 % of the path" in text
    assert "no IK solution at s = 0.60" in text
    drawn = objects(commands)
    assert {"/kinplan/path/planned0", "/kinplan/path/achieved", "/kinplan/path/failed0"} <= set(
        drawn
    )
    assert "/kinplan/markers/goal" in drawn
    # The red part starts where the event happened and ends at the path's end.
    red = drawn["/kinplan/path/failed0"]["geometries"][0]["data"]["attributes"]["position"]
    red = ms.ext_array(red["array"], np.float32).reshape(-1, 3)
    tube_radius = np.linalg.norm(red[0] - red[:10].mean(axis=0))
    for s in (plan.events[0].s, 1.0):
        distance = np.linalg.norm(red - plan.path.position(s)[0], axis=1).min()
        assert distance == pytest.approx(tube_radius, rel=0.05)
    # The last good pose is highlighted at the tool pose of the last achieved sample.
    placed = transforms(commands)
    np.testing.assert_allclose(
        placed["/kinplan/path/last_good"], ur5.fk(plan.q[-1]).homogeneous, atol=1e-5
    )


def test_plan_that_failed_at_once_shows_the_robot_still(tmp_path, planar_2r):
    plan = line_plan_stand_in(planar_2r, [0.3, 1.2], [3.0, 0.0, 0.0], 1.0, fail_at=0.0)
    assert len(plan.q) == 0
    text = viewer.render_html(planar_2r, plan)
    commands, config = page_parts(text)
    assert config["duration"] == 0.0
    assert not [c for c in commands if c["type"] == "set_animation"]
    assert "/kinplan/path/failed0" in objects(commands)


def test_real_trajectory_with_waypoints(tmp_path, ur5, real_trajectory):
    if real_trajectory is None:
        pytest.skip("kinplan.trajectory is not available")
    via = 0.5 * (UR5_Q0 + UR5_Q1) + 0.2
    motion = real_trajectory.cubic_via([UR5_Q0, via, UR5_Q1], [0.0, 1.0, 2.5])
    path = viewer.save_html(ur5, motion, tmp_path / "via.html", fps=20)
    commands, config = page_parts(path.read_text(encoding="utf-8"))
    assert config["duration"] == pytest.approx(2.5)
    markers = {p: o for p, o in objects(commands).items() if p.startswith("/kinplan/markers/via")}
    assert len(markers) == 3
    centres = sorted(tuple(np.round(o["object"]["matrix"][12:15], 6)) for o in markers.values())
    expected = sorted(tuple(np.round(ur5.fk(q).translation, 6)) for q in (UR5_Q0, via, UR5_Q1))
    np.testing.assert_allclose(centres, expected, atol=1e-5)


def test_real_cartesian_plan(tmp_path, planar_2r):
    cartesian = pytest.importorskip("cartesian")
    if not hasattr(cartesian, "follow"):
        pytest.skip("cartesian.follow is not available")
    arc = cartesian.Arc([1.2, 0.3, 0.0], [0.6, 1.3, 0.0], [-0.9, 1.5, 0.0])
    plan = cartesian.follow(planar_2r, arc, duration=2.0, q_seed=[0.2, 1.2])
    path = viewer.save_html(planar_2r, plan, tmp_path / "arc.html")
    commands, config = page_parts(path.read_text(encoding="utf-8"))
    assert config["duration"] == pytest.approx(plan.t[-1])
    assert "/kinplan/path/planned0" in objects(commands)


def wall_plan(robot):
    """A real Cartesian plan of the UR5 stopped by a thin wall across its line (a collision of
    the wrist and the wall at a sample), in a cell that also has a table."""
    import cartesian

    start = robot.fk(UR5_Q0)
    line = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    cell = kinplan.WorkCell(robot)
    cell.add_box("table", [1.2, 0.8, 0.04], pin.SE3(np.eye(3), np.array([0.3, 0.0, -0.02])))
    cell.add_box("wall", [0.3, 0.004, 0.4], pin.SE3(np.eye(3), line.position(np.array([0.5]))[0]))
    plan = cartesian.follow(robot, line, speed=0.2, q_seed=UR5_Q0, cell=cell)
    assert plan.status == "collision" and plan.cell_check.bodies[1] == "wall"
    return plan


def test_a_collision_turns_the_two_bodies_red_at_the_failing_instant(tmp_path, ur5):
    """The link and the obstacle of the failing pair get red copies (``<node>/hit``), hidden
    until the failing instant and shown from then on while the originals are hidden; the
    playback ends at that instant (the failing sample, which the plan does not keep) with the
    robot at the colliding configuration; the other obstacle stays as it is."""
    from kinplan.viewer.visuals import visuals_for

    plan = wall_plan(ur5)
    check = plan.cell_check
    link = check.bodies[0]
    text = viewer.render_html(ur5, plan)
    commands, config = page_parts(text)
    failing = plan.events[0].t  # the failing sample's time: the plan stops before it
    assert failing > plan.t[-1] and not check.between
    assert config["duration"] == pytest.approx(failing)
    visuals = visuals_for(ur5)
    parts = [p.name for p, owner in zip(visuals.parts, visuals.part_links) if owner == link]
    assert parts
    nodes = [f"/kinplan/robot/{part}" for part in parts] + ["/kinplan/cell/wall"]
    drawn = objects(commands)
    red = drawn["/kinplan/cell/collision"]["materials"][0]["color"]  # the red ball
    assert {p for p in drawn if p.endswith("/hit")} == {f"{node}/hit" for node in nodes}
    for node in nodes:
        assert drawn[f"{node}/hit"]["materials"][0]["color"] == red
        assert drawn[f"{node}/hit"]["object"]["matrix"] == drawn[node]["object"]["matrix"]
    assert drawn["/kinplan/cell/wall"]["materials"][0]["color"] != red
    hidden_first = {
        c["path"] for c in commands if c["type"] == "set_property" and c["value"] is False
    }
    clips = visibility(commands)
    for path in [f"{node}/hit" for node in nodes] + ["/kinplan/cell/collision"]:
        assert path in hidden_first  # hidden until the instant
        times, shown = clips[path]
        assert shown == [False, True] + [True] * (len(times) - 2)
        assert times[0] == 0.0 and times[1] == pytest.approx(failing, abs=2e-4)
        assert times[-1] == pytest.approx(failing, abs=1e-6)  # as long as the pose clips
    for node in nodes:
        times, shown = clips[f"{node}/<object>"]
        assert shown[:2] == [True, False] and times[1] == pytest.approx(failing, abs=2e-4)
    assert not any(path.startswith("/kinplan/cell/table") for path in clips)
    assert f"collision: {link} – wall" in text
    # the last key frame places the link's parts at the colliding configuration
    poses = animation(commands)
    placed, _ = visuals.placements(check.q)
    for part in parts:
        clip = poses[f"/kinplan/robot/{part}"]
        assert clip["times"][-1] == pytest.approx(failing, abs=1e-6)
        index = [p.name for p in visuals.parts].index(part)
        np.testing.assert_allclose(clip["position"][-1], placed[index][:3, 3], atol=1e-6)


def test_a_collision_between_two_samples_is_shown_where_it_happens(ur5):
    """A fin crossed between two samples 0.5 s apart: the plan keeps the first sample, and the
    playback ends at the configuration between them where the check found the collision, at
    the same fraction of the time between the samples."""
    from kinplan.viewer.playback import playback

    q_a, q_b = UR5_Q0 + [-0.3, 0, 0, 0, 0, 0], UR5_Q0 + [0.3, 0, 0, 0, 0, 0]
    cell = kinplan.WorkCell(ur5)
    cell.add_box("fin", (0.06, 0.002, 0.06), pin.SE3(np.eye(3), ur5.fk(UR5_Q0).translation))
    check = cell.check_motion(np.array([q_a, q_b]))
    assert check.index == 1 and check.between and 0 < check.fraction < 1
    event = types.SimpleNamespace(kind="collision", t=0.5, s=0.5, index=1, message="fin")
    plan = types.SimpleNamespace(
        kind="cartesian", description="a turn", t=np.zeros(1), q=q_a[None, :],
        qd=np.zeros((1, 6)), qdd=np.zeros((1, 6)), robot=ur5, tool_positions=None,
        planned_paths=[], waypoints=no_waypoints(6), moves=(), ok=False, status="collision",
        events=[event], cell=cell, cell_check=check,
    )  # fmt: skip
    played = playback(ur5, plan, 30.0)
    assert played.collision is not None and played.collision.bodies == check.bodies
    assert played.collision.t == pytest.approx(0.5 * check.fraction)
    np.testing.assert_allclose(played.t, [0.0, 0.5 * check.fraction])
    np.testing.assert_allclose(played.q[-1], check.q)
    commands, _ = page_parts(viewer.render_html(ur5, plan))
    assert "/kinplan/cell/fin/hit" in objects(commands)
    times, shown = visibility(commands)["/kinplan/cell/fin/hit"]
    assert shown[:2] == [False, True] and times[1] == pytest.approx(0.5 * check.fraction, abs=2e-4)


# ----------------------------------------------------------------------------------------------
# Misuse
# ----------------------------------------------------------------------------------------------


def test_wrong_joint_count_is_an_input_error(tmp_path, ur5):
    motion = cubic_stand_in([0.0, 0.0], [1.0, 1.0], 1.0)
    with pytest.raises(InputError, match=r"ur5 has 6 joints"):
        viewer.save_html(ur5, motion, tmp_path / "x.html")
    assert not (tmp_path / "x.html").exists()


@pytest.mark.parametrize(
    ("motion", "markers", "fps", "message"),
    [
        (object(), None, 30, "cannot play a object"),
        ("trajectory", None, 30, "cannot play a str"),
        ("cubic", [[0.0, 1.0]], 30, "marker 'p0' must be a position 3-vector"),
        ("cubic", {"a": [np.nan, 0, 0]}, 30, "marker 'a'"),
        ("cubic", None, 0.0, "fps must be a positive number"),
        ("cubic", None, float("nan"), "fps must be a positive number"),
        ("nan", None, 30, "NaN"),
    ],
)
def test_misuse_raises_kinplan_errors(tmp_path, planar_2r, motion, markers, fps, message):
    if motion == "cubic":
        motion = cubic_stand_in([0, 0], [1, 1], 1.0)
    elif motion == "nan":
        motion = cubic_stand_in([0, np.nan], [1, 1], 1.0)
    with pytest.raises(KinplanError, match=message):
        viewer.save_html(planar_2r, motion, tmp_path / "x.html", markers=markers, fps=fps)


def test_unwritable_path_is_a_viewer_error(tmp_path, planar_2r):
    motion = cubic_stand_in([0, 0], [1, 1], 1.0)
    (tmp_path / "a_file").write_text("")
    with pytest.raises(viewer.ViewerError, match="cannot write"):
        viewer.save_html(planar_2r, motion, tmp_path / "a_file" / "x.html")  # under a file
    written = viewer.save_html(planar_2r, motion, tmp_path / "missing" / "x.html")
    assert written.is_file()  # missing folders are created


# ----------------------------------------------------------------------------------------------
# Building blocks
# ----------------------------------------------------------------------------------------------


def test_primitive_visuals_of_a_urdf_without_meshes(tmp_path):
    urdf = tmp_path / "shapes.urdf"
    urdf.write_text(
        """<?xml version="1.0"?>
<robot name="shapes">
  <link name="base"><visual><geometry><box size="0.2 0.3 0.1"/></geometry></visual></link>
  <link name="arm">
    <visual><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.05" length="0.5"/></geometry>
    </visual>
    <visual><origin xyz="0 0 0.5"/><geometry><sphere radius="0.08"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>
"""
    )
    robot = kinplan.load_robot(urdf)
    commands, _ = page_parts(viewer.render_html(robot, cubic_stand_in([0.0], [0.8], 1.0)))
    kinds = {
        path.rsplit("/", 1)[1]: obj["geometries"][0]["type"]
        for path, obj in objects(commands).items()
        if path.startswith("/kinplan/robot/")
    }
    assert kinds == {
        "base_0": "BoxGeometry",
        "arm_0": "CylinderGeometry",
        "arm_1": "SphereGeometry",
    }
    # three.js cylinders run along y; URDF cylinders along z: the object turns y into z.
    cylinder = objects(commands)["/kinplan/robot/arm_0"]["object"]
    matrix = np.array(cylinder["matrix"]).reshape(4, 4).T
    np.testing.assert_allclose(matrix[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-12)


def test_pose_track_quaternions_match_pinocchio_and_are_continuous():
    rng = np.random.default_rng(3)
    rotations = [pin.exp3(rng.normal(size=3)) for _ in range(50)]
    poses = np.array([pin.SE3(r, rng.normal(size=3)).homogeneous for r in rotations])
    positions, quaternions = pose_to_track(poses)
    np.testing.assert_allclose(positions, poses[:, :3, 3])
    for quaternion, rotation in zip(quaternions, rotations):
        np.testing.assert_allclose(quaternion_matrix(quaternion), rotation, atol=1e-12)
    assert np.all(np.sum(quaternions[1:] * quaternions[:-1], axis=1) >= 0)


def test_tube_surrounds_the_polyline_at_its_radius():
    s = np.linspace(0.0, 1.0, 60)
    points = np.column_stack([np.cos(3 * s), np.sin(3 * s), 0.3 * s])
    vertices, normals, faces = ms.tube(points, radius=0.02, sides=8)
    assert vertices.shape == (60 * 8, 3) and faces.shape == (59 * 8 * 2, 3)
    centres = np.repeat(points, 8, axis=0)
    np.testing.assert_allclose(np.linalg.norm(vertices - centres, axis=1), 0.02, rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-9)
    assert ms.tube(points[:1], 0.02) is None


def test_packed_commands_round_trip():
    command = ms.set_transform("/a/b", pin.SE3.Random().homogeneous)
    back = ms.unpack(ms.pack(command))
    assert back["type"] == "set_transform" and back["path"] == "/a/b"
    np.testing.assert_allclose(back["matrix"], command["matrix"], rtol=1e-6, atol=1e-6)


# ----------------------------------------------------------------------------------------------
# Live viewer (binds localhost ports: one short test)
# ----------------------------------------------------------------------------------------------


def test_live_viewer_starts_plays_and_stops(planar_2r):
    with viewer.Viewer(planar_2r, timeout=20) as live:
        assert live.url.startswith("http://127.0.0.1:")
        process = live._process
        live.display([0.5, -0.5])
        live.play(cubic_stand_in([0.0, 0.0], [1.0, 1.0], 0.5), speed=2.0)
        live.play(cubic_stand_in([0.0, 0.0], [1.0, 1.0], 0.2), step=True, fps=20)
        with pytest.raises(InputError):
            live.display([0.5])
    assert process.poll() is not None  # the server stopped with the viewer
    live.close()  # twice is fine


def test_live_viewer_reports_a_missing_server(planar_2r):
    with pytest.raises(viewer.ViewerError, match="did not answer"):
        viewer.Viewer(planar_2r, zmq_url="tcp://127.0.0.1:9", timeout=0.5)


def test_modules_have_no_print_calls():
    for module in Path(viewer.__file__).parent.glob("*.py"):
        source = module.read_text(encoding="utf-8")
        assert not re.search(r"^\s*print\(", source, re.M), module.name


def test_simplified_polyline_stays_within_tolerance():
    s = np.linspace(0.0, 1.0, 2001)
    line = np.column_stack([s, 2 * s, np.zeros_like(s)])
    np.testing.assert_allclose(ms.simplify_polyline(line, 1e-4), line[[0, -1]])
    arc = np.column_stack([np.cos(s), np.sin(s), s])
    kept = ms.simplify_polyline(arc, 1e-4)
    assert 10 < len(kept) < 200
    # every original point lies within the tolerance of the simplified polyline
    a, b = kept[:-1], kept[1:]
    ab = b - a
    u = np.clip(np.einsum("pij,ij->pi", arc[:, None] - a, ab) / np.sum(ab * ab, axis=1), 0, 1)
    nearest = a + u[..., None] * ab
    assert np.linalg.norm(arc[:, None] - nearest, axis=2).min(axis=1).max() <= 1e-4 + 1e-12


def test_meshes_trimesh_cannot_read_are_embedded_as_files(monkeypatch):
    """Without a DAE reader (pycollada) the arm is still drawn: MeshCat parses the files."""
    import trimesh

    from kinplan.viewer import meshes, visuals

    def unreadable(*args, **kwargs):
        raise ImportError("no pycollada")

    robot = kinplan.load_robot("ur5")  # a new object: no cached visuals
    normal = visuals.RobotVisuals(robot)
    monkeypatch.setattr(trimesh, "load", unreadable)
    meshes.clear_mesh_caches()
    try:
        fallback = visuals.RobotVisuals(robot)
    finally:
        monkeypatch.undo()
        meshes.clear_mesh_caches()
    assert [p.name for p in fallback.parts] == [p.name for p in normal.parts]
    for a, b in zip(fallback.parts, normal.parts):
        geometry = a.obj["geometries"][0]
        assert geometry["type"] == "_meshfile_geometry" and geometry["format"] == "dae"
        assert "<COLLADA" in geometry["data"]
        np.testing.assert_allclose(a.bounds, b.bounds, atol=1e-5)


def test_the_playback_bar_names_the_move_under_way(planar_2r):
    """A program plan's moves reach the page as (start time, "number. label"), in time order,
    so the bar can name the move under way; a single motion has none."""
    from kinplan.program import MotionBuilder

    builder = MotionBuilder(planar_2r, np.array([0.3, 0.6]))
    builder.ptp_joints([0.8, 0.2], label="swing out")
    builder.ptp_joints([0.3, 0.6], label="back")
    plan = builder.finish()
    _, config = page_parts(viewer.render_html(planar_2r, plan))
    moves = config["moves"]
    assert [name for _, name in moves] == ["1. swing out", "2. back"]
    assert moves[0][0] == 0.0 and moves[1][0] == pytest.approx(plan.moves[1].t0)
    single = viewer.render_html(planar_2r, cubic_stand_in([0.0, 0.0], [0.5, 0.5], 1.0))
    assert page_parts(single)[1]["moves"] == []
