"""Work cells (issue 16): distances, self-collision pairs, motion checks between samples, tools.

Independent answers: coal called directly on the URDF's geometry built on Pinocchio's *full*
model (not kinplan's reduced one), closed-form sphere and box distances, and dense sampling of
the motions that ``check_motion`` certifies with its bounds.
"""

from __future__ import annotations

import functools
import logging
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh
from conftest import TESTS

import kinplan
from kinplan.cell import TOLERANCE, Body, CellError, WorkCell, xyz_rpy

#: Distances computed two ways by coal's analytic shape pairs agree to this [m].
EXACT = 1e-9
#: ... and through GJK (a convex hull against anything), whose tolerance is 1e-6 [m].
GJK = 2e-6

PROBE_URDF = """<?xml version="1.0"?>
<robot name="probe">
  <link name="base"/>
  <link name="arm">
    <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
  </link>
  <link name="hand">
    <collision><origin xyz="0.2 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="finger">
    <collision><origin xyz="-0.2 0 0"/><geometry><sphere radius="0.12"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <origin xyz="0.5 0 0"/>
    <parent link="arm"/><child link="hand"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
  <joint name="j3" type="revolute">
    <origin xyz="0.2 0 0"/>
    <parent link="hand"/><child link="finger"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
</robot>
"""
"""Three spheres on a planar chain: arm (r 0.1 at 0.5 m from j1, where j2 is), hand (r 0.05,
0.2 m past j2) and finger (r 0.12, 0.2 m back from j3, which is 0.2 m past j2): at q = 0 the
finger's sphere is centred on the arm's, so without an SRDF that non-adjacent pair is left
out."""


@functools.cache
def probe_robot(folder: str) -> kinplan.Robot:
    path = Path(folder) / "probe.urdf"
    path.write_text(PROBE_URDF)
    return kinplan.load_robot(path, tip="finger")


@pytest.fixture
def probe(tmp_path):
    return probe_robot(str(tmp_path))


@functools.cache
def ur5_cell() -> WorkCell:
    """The UR5 among a table (it stands on it), posts, a ball and thin plates."""
    cell = WorkCell(kinplan.load_robot("ur5"))
    cell.add_box("table", (1.4, 1.0, 0.04), xyz_rpy((0.2, 0.0, -0.02)))
    cell.add_cylinder("post", 0.04, 0.8, xyz_rpy((0.45, 0.25, 0.4)))
    cell.add_sphere("ball", 0.07, xyz_rpy((0.35, -0.35, 0.45)))
    cell.add_box("plate", (0.3, 0.004, 0.3), xyz_rpy((0.5, -0.05, 0.35), (0, 0, 20)))
    cell.add_box("shelf", (0.25, 0.25, 0.01), xyz_rpy((-0.4, 0.3, 0.55), (0, 10, 0)))
    return cell


UR5_HOME = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])


# ------------------------------------------------------------------------- distances
def closed_form_sphere_box(centre, radius, box_pose: pin.SE3, size) -> float:
    """Signed distance of a sphere and a box (penetration depth inside)."""
    local = box_pose.actInv(np.asarray(centre, dtype=float))
    half = np.asarray(size) / 2
    outside = np.maximum(np.abs(local) - half, 0.0)
    if np.any(outside > 0):
        return float(np.linalg.norm(outside)) - radius
    return -float(np.min(half - np.abs(local))) - radius


@pytest.mark.parametrize("angle", [0.0, 0.4, 1.3, 2.2, -2.7])
def test_distances_match_closed_form_spheres_and_boxes(probe, angle):
    cell = WorkCell(probe)
    ball = np.array([0.1, 0.55, 0.05])
    box = xyz_rpy((-0.3, -0.4, 0.1), (10, -20, 35))
    cell.add_sphere("ball", 0.08, ball)
    cell.add_box("crate", (0.3, 0.2, 0.25), box)
    q = np.array([angle, 0.5, -0.3])
    arm = np.array([0.5 * np.cos(angle), 0.5 * np.sin(angle), 0.0])
    got = {pair.bodies: pair.distance for pair in cell.pair_distances(q)}
    np.testing.assert_allclose(
        got[("arm", "ball")], np.linalg.norm(arm - ball) - 0.18, atol=EXACT, rtol=0
    )
    expected = closed_form_sphere_box(arm, 0.1, box, (0.3, 0.2, 0.25))
    np.testing.assert_allclose(got[("arm", "crate")], expected, atol=EXACT, rtol=0)


