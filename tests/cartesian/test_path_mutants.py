"""Blended corners (cartesian.blends) and torch angles (cartesian.torch) against independent
answers: a sub-path against its parent path at the mapped fractions and against finite
differences of itself, a corner blend's end conditions against the quintic's definition and its
parametrisation against the arc length of a dense polyline, the cuts against the sphere of the
radius, the per-corner radii and the refusals naming the corner; torch rotations against a
product of Pinocchio's exponentials, their frame against the seam's tangent and normal. The
paths themselves (cartesian.paths): difference derivatives at and beyond the ends against an
analytic half circle, Arc's and Weave's refusals at their limits, weaves against their analytic
sine offsets."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from cartesian.blends import CornerBlend, SubPath
from cartesian.torch import torch_rotations
from kinplan.errors import InputError

DOWN = pin.rpy.rpyToMatrix(np.pi, 0.0, 0.0)


def _pose(point, rpy=(np.pi, 0.0, 0.0)) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(point, dtype=float))


def _rates_by_differences(path: cartesian.Path, s: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """ω_s from differences of the path's own rotations."""
    lo, hi = path.rotation(s - h), path.rotation(s + h)
    return np.array([pin.log3(b @ a.T) for a, b in zip(lo, hi)]) / (2 * h)


def _polyline_length(path: cartesian.Path, a: float, b: float, count: int = 20001) -> float:
    points = path.position(np.linspace(a, b, count))
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


# ---------------------------------------------------------------------------- SubPath
def _curved_torch_seam() -> cartesian.TorchOrientation:
    """A torch along a corner blend: curvature, and so the rotation rate, vary along it."""
    tangents = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    curvatures = (np.array([0.0, 3.0, 0.0]), np.array([-8.0, 0.0, 0.0]))
    blend = CornerBlend(np.array([0.4, 0.0, 0.2]), np.array([0.5, 0.1, 0.2]), tangents, curvatures)
    return cartesian.TorchOrientation(blend, [0.0, 0.2, 1.0], 0.3, 0.2, 0.1)


@pytest.mark.parametrize(("s0", "s1"), [(0.0, 0.3), (0.2, 0.7), (0.55, 1.0)])
def test_sub_path_is_its_parent_at_the_mapped_fractions(s0, s1):
    parent = _curved_torch_seam()
    part = SubPath(parent, s0, s1)
    assert part.length == pytest.approx((s1 - s0) * parent.length, rel=1e-14)
    assert part.has_orientation and part.slerp is None
    s = np.linspace(0.0, 1.0, 41)
    mapped = s0 + (s1 - s0) * s
    np.testing.assert_allclose(part.position(s), parent.position(mapped), atol=1e-15)
    np.testing.assert_allclose(part.rotation(s), parent.rotation(mapped), atol=1e-15)
    # outside [0, 1]: the ends of the part, not of the parent
    np.testing.assert_allclose(part.position(np.array([-0.5, 1.5])), parent.position([s0, s1]))
    np.testing.assert_allclose(part.rotation(np.array([-0.5, 1.5])), parent.rotation([s0, s1]))
    np.testing.assert_allclose(part.start.translation, parent.pose(s0).translation, atol=1e-15)
    np.testing.assert_allclose(part.end.rotation, parent.pose(s1).rotation, atol=1e-15)
    # derivatives in the part's own fraction, by differences of the part itself
    inner = np.linspace(0.02, 0.98, 25)
    h = 1e-6
    first, second = part.position_derivatives(inner)
    numeric1 = (part.position(inner + h) - part.position(inner - h)) / (2 * h)
    numeric2 = part.position_derivatives(inner + h)[0] - part.position_derivatives(inner - h)[0]
    np.testing.assert_allclose(first, numeric1, atol=1e-8)
    np.testing.assert_allclose(second, numeric2 / (2 * h), atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), part.length, rtol=1e-9)
    omega, domega = part.angular_rates(inner)
    np.testing.assert_allclose(omega, _rates_by_differences(part, inner), atol=1e-6)
    numeric = (part.angular_rates(inner + h)[0] - part.angular_rates(inner - h)[0]) / (2 * h)
    np.testing.assert_allclose(domega, numeric, atol=1e-4 * max(1.0, np.abs(domega).max()))
    parent_omega, parent_domega = parent.angular_rates(s0 + (s1 - s0) * inner)
    np.testing.assert_allclose(domega, (s1 - s0) ** 2 * parent_domega, rtol=1e-12)
    np.testing.assert_allclose(omega, (s1 - s0) * parent_omega, rtol=1e-12)
    assert np.abs(domega).max() > 0.1  # the seam's rotation rate does change
    assert repr(part) == f"SubPath({parent!r}, {s0:.4g}..{s1:.4g})"
    # finite differences of a wrapped part step as far along the seam as the parent's do
    assert part._fd_step * (s1 - s0) == pytest.approx(parent._fd_step, rel=1e-15)


def test_sub_path_of_a_position_only_line():
    line = cartesian.Line([0.0, 0.0, 0.0], [0.4, 0.0, 0.0])
    part = SubPath(line, 0.25, 0.5)
    assert not part.has_orientation and part.rotation(np.array([0.5])) is None
    np.testing.assert_allclose(part.position(np.array([0.0, 1.0])), [[0.1, 0, 0], [0.2, 0, 0]])
    omega, domega = part.angular_rates(np.array([0.5]))
    assert not omega.any() and not domega.any()


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("line", -0.1, 0.5), "s0"),
        (("line", 0.5, 0.5), "s0 < s1"),
        (("line", 0.6, 0.5), "s0 < s1"),
        (("line", 0.2, 1.2), "s1 <= 1"),
        (("line", 0.2, np.nan), "s1"),
        (("not a path", 0.0, 1.0), "cartesian path, got 'not a path'"),
    ],
)
def test_sub_path_refuses_bad_fractions(args, words):
    line = cartesian.Line([0.0, 0.0, 0.0], [0.4, 0.0, 0.0])
    path = line if args[0] == "line" else args[0]
    with pytest.raises(InputError, match=words):
        SubPath(path, *args[1:])
    SubPath(line, 0.0, 1.0)  # the whole path is a part of itself


