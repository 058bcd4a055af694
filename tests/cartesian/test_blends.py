"""Blended corners (cartesian.blends): geometry against the sharp corner, exact derivatives,
tangent and curvature continuity, and the tool passing a corner at cruise speed on a UR5."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from cartesian.blends import CornerBlend, SubPath
from kinplan.errors import InputError

UR5_START = np.array([0.0, -1.6, 1.6, -1.57, -1.57, 0.0])


def corner_pieces(path: cartesian.PathSequence) -> list[CornerBlend]:
    return [piece for piece in path.paths if isinstance(piece, CornerBlend)]


def test_ninety_degree_corner_stays_within_the_radius():
    a, b, c = np.array([0.4, 0.0, 0.3]), np.array([0.6, 0.0, 0.3]), np.array([0.6, 0.2, 0.3])
    radius = 0.02
    path = cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(b, c)], radius)
    (blend,) = corner_pieces(path)
    s = np.linspace(0.0, 1.0, 4001)
    points = blend.position(s)
    # enters and leaves exactly on the sphere of the radius, inside it in between
    distances = np.linalg.norm(points - b, axis=1)
    assert distances[0] == pytest.approx(radius, abs=1e-12)
    assert distances[-1] == pytest.approx(radius, abs=1e-12)
    assert np.all(distances <= radius + 1e-12)
    # deviation from the sharp corner (distance to the nearer leg) at most the radius;
    # for a symmetric quintic about half of it
    leg1 = np.abs(points[:, 1])
    leg2 = np.abs(points[:, 0] - 0.6)
    deviation = np.minimum(leg1, leg2).max()
    assert 0.2 * radius < deviation <= radius
    # the sequence keeps the length of the legs outside the sphere
    assert path.length == pytest.approx(0.4 - 2 * radius + blend.length, abs=1e-12)


def finite_difference_check(path: cartesian.Path, s: np.ndarray, h: float = 1e-6) -> None:
    first, second = path.position_derivatives(s)
    numeric1 = (path.position(s + h) - path.position(s - h)) / (2 * h)
    numeric2 = (path.position_derivatives(s + h)[0] - path.position_derivatives(s - h)[0]) / (2 * h)
    scale = path.length
    np.testing.assert_allclose(numeric1, first, atol=1e-7 * scale)
    np.testing.assert_allclose(numeric2, second, atol=1e-6 * max(scale, np.abs(second).max()))


def test_blend_derivatives_are_exact_and_arc_length():
    rng = np.random.default_rng(5)
    for _ in range(20):
        a, b = rng.normal(size=3), rng.normal(size=3)
        ta, tb = rng.normal(size=3), rng.normal(size=3)
        ta, tb = ta / np.linalg.norm(ta), tb / np.linalg.norm(tb)
        ka = np.cross(ta, rng.normal(size=3))  # curvature vectors normal to the tangents
        kb = np.cross(tb, rng.normal(size=3))
        blend = CornerBlend(a, b, (ta, tb), (0.3 * ka, 0.3 * kb))
        s = np.linspace(0.01, 0.99, 97)
        finite_difference_check(blend, s)
        first, _ = blend.position_derivatives(s)
        np.testing.assert_allclose(np.linalg.norm(first, axis=1), blend.length, rtol=1e-12)
        np.testing.assert_allclose(blend.position(np.array([0.0, 1.0])), [a, b], atol=1e-13)


@pytest.mark.parametrize("seed", range(4))
def test_random_polylines_blend_smoothly(seed):
    """Property over 250 random 3-D polylines per seed: tangent and curvature continuous at
    every junction, each blend within its sphere, unit speed in s × length."""
    rng = np.random.default_rng(seed)
    for _ in range(250):
        count = rng.integers(3, 6)
        points = np.cumsum(rng.uniform(0.05, 0.3, (count, 1)) * _unit(rng, count), axis=0)
        lines = [cartesian.Line(p, q) for p, q in zip(points, points[1:])]
        shortest = min(line.length for line in lines)
        radii = rng.uniform(0.0, 0.5, count - 2) * shortest
        turns = [
            np.arccos(np.clip(p.delta @ q.delta / (p.length * q.length), -1, 1))
            for p, q in zip(lines, lines[1:])
        ]
        if max(turns) > np.pi - 1e-3:
            continue
        path = cartesian.blend_corners(lines, radii)
        pieces = path.paths
        for k, piece in enumerate(pieces):
            if not isinstance(piece, CornerBlend):
                continue
            for mine, other, at in ((0.0, pieces[k - 1], 1.0), (1.0, pieces[k + 1], 0.0)):
                here = [d[0] for d in piece.position_derivatives(np.array([mine]))]
                there = [d[0] for d in other.position_derivatives(np.array([at]))]
                tangent = here[0] / piece.length, there[0] / other.length
                curvature = here[1] / piece.length**2, there[1] / other.length**2
                np.testing.assert_allclose(*tangent, atol=1e-12)
                np.testing.assert_allclose(*curvature, atol=1e-9 / piece.length)
            corner = lines[[isinstance(p, CornerBlend) for p in pieces][:k].count(False) - 1].b
            distance = np.linalg.norm(piece.position(np.linspace(0, 1, 101)) - corner, axis=1)
            assert distance.max() <= np.linalg.norm(piece.a - corner) + 1e-12


def _unit(rng: np.random.Generator, count: int) -> np.ndarray:
    vectors = rng.normal(size=(count, 3))
    return vectors / np.linalg.norm(vectors, axis=1)[:, None]


def test_line_into_arc_blend_matches_the_arc():
    rotation = pin.rpy.rpyToMatrix(np.pi, 0.0, 0.0)
    a = pin.SE3(rotation, np.array([0.25, -0.05, 0.1]))
    b = pin.SE3(rotation, np.array([0.35, -0.05, 0.1]))
    via = pin.SE3(rotation, np.array([0.42, 0.02, 0.1]))
    c = pin.SE3(rotation, np.array([0.49, -0.05, 0.1]))
    path = cartesian.blend_corners([cartesian.Line(a, b), cartesian.Arc(b, via, c)], 0.01)
    assert path.has_orientation
    assert isinstance(path.paths[-1], SubPath)  # the arc, entered 1 cm after the corner
    (blend,) = corner_pieces(path)
    assert np.linalg.norm(path.paths[-1].start.translation - b.translation) == pytest.approx(0.01)
    finite_difference_check(path, np.linspace(0.01, 0.99, 301))
    # the blend meets the arc with the arc's tangent and curvature (1 / 0.07 m toward the centre)
    first, second = blend.position_derivatives(np.array([1.0]))
    arc_first, arc_second = path.paths[-1].position_derivatives(np.array([0.0]))
    np.testing.assert_allclose(first / blend.length, arc_first / path.paths[-1].length, atol=1e-12)
    curvature = second[0] / blend.length**2
    np.testing.assert_allclose(curvature, arc_second[0] / path.paths[-1].length ** 2, atol=1e-9)
    assert np.linalg.norm(curvature) == pytest.approx(1 / 0.07, rel=1e-9)
    rotations = path.rotation(np.linspace(0, 1, 11))
    np.testing.assert_allclose(rotations, np.broadcast_to(rotation, rotations.shape), atol=1e-12)


def test_blended_rectangle_is_followed_without_slowing_at_corners(ur5):
    start = ur5.fk(UR5_START)
    p0 = start.translation
    corners = [p0, p0 + [0.15, 0, 0], p0 + [0.15, 0.12, 0], p0 + [0, 0.12, 0], p0]
    poses = [pin.SE3(start.rotation, p) for p in corners]
    lines = [cartesian.Line(p, q) for p, q in zip(poses, poses[1:])]
    path = cartesian.blend_corners(lines, 0.02)
    plan = cartesian.follow(ur5, path, speed=0.05, q_seed=UR5_START)
    assert plan.ok, plan.summary()
    speed = np.linalg.norm(np.diff(plan.tool_positions, axis=0), axis=1) / np.diff(plan.t)
    ramp = 0.05 / 0.05 * 0.5  # the trapezoid's ramp time at the default ramp, generously
    cruise = (plan.t[1:] > ramp + 0.2) & (plan.t[1:] < plan.t[-1] - ramp - 0.2)
    assert speed[cruise].min() >= 0.95 * 0.05  # the issue asks for ≥ 50 % through a 90° corner
    assert plan.max_deviation <= 1e-6


def test_bad_blends():
    a, b, c = [0.4, 0.0, 0.3], [0.6, 0.0, 0.3], [0.6, 0.2, 0.3]
    lines = [cartesian.Line(a, b), cartesian.Line(b, c)]
    with pytest.raises(InputError, match="larger than half the path"):
        cartesian.blend_corners(lines, 0.11)
    with pytest.raises(InputError, match="≥ 0"):
        cartesian.blend_corners(lines, -0.01)
    with pytest.raises(InputError, match="radius"):
        cartesian.blend_corners(lines, [0.01, 0.01])
    with pytest.raises(InputError, match="turns back"):
        cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(b, a)], 0.01)
    with pytest.raises(InputError, match="continuous"):
        cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(a, c)], 0.01)
    sharp = cartesian.blend_corners(lines, 0.0)  # radius 0 keeps the corner
    assert not corner_pieces(sharp) and sharp.length == pytest.approx(0.4)