def test_sphere_inside_a_box_has_its_penetration_depth(probe):
    cell = WorkCell(probe)
    box = xyz_rpy((0.5, 0.02, 0.0))
    cell.add_box("block", (0.4, 0.5, 0.6), box)
    q = np.zeros(3)
    (hit,) = [c for c in cell.collisions(q) if c.bodies == ("arm", "block")]
    expected = closed_form_sphere_box((0.5, 0, 0), 0.1, box, (0.4, 0.5, 0.6))
    np.testing.assert_allclose(hit.distance, expected, atol=EXACT, rtol=0)
    assert hit.penetration == pytest.approx(0.3, abs=EXACT)  # 0.2 to the nearest face + 0.1


def full_model_geometry(robot):
    """The URDF's collision geometry on Pinocchio's full model, meshes as their convex hulls
    built by trimesh (not by kinplan's path through coal's qhull), as (model, geometry model,
    coal geometry of each object)."""
    model = pin.buildModelFromUrdf(str(robot.urdf_path))
    geometry = pin.buildGeomFromUrdf(
        model,
        str(robot.urdf_path),
        pin.GeometryType.COLLISION,
        package_dirs=[str(p) for p in robot.package_dirs],
    )
    shapes = []
    for obj in geometry.geometryObjects:
        shape = obj.geometry
        if isinstance(shape, coal.BVHModelBase):
            hull = trimesh.convex.convex_hull(np.asarray(shape.vertices()))
            points = coal.StdVec_Vec3s()
            for vertex in np.asarray(hull.vertices, dtype=float):
                points.append(vertex)
            triangles = coal.StdVec_Triangle()
            for face in np.asarray(hull.faces).tolist():
                triangles.append(coal.Triangle(*face))
            shape = coal.Convex(points, triangles)
        shapes.append(shape)
    return model, geometry, shapes


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_distances_match_coal_on_the_full_model(name):
    robot = kinplan.load_robot(name)
    cell = WorkCell(robot)
    obstacles = {
        "box": (coal.Box(0.3, 0.2, 0.1), xyz_rpy((0.4, 0.1, 0.3), (0, 30, 10))),
        "cyl": (coal.Cylinder(0.05, 0.4), xyz_rpy((0.3, -0.3, 0.4), (90, 0, 0))),
        "ball": (coal.Sphere(0.1), xyz_rpy((0.0, 0.4, 0.6))),
    }
    cell.add_box("box", (0.3, 0.2, 0.1), obstacles["box"][1])
    cell.add_cylinder("cyl", 0.05, 0.4, obstacles["cyl"][1])
    cell.add_sphere("ball", 0.1, obstacles["ball"][1])
    model, geometry, shapes = full_model_geometry(robot)
    data, geometry_data = model.createData(), geometry.createData()
    rng = np.random.default_rng(5)
    request = coal.DistanceRequest()
    compared = 0
    for _ in range(4):
        q = robot.random_configuration(rng)
        q_full = pin.neutral(model)
        for k, joint in enumerate(robot.joint_names):
            q_full[model.joints[model.getJointId(joint)].idx_q] = q[k]
        pin.updateGeometryPlacements(model, data, geometry, geometry_data, q_full)
        transforms = {}
        for k, obj in enumerate(geometry.geometryObjects):
            link = model.frames[obj.parentFrame].name
            transforms.setdefault(link, []).append((shapes[k], geometry_data.oMg[k]))
        got: dict[tuple[str, str], float] = {}
        for pair in cell.pair_distances(q):  # a link with several elements: its nearest
            got[pair.bodies] = min(got.get(pair.bodies, np.inf), pair.distance)
        for (first, second), distance in got.items():
            if second not in obstacles or first not in transforms:
                continue
            shape, pose = obstacles[second]
            expected = min(
                coal.distance(
                    g,
                    coal.Transform3s(T.rotation, T.translation),
                    shape,
                    coal.Transform3s(pose.rotation, pose.translation),
                    request,
                    coal.DistanceResult(),
                )  # fmt: skip
                for g, T in transforms[first]
            )
            np.testing.assert_allclose(distance, expected, atol=GJK, rtol=0)
            compared += 1
    assert compared >= 4 * 3 * 6