# ---------------------------------------------------------------------------- CornerBlend
def test_corner_blend_meets_its_end_conditions_and_runs_at_constant_speed():
    """c(0) = a, c(1) = b; the unit tangents and the curvature vectors (normal to them) at the
    ends; |dp/ds| = length everywhere, and equal steps in s are equal arc lengths."""
    rng = np.random.default_rng(30)
    for _ in range(10):
        a, b = rng.normal(size=3), rng.normal(size=3)
        ta, tb = (v / np.linalg.norm(v) for v in rng.normal(size=(2, 3)))
        ka, kb = np.cross(ta, rng.normal(size=3)), np.cross(tb, rng.normal(size=3))
        blend = CornerBlend(a, b, (ta, tb), (0.4 * ka, 0.4 * kb))
        first, second = blend.position_derivatives(np.array([0.0, 1.0]))
        np.testing.assert_allclose(first / blend.length, [ta, tb], atol=1e-12)
        np.testing.assert_allclose(second / blend.length**2, [0.4 * ka, 0.4 * kb], atol=1e-9)
        np.testing.assert_allclose(blend.position(np.array([0.0, 1.0])), [a, b], atol=1e-13)
        assert blend.length == pytest.approx(_polyline_length(blend, 0.0, 1.0), rel=1e-6)
        for lo, hi in ((0.0, 0.1), (0.33, 0.5), (0.71, 1.0)):  # arc length ∝ fraction
            piece = _polyline_length(blend, lo, hi, 4001)
            assert piece == pytest.approx((hi - lo) * blend.length, rel=1e-6)
        s = np.linspace(0.0, 1.0, 57)
        first, _ = blend.position_derivatives(s)
        np.testing.assert_allclose(np.linalg.norm(first, axis=1), blend.length, rtol=1e-12)
        # fractions outside [0, 1] are the ends
        np.testing.assert_allclose(blend.position(np.array([-1.0, 2.0])), [a, b], atol=1e-13)
        assert repr(blend).startswith("CornerBlend([")


def _hermite_quintic(a, b, end_tangents, end_curvatures) -> np.ndarray:
    """Coefficients (6, 3), lowest power first, solved from the six end conditions."""
    length = np.linalg.norm(b - a)
    rows = [[1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 2, 0, 0, 0],
            [1, 1, 1, 1, 1, 1], [0, 1, 2, 3, 4, 5], [0, 0, 2, 6, 12, 20]]  # fmt: skip
    values = [a, length * end_tangents[0], length**2 * end_curvatures[0]]
    values += [b, length * end_tangents[1], length**2 * end_curvatures[1]]
    return np.linalg.solve(np.array(rows, dtype=float), np.array(values))


def test_corner_blend_positions_are_at_their_exact_arc_length():
    """The quintic solved from its end conditions, its arc length by 40-point Gauss-Legendre
    and bisection: position(s) is the point at arc length s × length, to rounding."""
    ta, tb = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    ka, kb = np.array([0.0, 60.0, 0.0]), np.array([-60.0, 0.0, 0.0])
    a, b = np.zeros(3), np.array([0.02, 0.02, 0.0])
    blend = CornerBlend(a, b, (ta, tb), (ka, kb))
    coefficients = _hermite_quintic(a, b, (ta, tb), (ka, kb))
    derivative = np.polynomial.polynomial.polyder(coefficients, axis=0)
    nodes, weights = np.polynomial.legendre.leggauss(40)

    def arc(u: np.ndarray) -> np.ndarray:  # arc length from 0 to each u
        x = 0.5 * u[:, None] * (nodes + 1.0)
        speed = np.linalg.norm(np.polynomial.polynomial.polyval(x, derivative), axis=0)
        return 0.5 * u * np.sum(speed * weights, axis=1)

    total = float(arc(np.array([1.0]))[0])
    assert blend.length == pytest.approx(total, rel=1e-13)
    s = np.linspace(0.0, 1.0, 37)
    lo, hi = np.zeros_like(s), np.ones_like(s)
    for _ in range(60):
        middle = 0.5 * (lo + hi)
        below = arc(middle) < s * total
        lo, hi = np.where(below, middle, lo), np.where(below, hi, middle)
    expected = np.polynomial.polynomial.polyval(0.5 * (lo + hi), coefficients).T
    np.testing.assert_allclose(blend.position(s), expected, rtol=0.0, atol=1e-15)
    # integer arrays in: float points kept (a copy), shown as floats
    whole = CornerBlend(np.array([0, 0, 0]), np.array([1, 0, 0]), (ta, ta), (ka * 0, ka * 0))
    assert whole.a.dtype == whole.b.dtype == float
    assert repr(whole) == "CornerBlend([0.0, 0.0, 0.0] → [1.0, 0.0, 0.0])"


def test_corner_blend_orientation_is_the_slerp_between_its_end_rotations():
    ra, rb = pin.exp3(np.array([0.3, -0.2, 0.1])), pin.exp3(np.array([-0.5, 0.4, 1.0]))
    tangent = np.array([1.0, 0.0, 0.0])
    blend = CornerBlend(np.zeros(3), np.array([0.1, 0.05, 0.0]), (tangent, tangent),
                        (np.zeros(3), np.zeros(3)), (ra, rb))  # fmt: skip
    assert blend.has_orientation
    np.testing.assert_allclose(blend.rotation(np.array([0.0, 1.0])), [ra, rb], atol=1e-14)
    omega, domega = blend.angular_rates(np.linspace(0.0, 1.0, 5))
    np.testing.assert_allclose(omega, np.tile(ra @ pin.log3(ra.T @ rb), (5, 1)), atol=1e-14)
    assert not domega.any()
    flat = CornerBlend(np.zeros(3), np.array([0.1, 0.0, 0.0]), (tangent, tangent),
                       (np.zeros(3), np.zeros(3)))  # fmt: skip
    assert not flat.has_orientation and flat.rotation(np.array([0.5])) is None
    odd = CornerBlend(np.array([0.123456, -1.0, 2.5]), np.array([0.2, 1 / 3, 0.0]),
                      (tangent, tangent), (np.zeros(3), np.zeros(3)))  # fmt: skip
    assert repr(odd) == "CornerBlend([0.1235, -1.0, 2.5] → [0.2, 0.3333, 0.0])"
    assert flat.length == pytest.approx(0.1, rel=1e-13)  # straight: the chord
    with pytest.raises(InputError, match="two different points"):
        CornerBlend(np.ones(3), np.ones(3), (tangent, tangent), (np.zeros(3), np.zeros(3)))


