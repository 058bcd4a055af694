"""Blended corners (cartesian.blends) and torch angles (cartesian.torch) against independent
answers: a sub-path against its parent path at the mapped fractions and against finite
differences of itself, a corner blend's end conditions against the quintic's definition and its
parametrisation against the arc length of a dense polyline, the cuts against the sphere of the
radius, the per-corner radii and the refusals naming the corner; torch rotations against a
product of Pinocchio's exponentials, their frame against the seam's tangent and normal."""

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