# ----------------------------------------------------------------------- self-collision
@pytest.mark.parametrize(
    ("name", "folded", "pair"),
    [
        ("ur5", [0.0, -1.57, 2.9, 0.0, 0.0, 0.0], ("upper_arm_link", "wrist_3_link")),
        ("panda", [0.0, 1.5, 0.0, -3.0, 0.0, 0.5, 0.0], ("panda_link1", "panda_hand")),
    ],
)
def test_srdf_filtering_zero_configuration_free_folded_collides(name, folded, pair):
    robot = kinplan.load_robot(name)
    cell = WorkCell(robot)
    assert cell.srdf_path is not None and cell.srdf_path.suffix == ".srdf"
    assert cell.collisions(robot.neutral()) == []
    assert cell.distance(robot.neutral()) > 0
    reasons = {frozenset(p.bodies): p.reason for p in cell.excluded_pairs}
    assert any(r.startswith("disabled in") for r in reasons.values())
    assert any(r.startswith("adjacent links") for r in reasons.values())
    for first, second in cell.checked_pairs:
        assert frozenset((first, second)) not in reasons
    hits = {c.bodies for c in cell.collisions(np.array(folded))}
    assert pair in hits


def test_without_srdf_pairs_touching_at_zero_are_left_out_and_said(probe, caplog):
    with caplog.at_level(logging.INFO, logger="kinplan.cell"):
        cell = WorkCell(probe)
    reasons = {p.bodies: p.reason for p in cell.excluded_pairs}
    assert reasons[("arm", "finger")] == "in contact at the zero configuration (no SRDF)"
    assert reasons[("arm", "hand")].startswith("adjacent links (joint j2)")
    assert any("zero configuration" in r.message for r in caplog.records)
    assert cell.checked_pairs == []  # hand–finger are adjacent too


def test_srdf_argument_and_unknown_links(probe, tmp_path):
    srdf = tmp_path / "probe_custom.srdf"
    srdf.write_text('<robot name="probe"><disable_collisions link1="arm" link2="finger"/></robot>')
    cell = WorkCell(probe, srdf=srdf)
    assert cell.srdf_path == srdf
    reasons = {p.bodies: p.reason for p in cell.excluded_pairs}
    assert reasons[("arm", "finger")] == "disabled in probe_custom.srdf"
    srdf.write_text('<robot name="probe"><disable_collisions link1="arm" link2="claw"/></robot>')
    with pytest.raises(CellError, match=r"srdf: .*'claw'.*links: arm, base, finger, hand"):
        WorkCell(probe, srdf=srdf)
    srdf.write_text("<robot")
    with pytest.raises(CellError, match="srdf: .* not valid XML"):
        WorkCell(probe, srdf=srdf)
    with pytest.raises(CellError, match="srdf: no file"):
        WorkCell(probe, srdf=tmp_path / "missing.srdf")


def test_base_fixed_in_world_is_never_checked_against_the_table_and_allowed_pairs():
    cell = ur5_cell()
    reasons = {p.bodies: p.reason for p in cell.excluded_pairs}
    assert reasons[("base_link", "table")] == "both fixed in the world (constant)"
    assert ("shoulder_link", "table") in cell.checked_pairs
    other = cell.for_robot(cell.robot)
    other.add_box("pedestal", (0.3, 0.3, 0.3), xyz_rpy((0, 0, 0.05)), allowed=["shoulder_link"])
    reasons = {p.bodies: p.reason for p in other.excluded_pairs}
    assert reasons[("shoulder_link", "pedestal")] == "allowed when pedestal was added"
    assert ("upper_arm_link", "pedestal") in other.checked_pairs
    other.allow("upper_arm_link", "pedestal")
    assert ("upper_arm_link", "pedestal") not in other.checked_pairs
    assert "pedestal" not in cell.obstacles  # for_robot copied the obstacles