# ---------------------------------------------------------------------------- blend_corners
def test_blend_cuts_lie_on_the_sphere_of_each_corner_radius():
    """Per-corner radii: each corner's blend starts and ends at its own radius from the corner
    point, the sequence is continuous in position, tangent and rotation, and a radius of 0
    leaves its corner sharp."""
    points = [
        [0.3, 0.0, 0.2],
        [0.5, 0.0, 0.2],
        [0.5, 0.2, 0.25],
        [0.3, 0.25, 0.25],
        [0.3, 0.4, 0.2],
    ]
    rpys = [(np.pi, 0.0, 0.0), (np.pi, 0.1, 0.2), (np.pi, 0.2, 0.0), (3.0, 0.0, 0.3), (np.pi, 0, 0)]
    poses = [_pose(p, r) for p, r in zip(points, rpys)]
    lines = [cartesian.Line(p, q) for p, q in zip(poses, poses[1:])]
    radii = [0.03, 0.0, 0.05]
    path = cartesian.blend_corners(lines, radii)
    kinds = [type(piece).__name__ for piece in path.paths]
    assert kinds == ["SubPath", "CornerBlend", "SubPath", "SubPath", "CornerBlend", "SubPath"]
    blends = [piece for piece in path.paths if isinstance(piece, CornerBlend)]
    for blend, corner, radius in zip(blends, np.array(points)[[1, 3]], [0.03, 0.05]):
        assert np.linalg.norm(blend.a - corner) == pytest.approx(radius, abs=1e-12)
        assert np.linalg.norm(blend.b - corner) == pytest.approx(radius, abs=1e-12)
    # the sharp corner (radius 0) is kept: the pieces meet at the corner point
    np.testing.assert_allclose(path.paths[2].end.translation, points[2], atol=1e-15)
    np.testing.assert_allclose(path.paths[3].start.translation, points[2], atol=1e-15)
    for before, after in zip(path.paths, path.paths[1:]):
        np.testing.assert_allclose(before.end.translation, after.start.translation, atol=1e-12)
        np.testing.assert_allclose(before.end.rotation, after.start.rotation, atol=1e-12)
    for blend, (k_before, k_after) in zip(blends, [(0, 2), (3, 5)]):
        out = path.paths[k_before].position_derivatives(np.array([1.0]))[0][0]
        into = path.paths[k_after].position_derivatives(np.array([0.0]))[0][0]
        ends = blend.position_derivatives(np.array([0.0, 1.0]))[0]
        np.testing.assert_allclose(ends[0] / blend.length, out / np.linalg.norm(out), atol=1e-12)
        np.testing.assert_allclose(ends[1] / blend.length, into / np.linalg.norm(into), atol=1e-12)
    total = sum(piece.length for piece in path.paths)
    assert path.length == pytest.approx(total, rel=1e-14)


def test_blend_of_an_arc_into_a_line_cuts_the_arc_on_the_sphere():
    a, via, c = _pose([0.4, 0.0, 0.2]), _pose([0.45, 0.05, 0.2]), _pose([0.5, 0.0, 0.2])
    arc = cartesian.Arc(a, via, c)
    line = cartesian.Line(c, _pose([0.6, 0.0, 0.2]))
    path = cartesian.blend_corners([arc, line], 0.02)
    first, blend, last = path.paths
    assert isinstance(first, SubPath) and isinstance(blend, CornerBlend)
    assert isinstance(last, SubPath)
    corner = c.translation
    assert np.linalg.norm(first.end.translation - corner) == pytest.approx(0.02, abs=1e-12)
    assert np.linalg.norm(last.start.translation - corner) == pytest.approx(0.02, abs=1e-12)
    assert first.s0 == 0.0 and last.s1 == 1.0
    # the cut on the arc is the last crossing of the sphere (the arc stays outside before it)
    s = np.linspace(0.0, first.s1, 2001)
    assert np.all(np.linalg.norm(arc.position(s) - corner, axis=1) >= 0.02 - 1e-12)
    # the blend's curvature at its start is the arc's (radius 0.05 m)
    second = blend.position_derivatives(np.array([0.0]))[1][0] / blend.length**2
    assert np.linalg.norm(second) == pytest.approx(1 / 0.05, rel=1e-9)


def _assert_smooth_junctions(path: cartesian.PathSequence) -> None:
    """Position, unit tangent and curvature vector continuous where each blend meets its
    neighbours."""
    pieces = path.paths
    for k, piece in enumerate(pieces):
        if not isinstance(piece, CornerBlend):
            continue
        for mine, other, at in ((0.0, pieces[k - 1], 1.0), (1.0, pieces[k + 1], 0.0)):
            here = [d[0] for d in piece.position_derivatives(np.array([mine]))]
            there = [d[0] for d in other.position_derivatives(np.array([at]))]
            np.testing.assert_allclose(piece.position(np.array([mine]))[0],
                                       other.position(np.array([at]))[0], atol=1e-12)  # fmt: skip
            np.testing.assert_allclose(here[0] / piece.length, there[0] / other.length, atol=1e-9)
            np.testing.assert_allclose(
                here[1] / piece.length**2, there[1] / other.length**2, atol=1e-6
            )


def test_line_arc_line_blends_both_corners_smoothly():
    """A half circle between two lines, both corners blended: the blend into the arc meets it
    with the arc's tangent and curvature at the cut, not at the arc's start."""
    arc = cartesian.Arc([0.1, 0.0, 0.0], [0.15, 0.05, 0.0], [0.2, 0.0, 0.0])
    pieces = [cartesian.Line([0.0, 0.0, 0.0], [0.1, 0.0, 0.0]), arc]
    pieces.append(cartesian.Line([0.2, 0.0, 0.0], [0.3, 0.0, 0.0]))
    path = cartesian.blend_corners(pieces, 0.02)
    kinds = [type(piece).__name__ for piece in path.paths]
    assert kinds == ["SubPath", "CornerBlend", "SubPath", "CornerBlend", "SubPath"]
    _assert_smooth_junctions(path)
    middle = path.paths[2]
    assert 0.0 < middle.s0 < middle.s1 < 1.0
    for s, corner in ((middle.s0, [0.1, 0, 0]), (middle.s1, [0.2, 0, 0])):
        point = arc.position(np.array([s]))[0]
        assert np.linalg.norm(point - corner) == pytest.approx(0.02, abs=1e-12)


def test_a_line_into_a_tangent_arc_is_already_smooth():
    """The arc leaves the line along it (its end tangent is reversed, which does not matter):
    no blend, the pieces kept whole."""
    line = cartesian.Line([0.0, 0.0, 0.0], [0.1, 0.0, 0.0])
    arc = cartesian.Arc([0.1, 0.0, 0.0], [0.15, 0.05, 0.0], [0.1, 0.1, 0.0])
    path = cartesian.blend_corners([line, arc], 0.02)
    assert [type(p).__name__ for p in path.paths] == ["Line", "Arc"]


def test_the_cut_is_the_last_entry_into_the_sphere():
    """A 300° arc ending at the corner starts within the blend radius of it: the path is cut
    where it last enters the sphere (at 300° − 2 asin(r / 2R)), not where it first leaves it."""
    radius, blend = 0.05, 0.06
    angles = np.radians([0.0, 150.0, 300.0])
    points = [[radius * np.cos(a), radius * np.sin(a), 0.0] for a in angles]
    arc = cartesian.Arc(*points)
    end = np.array(points[2])
    line = cartesian.Line(end, end + [0.0, -0.15, 0.0])
    path = cartesian.blend_corners([arc, line], blend)
    first = path.paths[0]
    assert isinstance(first, SubPath) and first.s0 == 0.0
    expected = (300.0 - 2.0 * np.degrees(np.arcsin(blend / (2.0 * radius)))) / 300.0
    assert first.s1 == pytest.approx(expected, abs=1e-9)
    assert np.linalg.norm(first.end.translation - end) == pytest.approx(blend, abs=1e-12)
    _assert_smooth_junctions(path)


def test_corners_whose_tangents_round_beyond_one_are_straight_or_reversed():
    """Collinear lines whose unit tangents' dot product rounds to 1 + 2e-16 (or −1 − 2e-16):
    still a straight joint, kept whole (or a reversal, refused)."""
    a = [0.2739233746429086, -0.4604265724722594, -0.9180529521276106]
    b = [-0.35069603744104383, -0.0556988423845558, -0.38479569698868465]
    c = [-1.3464923130416553, 0.5895362535100555, 0.46534693119619797]
    straight = cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(b, c)], 0.1)
    assert [type(p).__name__ for p in straight.paths] == ["Line", "Line"]
    a = [0.2307702229625077, -0.23264489147623313, 0.994419871578422]
    b = [0.9227904211799924, 0.034387896098786896, 1.2109614811271516]
    with pytest.raises(InputError, match="turns back"):
        cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(b, a)], 0.1)


def test_straight_joints_and_single_paths_are_kept_whole():
    a, b, c = [0.3, 0.0, 0.2], [0.4, 0.0, 0.2], [0.6, 0.0, 0.2]
    straight = cartesian.blend_corners([cartesian.Line(a, b), cartesian.Line(b, c)], 0.04)
    assert [type(p).__name__ for p in straight.paths] == ["Line", "Line"]
    assert straight.length == pytest.approx(0.3)
    slight = cartesian.blend_corners(
        [cartesian.Line(a, b), cartesian.Line(b, [0.6, 0.0, 0.2 + 1e-6])], 0.04
    )
    assert any(isinstance(p, CornerBlend) for p in slight.paths)  # turns 5e-6 rad: blended
    single = cartesian.blend_corners(cartesian.Line(a, c), 0.01)
    assert [type(p).__name__ for p in single.paths] == ["Line"]


def test_radius_of_half_a_neighbour_is_allowed_and_more_is_named():
    a, b, c = [0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.3, 0.0]
    lines = [cartesian.Line(a, b), cartesian.Line(b, c)]
    path = cartesian.blend_corners(lines, 0.05)  # exactly half the first line
    assert path.paths[0].length == pytest.approx(0.05, abs=1e-12)
    with pytest.raises(InputError, match=r"corner 1 .*path before it \(0.1 m long\).*0.05 m"):
        cartesian.blend_corners(lines, 0.0501)
    lines = [cartesian.Line(c, b), cartesian.Line(b, a)]
    with pytest.raises(InputError, match=r"corner 1 .*path after it \(0.1 m long\)"):
        cartesian.blend_corners(lines, 0.06)
    three = [cartesian.Line(a, b), cartesian.Line(b, c), cartesian.Line(c, [0.4, 0.3, 0.0])]
    with pytest.raises(InputError, match=r"-0.01"):
        cartesian.blend_corners(three, [0.01, -0.01])
    with pytest.raises(InputError, match="radius"):
        cartesian.blend_corners(three, [0.01])
    with pytest.raises(InputError, match="corner 2 turns back"):
        back = [cartesian.Line(a, b), cartesian.Line(b, c), cartesian.Line(c, b)]
        cartesian.blend_corners(back, 0.01)
    nearly = cartesian.Line(b, [0.0, 1e-4, 0.0])  # turns 179.94°: blended
    assert any(
        isinstance(p, CornerBlend)
        for p in cartesian.blend_corners([cartesian.Line(a, b), nearly], 0.01).paths
    )
    back = [cartesian.Line(a, b), cartesian.Line(b, a)]
    assert cartesian.blend_corners(back, 0.0).length == pytest.approx(0.2)  # radius 0: kept
    with pytest.raises(InputError, match=r"radius must be a number \[m\]"):
        cartesian.blend_corners(lines, "wide")
    with pytest.raises(InputError, match=r"radius must be ≥ 0 \[m\], got -0.01"):
        cartesian.blend_corners(lines, -0.01)
    with pytest.raises(InputError, match=r"radius must be finite \[m\]"):
        cartesian.blend_corners(three, [0.01, np.nan])


# ---------------------------------------------------------------------------- torch
def _rotation_about(axis: int, angle: float) -> np.ndarray:
    vector = np.zeros(3)
    vector[axis] = angle
    return pin.exp3(vector)


@pytest.mark.parametrize("seed", range(3))
def test_torch_rotations_are_the_seam_frame_times_the_three_angle_rotations(seed):
    """R = [t, z × t, z] · Rx(work) · Ry(travel) · Rz(roll), z the normal's component across
    the tangent, reversed; tangents of any length, normals of any length and tilt."""
    rng = np.random.default_rng(seed)
    normal = rng.normal(size=3) * rng.uniform(0.1, 5.0)
    tangents = rng.normal(size=(20, 3)) * rng.uniform(0.01, 10.0, (20, 1))
    work, travel, roll = rng.uniform(-1.4, 1.4, 3)
    rotations = torch_rotations(tangents, normal, work, travel, roll)
    for tangent, rotation in zip(tangents, rotations):
        t = tangent / np.linalg.norm(tangent)
        n = normal / np.linalg.norm(normal)
        z = -(n - (n @ t) * t)
        z /= np.linalg.norm(z)
        frame = np.column_stack([t, np.cross(z, t), z])
        expected = (
            frame @ _rotation_about(0, work) @ _rotation_about(1, travel) @ _rotation_about(2, roll)
        )
        np.testing.assert_allclose(rotation, expected, atol=1e-12)
    # each angle alone: the torch axis tilts left of the travel (work), forward (travel)
    t, n = np.array([[1.0, 0.0, 0.0]]), [0.0, 0.0, 1.0]
    np.testing.assert_allclose(torch_rotations(t, n, 0.3)[0][:, 2], [0, np.sin(0.3), -np.cos(0.3)])
    np.testing.assert_allclose(
        torch_rotations(t, n, 0.0, 0.3)[0][:, 2], [np.sin(0.3), 0, -np.cos(0.3)], atol=1e-15
    )
    rolled = torch_rotations(t, n, 0.0, 0.0, 0.3)[0]
    np.testing.assert_allclose(rolled[:, 2], [0, 0, -1], atol=1e-15)
    np.testing.assert_allclose(rolled[:, 0], [np.cos(0.3), -np.sin(0.3), 0], atol=1e-15)
    with pytest.raises(InputError, match="along the surface normal"):
        torch_rotations(np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 2.0]]), n)
    # default angles 0: the seam frame itself (x along the travel, z into the surface)
    np.testing.assert_allclose(torch_rotations(t, [0, 0, 3]), [np.diag([1.0, -1.0, -1.0])])