# ----------------------------------------------------------------------- motions
def sweep(q_a, q_b, count):
    t = np.linspace(0.0, 1.0, count)[:, None]
    return q_a + t * (q_b - q_a)


def slack(cell, q, clearance) -> float:
    """Smallest distance minus its pair's threshold at q [m] (< 0: the pair fails there):
    the clearance for robot–obstacle pairs, 0 for self pairs."""
    pairs = cell.pair_distances(q)
    return min((p.distance - (clearance if p.kind == "obstacle" else 0.0) for p in pairs),
               default=np.inf)  # fmt: skip


def test_collision_between_two_samples_is_caught():
    robot = kinplan.load_robot("ur5")
    cell = WorkCell(robot)
    q_a = UR5_HOME + [-0.3, 0, 0, 0, 0, 0]
    q_b = UR5_HOME + [0.3, 0, 0, 0, 0, 0]
    flange = robot.fk(UR5_HOME).translation  # where the flange passes halfway
    cell.add_box("fin", (0.06, 0.002, 0.06), xyz_rpy(flange, (0, 0, 0)))
    q = np.array([q_a, q_b])
    assert cell.distance(q_a) > 0.05 and cell.distance(q_b) > 0.05
    result = cell.check_motion(q)
    assert result.index == 1 and result.between
    assert "fin" in result.bodies
    assert 0 < result.fraction < 1
    assert cell.distance(result.q) <= 0  # a real collision, at a configuration of the segment
    np.testing.assert_allclose(result.q, q_a + result.fraction * (q_b - q_a), atol=1e-15)
    assert result.penetration == pytest.approx(-result.distance)
    assert result.min_clearance == pytest.approx(result.distance)
    assert not result.ok and "between samples 0 and 1" in result.describe()
    dense = cell.check_motion(sweep(q_a, q_b, 401))  # dense sampling agrees: a collision
    assert dense.index is not None and not dense.between