def test_torch_on_an_arc_follows_the_tangent_with_rates_of_its_rotations():
    arc = cartesian.Arc([0.4, 0.0, 0.2], [0.45, 0.05, 0.2], [0.5, 0.0, 0.2])
    torch = cartesian.TorchOrientation(arc, [0.0, 0.0, 2.0], 0.2, -0.3, 0.4)
    np.testing.assert_allclose(torch.normal, [0.0, 0.0, 1.0])
    assert torch.slerp is None and torch.length == arc.length and torch.has_orientation
    s = np.linspace(0.0, 1.0, 21)
    np.testing.assert_allclose(torch.position(s), arc.position(s))
    for mine, theirs in zip(torch.position_derivatives(s), arc.position_derivatives(s)):
        np.testing.assert_allclose(mine, theirs)
    tangents = arc.position_derivatives(s)[0]
    np.testing.assert_allclose(
        torch.rotation(s), torch_rotations(tangents, [0, 0, 1], 0.2, -0.3, 0.4), atol=1e-15
    )
    inner = np.linspace(0.05, 0.95, 7)
    omega, domega = torch.angular_rates(inner)
    np.testing.assert_allclose(omega, _rates_by_differences(torch, inner), atol=1e-6)
    # the torch turns with the tangent: about the normal, by the arc's sweep (π) per unit s
    np.testing.assert_allclose(omega, np.tile([0.0, 0.0, -np.pi], (7, 1)), atol=1e-6)
    assert np.abs(domega).max() < 1e-3
    assert repr(torch) == f"TorchOrientation({arc!r}, work 11.5°, travel -17.2°, roll 22.9°)"
    # a gently curved seam (30°) turns the torch too: no constant rotation
    gentle = cartesian.Arc([0.0, 0.0, 0.0], [0.05, 0.0067, 0.0], [0.1, 0.0, 0.0])
    torch = cartesian.TorchOrientation(gentle)
    assert torch.slerp is None
    ends = torch.rotation(np.array([0.0, 1.0]))
    turned = np.degrees(np.linalg.norm(pin.log3(ends[0].T @ ends[1])))
    assert turned == pytest.approx(2 * np.degrees(2 * np.arctan(0.0067 / 0.05)), rel=1e-9)


def test_torch_on_a_straight_seam_is_constant():
    seam = cartesian.Line([0.4, 0.0, 0.1], [0.6, 0.1, 0.1])
    torch = cartesian.TorchOrientation(seam, [0.0, 0.3, 1.0], 0.1, 0.2, 0.3)
    assert torch.slerp is not None and torch.slerp.angle < 1e-15
    expected = torch_rotations(np.array([seam.delta]), [0.0, 0.3, 1.0], 0.1, 0.2, 0.3)[0]
    np.testing.assert_allclose(torch.rotation(np.linspace(0, 1, 5)), np.tile(expected, (5, 1, 1)))
    omega, domega = torch.angular_rates(np.array([0.2, 0.9]))
    assert np.abs(omega).max() < 1e-15 and not domega.any()
    default = cartesian.TorchOrientation(seam)
    np.testing.assert_allclose(default.normal, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(default.rotation(np.array([0.5]))[0][:, 2], [0, 0, -1], atol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"work_angle": np.pi / 2}, "work_angle must be within ±90°.*90.0°"),
        ({"work_angle": -np.pi / 2}, "work_angle must be within ±90°.*-90.0°"),
        ({"travel_angle": 1.6}, "travel_angle must be within ±90°.*91.7°"),
        ({"travel_angle": "steep"}, r"travel_angle must be a number \[rad\]"),
        ({"work_angle": np.nan}, r"work_angle must be a finite number \[rad\]"),
        ({"roll": np.inf}, r"roll must be a finite number \[rad\]"),
        ({"normal": [0.0, 0.0]}, "normal"),
        ({"normal": [0.0, 1.0]}, r"normal must be 3 numbers, got shape \(2,\)"),
        ({"normal": [0.0, 1e-10, 0.0]}, "non-zero"),
    ],
)
def test_torch_refuses_bad_angles_and_normals(kwargs, words):
    seam = cartesian.Line([0.4, 0.0, 0.1], [0.6, 0.0, 0.1])
    with pytest.raises(InputError, match=words):
        cartesian.TorchOrientation(seam, **kwargs)
    cartesian.TorchOrientation(seam, [0.0, 1e-8, 0.0], 1.57, -1.57, 10.0)  # within the limits


def test_torch_refuses_a_seam_of_no_length_and_one_into_the_surface():
    turn = cartesian.Line(_pose([0.4, 0.0, 0.1]), _pose([0.4, 0.0, 0.1], (np.pi, 0.0, 0.5)))
    with pytest.raises(InputError, match="non-zero length"):
        cartesian.TorchOrientation(turn)
    # a seam that turns into the normal only near its end is refused too (the whole seam)
    arc = cartesian.Arc([0.0, 0.0, 0.0], [0.1, 0.0, 0.1], [0.2, 0.0, 0.0])
    with pytest.raises(InputError, match="along the surface normal"):
        cartesian.TorchOrientation(arc, [1.0, 0.0, 0.0])


# ---------------------------------------------------------------------------- paths: fractions
CENTRE, RADIUS = np.array([0.4, 0.0, 0.2]), 0.1


def _half_circle(u):
    """p(u) = c + r (cos πu, sin πu, 0): at constant speed, so u is already the length
    fraction and dp/ds = πr (−sin πs, cos πs, 0), d²p/ds² = −π²r (cos πs, sin πs, 0)."""
    u = np.asarray(u, dtype=float)
    angle = np.pi * u
    return CENTRE + RADIUS * np.stack([np.cos(angle), np.sin(angle), 0.0 * angle], axis=-1)


def _half_circle_derivatives(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    angle = np.pi * s
    first = np.pi * RADIUS * np.column_stack([-np.sin(angle), np.cos(angle), 0.0 * s])
    second = -(np.pi**2) * RADIUS * np.column_stack([np.cos(angle), np.sin(angle), 0.0 * s])
    return first, second


def test_a_fraction_that_is_not_a_number_is_refused_saying_what_s_is():
    """as_fractions names what s must be: a number or a 1-D array of path fractions."""
    line = cartesian.Line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"s must be a number or a 1-D array of path fractions"):
        line.position("half")


def test_difference_derivatives_at_the_ends_are_one_sided_over_the_path():
    """A FunctionPath's derivatives are central differences of its positions: at s = 0 and
    s = 1 the difference is one-sided over a step h = 4/4001 inside the path, so dp/ds and
    d²p/ds² are the analytic ones of the half circle to O(h) there (1e-3 m, 5e-3 m) and to
    O(h²) inside (1e-6 m, 1e-5 m); a difference that reached past the end, where positions
    are held at the end point, would shrink them."""
    path = cartesian.FunctionPath(_half_circle)
    inner = np.linspace(0.1, 0.9, 9)
    first, second = path.position_derivatives(inner)
    expected_first, expected_second = _half_circle_derivatives(inner)
    np.testing.assert_allclose(first, expected_first, rtol=0, atol=1e-6)
    np.testing.assert_allclose(second, expected_second, rtol=0, atol=1e-5)
    ends = np.array([0.0, 1.0])
    first, second = path.position_derivatives(ends)
    expected_first, expected_second = _half_circle_derivatives(ends)
    np.testing.assert_allclose(first, expected_first, rtol=0, atol=1e-3)
    np.testing.assert_allclose(second, expected_second, rtol=0, atol=5e-3)


def test_a_sequence_asked_outside_its_fractions_gives_its_ends_derivatives():
    """A PathSequence clips s into [0, 1] before it maps s to its pieces: a FunctionPath piece
    (derivatives by differences) asked at s = −0.5 and 1.5 gives exactly the one-sided
    derivatives at its start and end, which are the analytic ones to O(h) (1e-3 m, 5e-3 m)."""
    sequence = cartesian.PathSequence([cartesian.FunctionPath(_half_circle)])
    first, second = sequence.position_derivatives(np.array([-0.5, 0.0, 1.0, 1.5]))
    np.testing.assert_array_equal(first[[0, 3]], first[[1, 2]])
    np.testing.assert_array_equal(second[[0, 3]], second[[1, 2]])
    expected_first, expected_second = _half_circle_derivatives(np.array([0.0, 0.0, 1.0, 1.0]))
    np.testing.assert_allclose(first, expected_first, rtol=0, atol=1e-3)
    np.testing.assert_allclose(second, expected_second, rtol=0, atol=5e-3)


def test_a_sequence_asked_at_no_fractions_gives_empty_arrays_of_its_shapes():
    """An empty s: a one-piece sequence answers (0, 3) positions and derivatives and (0, 3, 3)
    rotations (its first piece gives the shapes)."""
    pose = pin.SE3(DOWN, np.array([0.4, 0.0, 0.2]))
    line = cartesian.Line(pose, pin.SE3(DOWN, np.array([0.5, 0.0, 0.2])))
    sequence = cartesian.PathSequence([line])
    none = np.array([], dtype=float)
    assert sequence.position(none).shape == (0, 3)
    assert [d.shape for d in sequence.position_derivatives(none)] == [(0, 3), (0, 3)]
    assert sequence.rotation(none).shape == (0, 3, 3)


def test_a_position_only_path_has_zero_angular_rates_of_three_components():
    """ω_s and dω_s/ds of a path without orientation: (N, 3) zeros."""
    line = cartesian.Line([0.0, 0.0, 0.0], [0.3, 0.0, 0.0])
    omega, domega = line.angular_rates(np.linspace(0.0, 1.0, 5))
    np.testing.assert_array_equal(omega, np.zeros((5, 3)))
    np.testing.assert_array_equal(domega, np.zeros((5, 3)))


def test_an_orientation_function_is_asked_within_the_path_only_for_rates_beyond_it():
    """Rates by differences of R(s) asked at s beyond the ends: the orientation function (defined
    on [0, 1] only) is asked within [0, 1] only, and the rates there are the end's: a turn of
    0.8 rad about z over the path, ω_s = (0, 0, 0.8) rad (one-sided differences at the ends,
    exact to rounding for a constant rate), dω_s/ds = 0."""
    asked = []

    def turning(s: float) -> np.ndarray:
        asked.append(s)
        return pin.exp3(np.array([0.0, 0.0, 0.8 * s]))

    path = cartesian.FunctionPath(_half_circle, orientation=turning)
    asked.clear()
    with np.errstate(all="raise"):  # no 0/0 beyond the ends
        omega, domega = path.angular_rates(np.array([-0.5, 0.0, 0.5, 1.0, 1.5, 7.0]))
    assert asked and min(asked) >= 0.0 and max(asked) <= 1.0
    np.testing.assert_allclose(omega, np.tile([0.0, 0.0, 0.8], (6, 1)), atol=1e-6)
    np.testing.assert_array_equal(omega[:2], omega[[0]].repeat(2, axis=0))
    np.testing.assert_array_equal(omega[3:], omega[[3]].repeat(3, axis=0))
    np.testing.assert_allclose(domega, 0.0, atol=1e-3)


def test_position_derivatives_beyond_the_ends_are_the_ends():
    """dp/ds and d²p/ds² by finite differences at s beyond [0, 1]: the values at the nearest
    end (one-sided differences), finite, not 0/0 (a FunctionPath and a Weave on it)."""
    path = cartesian.FunctionPath(_half_circle)
    weave = cartesian.Weave(cartesian.Line([0.0, 0.0, 0.0], [0.4, 0.0, 0.0]), 0.01, 0.05)
    for p in (path, weave):
        with np.errstate(all="raise"):
            first, second = p.position_derivatives(np.array([-0.5, 0.0, 1.0, 1.5, 7.0]))
        np.testing.assert_array_equal(first[0], first[1])
        np.testing.assert_array_equal(second[0], second[1])
        np.testing.assert_array_equal(first[3:], first[[2]].repeat(2, axis=0))
        np.testing.assert_array_equal(second[3:], second[[2]].repeat(2, axis=0))


def test_an_oriented_path_without_a_slerp_must_implement_its_rotations():
    """Path is a base class: an oriented subclass with neither a slerp nor _rotation is told
    what to implement."""

    class Bare(cartesian.Path):
        has_orientation = True
        length = 1.0

        def position(self, s):
            return np.zeros((len(np.atleast_1d(s)), 3))

    with pytest.raises(NotImplementedError, match="without a slerp implements _rotation"):
        Bare().rotation(np.array([0.5]))


# ---------------------------------------------------------------------------- paths: Arc
def test_arc_collinearity_is_judged_against_the_longer_side():
    """A via point 1 m out and an end 1 cm from the start, 1e-11 m off the line through
    them (a circle of radius ~5e8 m): |ab × ac| = 1e-11 m² is within 1e-9 × the longer side
    squared (1 m²), though not of the shorter one (1e-13 m²): refused as collinear."""
    with pytest.raises(InputError, match="collinear"):
        cartesian.Arc([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.01, 1e-11, 0.0])