def test_sample_collision_and_clearance_shortfall():
    cell = ur5_cell()
    q_end = UR5_HOME + [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    robot = cell.robot
    result = cell.check_motion(np.array([UR5_HOME, q_end]))
    margin = result.min_clearance
    assert result.ok and margin > 0.02
    flagged = cell.check_motion(np.array([UR5_HOME, q_end]), clearance=margin + 0.01)
    assert flagged.index == 0 and not flagged.between
    assert flagged.bodies == result.min_pair
    assert flagged.penetration == pytest.approx(0.01, abs=GJK)
    assert flagged.distance == pytest.approx(margin, abs=GJK)
    del robot


def probe_near_self_contact(folder) -> tuple[WorkCell, np.ndarray]:
    """The probe with an SRDF that disables nothing (so arm–finger is checked), folded so the
    finger's sphere is 1 mm from the arm's (centres 0.221 m apart: 2 · 0.2 · sin(q3 / 2))."""
    srdf = Path(folder) / "probe_all_pairs.srdf"
    srdf.write_text('<robot name="probe"/>')
    cell = WorkCell(probe_robot(str(folder)), srdf=srdf)
    assert cell.checked_pairs == [("arm", "finger")]
    return cell, np.array([0.0, 0.0, 2.0 * np.arcsin(0.221 / 0.4)])


def test_clearance_margin_applies_to_obstacles_only(tmp_path):
    """A self pair 1 mm apart passes a 5 mm clearance (neighbouring links of real arms sit that
    close); an obstacle 1 mm away fails it, naming the pair, 4 mm inside the margin."""
    cell, folded = probe_near_self_contact(tmp_path)
    q = np.array([folded, folded + [0.1, 0.0, 0.0]])  # turning about j1 keeps the fold
    (pair,) = cell.pair_distances(folded)
    assert pair.kind == "self" and pair.distance == pytest.approx(0.001, abs=EXACT)
    free = cell.check_motion(q, clearance=0.005)
    assert free.ok and free.kind is None
    assert free.min_self_clearance == pytest.approx(0.001, abs=EXACT)
    assert free.min_self_pair == ("arm", "finger")
    np.testing.assert_allclose(free.self_distances, 0.001, atol=EXACT)
    assert cell.collisions(folded, margin=0.005) == []
    # a ball 1 mm above the finger's sphere (r 0.12), 14+ cm from the other links
    finger = probe_robot(str(tmp_path)).fk(folded).translation  # the tip: the finger's frame
    centre = finger + np.array([-0.2 * np.cos(folded[2]), -0.2 * np.sin(folded[2]), 0.141])
    cell.add_sphere("ball", 0.02, xyz_rpy(centre))
    (near,) = [p for p in cell.pair_distances(folded) if p.kind == "obstacle" and
               p.distance < 0.01]  # fmt: skip
    assert near.bodies == ("finger", "ball") and near.distance == pytest.approx(0.001, abs=EXACT)
    hit = cell.check_motion(q, clearance=0.005)
    assert hit.index == 0 and not hit.between and hit.bodies == ("finger", "ball")
    assert hit.kind == "obstacle"
    assert hit.distance == pytest.approx(0.001, abs=EXACT)
    assert hit.penetration == pytest.approx(0.004, abs=EXACT)
    assert "(clearance 5 mm)" in hit.describe()
    assert [c.bodies for c in cell.collisions(folded, margin=0.005)] == [("finger", "ball")]
    assert cell.check_motion(q, clearance=0.0009).ok  # under 1 mm: the ball passes too


def test_self_contact_fails_whatever_the_clearance(tmp_path):
    """A self pair fails on contact, with its penetration depth (not measured from the
    clearance), and the description does not blame the clearance."""
    cell, folded = probe_near_self_contact(tmp_path)
    deeper = folded - [0.0, 0.0, 0.05]  # centres closer: the spheres overlap
    depth = 0.22 - 0.4 * np.sin(deeper[2] / 2)
    assert depth > 0.005
    for clearance in (0.0, 0.01):
        hit = cell.check_motion(np.array([folded, deeper]), clearance=clearance)
        assert hit.index == 1 and hit.bodies == ("arm", "finger") and hit.kind == "self"
        assert hit.penetration == pytest.approx(-hit.distance)
        assert "clearance" not in hit.describe()


def test_between_samples_an_obstacle_inside_the_margin_is_caught(probe):
    """Turning about j1 from −0.3 to 0.3 rad, the finger (r 0.12 centred 0.5 m out) passes
    3 mm under a ball halfway but is 6 cm from it at both samples: with a 1 cm clearance the
    shortfall between the two samples is found (conservative advancement with the obstacle's
    threshold), at a configuration where it is real; without a margin the motion is free."""
    cell = WorkCell(probe)
    cell.add_sphere("ball", 0.02, xyz_rpy((0.5, 0.0, 0.12 + 0.02 + 0.003)))
    q = np.array([[-0.3, 0.0, 0.0], [0.3, 0.0, 0.0]])
    assert min(p.distance for p in cell.pair_distances(q[0])) > 0.06
    assert min(p.distance for p in cell.pair_distances(q[1])) > 0.06
    assert cell.check_motion(q).ok
    hit = cell.check_motion(q, clearance=0.01)
    assert hit.index == 1 and hit.between and hit.kind == "obstacle"
    assert hit.bodies == ("finger", "ball")
    assert 0.0 < hit.fraction < 1.0
    assert 0.003 - EXACT <= hit.distance < 0.01
    assert hit.penetration == pytest.approx(0.01 - hit.distance)
    (pair,) = [p for p in cell.pair_distances(hit.q) if p.bodies == ("finger", "ball")]
    assert pair.distance == pytest.approx(hit.distance, abs=EXACT)
    dense = cell.check_motion(sweep(q[0], q[1], 601), clearance=0.01)
    assert dense.index is not None and dense.bodies == ("finger", "ball")


def test_per_sample_distances_are_exact_and_minima_consistent():
    cell = ur5_cell()
    rng = np.random.default_rng(2)
    q_a = UR5_HOME + rng.uniform(-0.4, 0.4, 6)
    q_b = q_a + rng.uniform(-0.5, 0.5, 6)
    q = sweep(q_a, q_b, 120)
    result = cell.check_motion(q, full=True)
    expected = np.array([cell.distance(row) for row in q])
    np.testing.assert_allclose(result.distances, expected, atol=GJK, rtol=0)
    stop = len(q) if result.index is None else result.index + 1
    if not result.between:
        assert result.min_clearance == pytest.approx(np.min(result.distances[:stop]))
    obstacle = [min(p.distance for p in cell.pair_distances(row) if p.kind == "obstacle")
                for row in q[::17]]  # fmt: skip
    np.testing.assert_allclose(result.obstacle_distances[::17], obstacle, atol=GJK, rtol=0)
    assert result.evaluations < len(q) * len(cell.checked_pairs) / 3


@pytest.mark.parametrize("seed", range(16))
def test_check_motion_agrees_with_dense_sampling(seed):
    """Random coarse motions near the obstacles: a reported failure is real, and dense
    sampling finds no failure before it (nor any when the motion is reported free)."""
    cell = ur5_cell()
    rng = np.random.default_rng(100 + seed)
    clearance = [0.0, 0.015][seed % 2]
    start = UR5_HOME + rng.uniform(-0.8, 0.8, 6)
    q = np.cumsum(np.vstack([start, rng.uniform(-0.35, 0.35, (4, 6))]), axis=0)
    result = cell.check_motion(q, clearance=clearance)
    if result.index is not None:
        assert cell.collisions(result.q, margin=clearance)  # a real failure
        k = result.index
        expected = q[k - 1] + result.fraction * (q[k] - q[k - 1]) if result.between else q[k]
        np.testing.assert_allclose(result.q, expected, atol=1e-12)
    # dense sampling of every segment before the failing one finds nothing either (the
    # failing segment may hold earlier contacts of the failing pair, reported at its sample)
    last = len(q) - 1 if result.index is None else result.index - 1
    for k in range(last):
        dense = sweep(q[k], q[k + 1], 150)
        worst = min(slack(cell, row, clearance) for row in dense)
        assert worst >= -TOLERANCE - GJK, (k, worst)


@pytest.mark.parametrize("source", ["mimic_arm.urdf", "prismatic_gantry.urdf"])
def test_motion_bounds_hold_for_prismatic_and_mimic_joints(source):
    """The lever bounds take prismatic travel and mimic multipliers into account: dense
    sampling finds nothing before a reported failure (these URDFs have visuals only, which then
    serve as collision geometry)."""
    robot = kinplan.load_robot(TESTS / "urdf" / source)
    cell = WorkCell(robot)
    assert cell.geometry_source == "visual"
    rng = np.random.default_rng(0)
    for k in range(3):
        cell.add_sphere(f"ball{k}", 0.05, robot.fk(robot.random_configuration(rng)).translation)
        place = xyz_rpy(robot.fk(robot.random_configuration(rng)).translation, (0, 30 * k, 0))
        cell.add_box(f"fin{k}", (0.1, 0.02, 0.1), place)
    span = np.minimum(1.0, (robot.upper - robot.lower) / 2)
    for seed in range(6):
        rng = np.random.default_rng(seed)
        clearance = [0.0, 0.01][seed % 2]
        steps = rng.uniform(-0.3, 0.3, (3, robot.nq)) * span
        q = np.cumsum(np.vstack([robot.random_configuration(rng), steps]), axis=0)
        result = cell.check_motion(q, clearance=clearance)
        if result.index is not None:
            assert cell.collisions(result.q, margin=clearance)  # a real failure
        last = len(q) - 1 if result.index is None else result.index - 1
        for k in range(last):
            worst = min(slack(cell, row, clearance) for row in sweep(q[k], q[k + 1], 120))
            assert worst >= -TOLERANCE - GJK, (seed, k, worst)


def test_distant_pairs_cost_no_coal_call():
    cell = ur5_cell()
    start = UR5_HOME + [np.pi, 0, 0, 0, 0, 0]  # the arm turned away from the obstacles
    q = sweep(start, start + [0.2, -0.1, 0.1, 0.2, 0.1, 0.3], 200)
    result = cell.check_motion(q)
    assert result.ok and result.min_clearance > 0.02
    assert result.min_clearance == np.min(result.distances)
    n_pairs = len(cell.checked_pairs)
    # all pairs at the first sample, the nearest obstacle and self pairs at every sample, and
    # a few more: far from the ~51 pairs × 200 samples a sample-by-sample check computes
    assert result.evaluations < n_pairs + 200 * 4


def test_check_motion_input_errors():
    cell = ur5_cell()
    with pytest.raises(kinplan.InputError, match=r"shape \(N, 6\)"):
        cell.check_motion(np.zeros((3, 5)))
    with pytest.raises(kinplan.InputError, match="clearance"):
        cell.check_motion(np.zeros((3, 6)), clearance=-0.01)
    with pytest.raises(kinplan.InputError, match="finite"):
        cell.check_motion(np.full((2, 6), np.nan))


# ----------------------------------------------------------------------- bad input
def test_bad_obstacles_are_cell_errors_naming_the_argument(probe, tmp_path):
    cell = WorkCell(probe)
    with pytest.raises(CellError, match=r"add_box\('t'\): size of a box must be 3 number"):
        cell.add_box("t", (1.0, -1.0, 1.0))
    with pytest.raises(CellError, match=r"add_sphere\('s'\): radius must be > 0"):
        cell.add_sphere("s", -0.1)
    with pytest.raises(CellError, match=r"add_cylinder\('c'\): length must be > 0"):
        cell.add_cylinder("c", 0.1, 0.0)
    with pytest.raises(CellError, match=r"add_mesh\('m'\): path: no mesh file"):
        cell.add_mesh("m", tmp_path / "missing.stl")
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(b"\x00\x01 not a mesh at all")
    with pytest.raises(CellError, match=r"add_mesh\('g'\): path: .*(cannot read|no usable)"):
        cell.add_mesh("g", garbage)
    with pytest.raises(CellError, match=r"add_mesh\('n'\): scale must be > 0"):
        cell.add_mesh("n", garbage, scale=-1.0)
    with pytest.raises(CellError, match="shape must be one of box, cylinder, sphere, mesh"):
        Body("cone", (0.1, 0.2))
    with pytest.raises(CellError, match=r"add_box\('p'\): the rotation of pose"):
        cell.add_box("p", (1, 1, 1), np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(CellError, match="'arm' is a link of probe"):
        cell.add_sphere("arm", 0.1)
    cell.add_sphere("ok", 0.1, (3, 3, 3))
    with pytest.raises(CellError, match="already an obstacle 'ok'"):
        cell.add_sphere("ok", 0.1)
    with pytest.raises(CellError, match="allowed names 'claw'"):
        cell.add_sphere("other", 0.1, allowed=["claw"])
    assert list(cell.obstacles) == ["ok"]
    for error in (CellError("x"),):
        assert isinstance(error, kinplan.KinplanError)


def test_robot_mesh_that_cannot_be_found_is_a_cell_error(tmp_path):
    text = PROBE_URDF.replace(
        '<sphere radius="0.05"/>', '<mesh filename="package://probe/meshes/hand.stl"/>'
    )
    path = tmp_path / "probe_mesh.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="finger")
    message = r"collision mesh .*hand.stl.* of link 'hand'.*package_dirs"
    with pytest.raises(CellError, match=message):
        WorkCell(robot)


def test_mesh_obstacles_surface_and_convex(probe, tmp_path):
    path = tmp_path / "cube_mm.stl"
    trimesh.creation.box((200.0, 200.0, 200.0)).export(path)
    cell = WorkCell(probe)
    cell.add_mesh("surface", path, xyz_rpy((0.5, 0.0, 0.25)), scale=0.001)
    cell.add_mesh("solid", path, xyz_rpy((0.5, 0.0, -0.5)), scale=0.001, convex=True)
    got = {p.bodies: p.distance for p in cell.pair_distances(np.zeros(3))}
    assert got[("arm", "surface")] == pytest.approx(0.05, abs=1e-9)  # 0.25 − 0.1 − 0.1
    assert got[("arm", "solid")] == pytest.approx(0.3, abs=1e-9)  # 0.5 − 0.1 − 0.1


# ----------------------------------------------------------------------- tools
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_with_tool_moves_the_tip_to_the_tcp(name):
    robot = kinplan.load_robot(name)
    tcp = xyz_rpy((0.02, -0.01, 0.28), (0, -35, 15))
    tooled = robot.with_tool(tcp, Body.cylinder(0.012, 0.25, xyz_rpy((0, 0, 0.14))))
    assert tooled.tip_frame == "tcp" and tooled.tool.flange == robot.tip_frame
    assert tooled.nq == robot.nq and tooled.joint_names == robot.joint_names
    np.testing.assert_array_equal(tooled.lower, robot.lower)
    rng = np.random.default_rng(8)
    for _ in range(5):
        q = robot.random_configuration(rng)
        flange = robot.fk(q)
        np.testing.assert_allclose(tooled.fk(q).homogeneous, (flange * tcp).homogeneous, atol=1e-12)
        J_flange, J = robot.jacobian(q), tooled.jacobian(q)
        lever = (flange * tcp).translation - flange.translation
        np.testing.assert_allclose(J[3:], J_flange[3:], atol=1e-12)
        np.testing.assert_allclose(
            J[:3], J_flange[:3] - np.cross(lever, J_flange[3:], axisb=0, axisc=0), atol=1e-12
        )
    # the closed form is rebuilt for the TCP and checked against FK; IK lands on the target
    assert tooled.closed_form_ik is not None
    for _ in range(5):
        q = robot.random_configuration(rng)
        target = tooled.fk(q)
        result = tooled.ik(target, q_seed=q + 0.02)
        assert result.success and result.position_error < 1e-9
        reached = tooled.fk(result.q)
        np.testing.assert_allclose(reached.homogeneous, target.homogeneous, atol=1e-9)
        if name == "ur5":  # six joints: the seed's branch is the configuration itself
            np.testing.assert_allclose(result.q, q, atol=1e-9)


def test_tool_body_collides_like_a_link(tmp_path):
    robot = kinplan.load_robot("ur5")
    mesh = tmp_path / "nozzle_mm.stl"
    trimesh.creation.cylinder(radius=10.0, height=100.0).export(mesh)
    tooled = robot.with_tool(xyz_rpy((0, 0, 0.12)), Body.mesh(mesh, xyz_rpy((0, 0, 0.06)), 0.001))
    cell = WorkCell(tooled)
    assert "tool" in cell.robot_bodies
    assert cell.srdf_path is not None and cell.srdf_path.name == "ur5.srdf"  # still found
    reasons = {p.bodies: p.reason for p in cell.excluded_pairs if "tool" in p.bodies}
    assert reasons[("wrist_3_link", "tool")] == "rigidly attached to each other"
    assert ("forearm_link", "tool") in cell.checked_pairs
    tcp = tooled.fk(UR5_HOME)
    cell.add_sphere("ball", 0.02, tcp.act(np.array([0.0, 0.0, -0.03])))  # 3 cm up the nozzle
    hits = {c.bodies: c for c in cell.collisions(UR5_HOME)}
    assert ("tool", "ball") in hits
    # the nozzle's surface is 1 cm from its axis (trimesh's 32-gon: cos(π/32) cm at the flats):
    # the ball (r 2 cm) on the axis is 3 cm deep
    depth = 0.02 + 0.01 * np.cos(np.pi / 32)
    assert hits[("tool", "ball")].penetration == pytest.approx(depth, abs=GJK)
    bare = cell.for_robot(robot)
    assert "tool" not in bare.robot_bodies and "ball" in bare.obstacles


def test_with_tool_bad_input():
    robot = kinplan.load_robot("ur5")
    with pytest.raises(CellError, match="body must be a kinplan.cell.Body"):
        robot.with_tool(xyz_rpy((0, 0, 0.1)), body={"cylinder": [0.01, 0.2]})
    with pytest.raises(CellError, match="pose"):
        robot.with_tool("tcp")
    with pytest.raises(CellError, match="size of a cylinder must be 2"):
        Body("cylinder", (0.1,))