@pytest.mark.parametrize("chord", [0.01, 1.0, 10.0])
def test_arc_collinearity_is_relative_to_the_size_of_the_points(chord):
    """Start and end a chord apart, the via point midway and off the chord by a sagitta of
    5e-10 chord (refused as collinear) or 4e-9 chord (an arc, of the chord's length to 1e-12,
    from the start to the end to 1e-7 chord), the same at 1 cm, 1 m and 10 m."""
    start, end = np.zeros(3), np.array([chord, 0.0, 0.0])
    with pytest.raises(InputError, match="collinear"):
        cartesian.Arc(start, [0.5 * chord, 5e-10 * chord, 0.0], end)
    arc = cartesian.Arc(start, [0.5 * chord, 4e-9 * chord, 0.0], end)
    assert arc.length == pytest.approx(chord, rel=1e-12)
    np.testing.assert_allclose(
        arc.position(np.array([0.0, 1.0])), [start, end], rtol=0, atol=1e-7 * chord
    )


def test_an_arc_whose_circumcentre_rounds_onto_a_point_is_refused_as_an_arc():
    """A right triangle one rounding step (2.2e-16 m) on a side, 1.7 m from the origin: its
    circumcentre, a half step from the start in two coordinates, rounds onto the start (a
    radius of 0). The Arc refuses the circle itself, rather than failing later on a unit
    vector of NaN."""
    step = np.spacing(1.0)
    with pytest.raises(InputError, match="cannot be computed in double precision"):
        cartesian.Arc([1.0, 1.0, 1.0], [1.0, 1.0 + step, 1.0], [1.0 + step, 1.0, 1.0])


# ---------------------------------------------------------------------------- paths: Weave
SEAM_X = ([0.4, 0.0, 0.2], [0.6, 0.0, 0.2])  # 0.2 m along x


def _sine_weave(s: np.ndarray, start, direction, across, amplitude, wavelength) -> np.ndarray:
    """Seam point plus A sin(2π u / λ) along ``across``, u = s × the seam length."""
    direction = np.asarray(direction, dtype=float)
    u = s * np.linalg.norm(direction)
    offset = amplitude * np.sin(2.0 * np.pi * u / wavelength)
    return np.asarray(start) + s[:, None] * direction + offset[:, None] * np.asarray(across)


@pytest.mark.parametrize(
    ("args", "kwargs", "words"),
    [
        ((0.001, 0.0), {}, r"wavelength must be > 0 \[m\], got 0.0"),
        ((0.001, -0.01), {}, r"wavelength must be > 0 \[m\], got -0.01"),
        ((0.001, 0.01), {"dwell": -0.001}, r"dwell must be ≥ 0 \[m\], got -0.001"),
        ((0.1, 0.01), {}, r"amplitude 0.1 m is not small against the seam \(0.2 m long\)"),
        ((0.001, 0.01), {"normal": [0.0, 0.0, 0.999e-9]}, "normal must be a non-zero 3-vector"),
    ],
)
def test_weave_refuses_each_argument_at_its_limit_by_name(args, kwargs, words):
    """A 0.2 m seam: a wavelength of 0 or below, a negative dwell, an amplitude of half the seam
    and a normal shorter than 1e-9 are each refused with their own message."""
    with pytest.raises(InputError, match=words):
        cartesian.Weave(cartesian.Line(*SEAM_X), *args, **kwargs)


def test_weave_accepts_the_arguments_just_inside_their_limits():
    """An amplitude just under half the seam (0.2 m and 4 m seams), a dwell of 0, and normals of
    length 1e-9 (exactly) and 1e-6, normalised."""
    seam = cartesian.Line(*SEAM_X)
    assert cartesian.Weave(seam, 0.0999, 0.01, dwell=0.0).amplitude == 0.0999
    long_seam = cartesian.Line([0.0, 0.0, 0.0], [4.0, 0.0, 0.0])
    assert cartesian.Weave(long_seam, 1.99, 0.5).amplitude == 1.99
    for size in (1e-9, 1e-6):
        weave = cartesian.Weave(seam, 0.001, 0.01, normal=[0.0, 0.0, size])
        np.testing.assert_allclose(weave.normal, [0.0, 0.0, 1.0], rtol=0, atol=1e-15)


def test_weave_refuses_a_seam_of_zero_length():
    """A Line that only turns the tool has length 0: no seam to weave along."""
    turn = cartesian.Line(_pose([0.4, 0.0, 0.1]), _pose([0.4, 0.0, 0.1], (np.pi, 0.0, 0.5)))
    assert turn.length == 0.0
    with pytest.raises(InputError, match="Weave needs a seam of non-zero length"):
        cartesian.Weave(turn, 0.001, 0.01)


def test_weave_across_an_explicit_normal_is_perpendicular_to_it():
    """normal (0, 3, 4): kept as its unit vector (0, 0.6, 0.8); on a seam along x the torch
    weaves along n × t = (0, 0.8, −0.6), A sin(2πu/λ) (1e-12 m)."""
    seam = cartesian.Line(*SEAM_X)
    weave = cartesian.Weave(seam, 0.002, 0.01, normal=[0.0, 3.0, 4.0])
    np.testing.assert_allclose(weave.normal, [0.0, 0.6, 0.8], rtol=0, atol=1e-15)
    s = np.linspace(0.0, 1.0, 201)
    expected = _sine_weave(s, SEAM_X[0], [0.2, 0.0, 0.0], [0.0, 0.8, -0.6], 0.002, 0.01)
    np.testing.assert_allclose(weave.position(s), expected, rtol=0, atol=1e-12)


def test_weave_of_a_position_only_seam_stays_in_the_horizontal_plane():
    """No orientation and no normal: n is the world z, so a seam along y weaves along
    z × y = −x, in its own horizontal plane (1e-12 m)."""
    start = [0.4, 0.0, 0.2]
    seam = cartesian.Line(start, [0.4, 0.2, 0.2])
    weave = cartesian.Weave(seam, 0.002, 0.01)
    assert weave.normal is None
    s = np.linspace(0.0, 1.0, 201)
    expected = _sine_weave(s, start, [0.0, 0.2, 0.0], [-1.0, 0.0, 0.0], 0.002, 0.01)
    np.testing.assert_allclose(weave.position(s), expected, rtol=0, atol=1e-12)


def test_weave_refuses_a_seam_within_1e_9_rad_of_the_world_z():
    """A position-only seam 1 m long and 7.5e-10 rad off the (default, unit) world z runs
    along the normal to 1e-9: refused; at 1.5e-9 rad it is woven."""
    with pytest.raises(InputError, match="the seam runs along the normal"):
        cartesian.Weave(cartesian.Line([0.0, 0.0, 0.0], [7.5e-10, 0.0, 1.0]), 0.001, 0.01)
    cartesian.Weave(cartesian.Line([0.0, 0.0, 0.0], [1.5e-9, 0.0, 1.0]), 0.001, 0.01)


@pytest.mark.parametrize(
    "points",
    [
        [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.0, 0.1], [0.3, 0.0, 0.1]],
        [[0.0, 0.0, 0.0], [0.025, 0.0, 0.0], [0.025, 0.0, 0.013], [2.547, 0.0, 0.013]],
    ],
)
def test_weave_refuses_a_seam_that_runs_along_the_normal_for_a_stretch(points):
    """A horizontal seam with a vertical step in it (along the world z, the default normal):
    0.1 m of a 0.4 m seam, or 13 mm of a 2.56 m one (s from 2.5/256 to 3.8/256: between two
    fractions 1/128 apart, around one of the 257 evenly spaced fractions the whole seam is
    checked at)."""
    with pytest.raises(InputError, match="the seam runs along the normal somewhere"):
        cartesian.Weave(cartesian.Polyline(points), 0.001, 0.01)


def test_weave_of_an_oriented_seam_keeps_the_seams_slerp():
    """A seam of poses turning 0.6 rad about the world z: the weave's orientation is the seam's
    slerp (the same object), R0 exp(s log(R0ᵀ R1)) by Pinocchio (1e-15), and it weaves across
    the tool axis (−z): along (−z) × x = −y (1e-12 m)."""
    r0, r1 = pin.rpy.rpyToMatrix(np.pi, 0.0, 0.0), pin.rpy.rpyToMatrix(np.pi, 0.0, 0.6)
    seam = cartesian.Line(pin.SE3(r0, np.array(SEAM_X[0])), pin.SE3(r1, np.array(SEAM_X[1])))
    weave = cartesian.Weave(seam, 0.002, 0.01)
    assert weave.slerp is seam.slerp
    s = np.linspace(0.0, 1.0, 11)
    expected = [r0 @ pin.exp3(f * pin.log3(r0.T @ r1)) for f in s]
    np.testing.assert_allclose(weave.rotation(s), expected, rtol=0, atol=1e-15)
    np.testing.assert_allclose(weave.slerp(s), expected, rtol=0, atol=1e-15)
    s = np.linspace(0.0, 1.0, 201)
    expected = _sine_weave(s, SEAM_X[0], [0.2, 0.0, 0.0], [0.0, -1.0, 0.0], 0.002, 0.01)
    np.testing.assert_allclose(weave.position(s), expected, rtol=0, atol=1e-12)


def test_weave_of_a_seam_held_at_a_rotation_weaves_across_the_held_tool_axis():
    """HeldOrientation of a position-only seam along x at Rx(π/2) (tool axis −y): the weave
    keeps the seam's difference step and offsets along (−y) × x = z (1e-12 m)."""
    seam = cartesian.Line(*SEAM_X)
    held = cartesian.HeldOrientation(seam, pin.rpy.rpyToMatrix(np.pi / 2, 0.0, 0.0))
    weave = cartesian.Weave(held, 0.002, 0.01)
    s = np.linspace(0.0, 1.0, 201)
    expected = _sine_weave(s, SEAM_X[0], [0.2, 0.0, 0.0], [0.0, 0.0, 1.0], 0.002, 0.01)
    np.testing.assert_allclose(weave.position(s), expected, rtol=0, atol=1e-12)


def test_weave_across_a_curved_seam_and_beyond_its_ends():
    """On a position-only half circle (normal z) the direction across the seam is z × t, the
    inward radius −(cos πs, sin πs, 0) (1e-9 inside, where the differences are central; 2e-3
    at the one-sided ends); asked beyond the ends it is exactly that at the nearest end."""
    weave = cartesian.Weave(cartesian.FunctionPath(_half_circle), 0.002, 0.02)
    inner = np.linspace(0.05, 0.95, 19)
    inward = -np.column_stack([np.cos(np.pi * inner), np.sin(np.pi * inner), 0.0 * inner])
    np.testing.assert_allclose(weave.across(inner), inward, rtol=0, atol=1e-9)
    ends = weave.across(np.array([0.0, 1.0]))
    np.testing.assert_allclose(ends, [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], rtol=0, atol=2e-3)
    beyond = weave.across(np.array([-0.5, 1.5, 7.0]))
    np.testing.assert_array_equal(beyond, ends[[0, 1, 1]])


def test_weave_asks_its_seam_within_its_fractions_only():
    """A seam of one's own (a Path subclass) that extrapolates beyond its ends: the weave
    clips s into [0, 1] before it asks the seam, so at s = −0.5 and 1.5 it is exactly at its
    own start and end, on the seam's ends."""

    class Extrapolating(cartesian.Path):
        """p(s) = a + s d for any s, not clipped."""

        a, d = np.array([0.4, 0.0, 0.2]), np.array([0.2, 0.0, 0.0])
        length = 0.2

        def position(self, s):
            return self.a + np.asarray(s, dtype=float)[:, None] * self.d

        def position_derivatives(self, s):
            n = len(np.atleast_1d(s))
            return np.tile(self.d, (n, 1)), np.zeros((n, 3))

    weave = cartesian.Weave(Extrapolating(), 0.002, 0.01)
    beyond = weave.position(np.array([-0.5, 1.5]))
    np.testing.assert_array_equal(beyond, weave.position(np.array([0.0, 1.0])))
    np.testing.assert_allclose(beyond, [SEAM_X[0], SEAM_X[1]], rtol=0, atol=1e-15)


def test_weave_refuses_a_stretch_along_the_normal_between_its_construction_samples():
    """A 7 mm vertical step in a 2.56 m horizontal seam, between two of the 257 fractions the
    construction checks (k/256 for k = 2, 3): the weave is built, but asked where the step is
    (s ≈ 0.0094) it says the seam runs along the normal there instead of returning NaN; away
    from the step it weaves."""
    points = [[0.0, 0.0, 0.0], [0.0205, 0.0, 0.0], [0.0205, 0.0, 0.007], [2.553, 0.0, 0.007]]
    weave = cartesian.Weave(cartesian.Polyline(points), 0.001, 0.01)
    s_step = (0.0205 + 0.0035) / weave.length
    assert 2 / 256 < s_step < 3 / 256
    with pytest.raises(InputError, match=r"runs along the normal at s = 0\.009"):
        weave.position(np.array([0.5, s_step]))
    assert np.all(np.isfinite(weave.position(np.linspace(0.02, 1.0, 50))))
