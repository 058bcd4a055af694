"""Cartesian paths on their own: the rates of a path with an orientation function against the
analytic angular velocity, path fractions outside [0, 1], and how sequences are assembled."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from kinplan.errors import InputError

A, B = 1.3, 0.7  # [rad per unit s] of the test orientation R(s) = Rz(A s) Rx(B s)
R0 = pin.utils.rpyToMatrix(0.2, -0.4, 0.9)


def twisting(s: float) -> np.ndarray:
    """R(s) = R0 Rz(A s) Rx(B s), defined on the path fractions [0, 1] only."""
    assert 0.0 <= s <= 1.0, f"orientation asked outside the path: s = {s}"
    return R0 @ pin.exp3(np.array([0.0, 0.0, A * s])) @ pin.exp3(np.array([B * s, 0.0, 0.0]))


def twisting_rates(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World angular velocity per unit s of R(s) = R0 Rz(As) Rx(Bs), and its s-derivative:
    ω_s = A R0 ez + B R0 Rz(As) ex, dω_s/ds = A B R0 (ez × Rz(As) ex)."""
    ez, ex = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
    omega, rate = [], []
    for x in s:
        turned = pin.exp3(np.array([0.0, 0.0, A * x])) @ ex
        omega.append(A * R0 @ ez + B * R0 @ turned)
        rate.append(A * B * R0 @ np.cross(ez, turned))
    return np.array(omega), np.array(rate)


def helix(u):
    u = np.asarray(u, dtype=float)
    return np.stack([0.2 * np.cos(2 * u), 0.2 * np.sin(2 * u), 0.1 * u], axis=-1)


def test_angular_rates_of_an_orientation_function_are_the_analytic_ones():
    """A FunctionPath with an orientation function R(s): ω_s and dω_s/ds (by differences of
    R, the path's own fallback) equal the analytic rates inside the path and at both ends
    (one-sided there), and the function is only ever asked within [0, 1]."""
    path = cartesian.FunctionPath(helix, orientation=twisting)
    inner = np.linspace(0.05, 0.95, 19)
    omega, rate = path.angular_rates(inner)
    expected_omega, expected_rate = twisting_rates(inner)
    np.testing.assert_allclose(omega, expected_omega, atol=1e-6)
    np.testing.assert_allclose(rate, expected_rate, atol=1e-5)
    ends = np.array([0.0, 1.0])
    omega, rate = path.angular_rates(ends)
    expected_omega, expected_rate = twisting_rates(ends)
    np.testing.assert_allclose(omega, expected_omega, atol=2e-3)
    np.testing.assert_allclose(rate, expected_rate, atol=2e-2)
    rotations = path.rotation(inner)
    for s, rotation in zip(inner, rotations):
        assert np.linalg.norm(pin.log3(rotation.T @ twisting(s))) < 1e-12


@pytest.mark.parametrize("kind", ["line", "arc", "function", "sequence"])
def test_fractions_outside_the_path_are_its_ends(kind):
    """s < 0 is the start and s > 1 the end: positions, rotations and (one-sided) rates are
    those of the nearest end, for every kind of path."""
    r1 = R0 @ pin.exp3(np.array([0.0, 0.0, 0.8]))
    start, via, end = np.array([0.4, 0.0, 0.3]), np.array([0.5, 0.1, 0.3]), [0.4, 0.2, 0.3]
    if kind == "line":
        path = cartesian.Line(pin.SE3(R0, start), pin.SE3(r1, np.array(end)))
    elif kind == "arc":
        path = cartesian.Arc(pin.SE3(R0, start), pin.SE3(R0, via), pin.SE3(r1, np.array(end)))
    elif kind == "function":
        path = cartesian.FunctionPath(helix, orientation=twisting)
    else:
        path = cartesian.PathSequence(
            [cartesian.Line(pin.SE3(R0, start), pin.SE3(r1, via)), cartesian.Line(
                pin.SE3(r1, via), pin.SE3(r1, np.array(end)))]
        )  # fmt: skip
    outside = np.array([-0.5, -1e-3, 1.0 + 1e-3, 1.5, 7.0])
    ends = np.array([0.0, 0.0, 1.0, 1.0, 1.0])
    np.testing.assert_allclose(path.position(outside), path.position(ends), atol=1e-15)
    np.testing.assert_allclose(path.rotation(outside), path.rotation(ends), atol=1e-15)
    np.testing.assert_allclose(path.pose(-0.5).translation, path.start.translation, atol=1e-15)
    np.testing.assert_allclose(path.pose(1.5).translation, path.end.translation, atol=1e-15)


def test_arc_positions_beyond_the_sweep_are_not_extrapolated():
    """A quarter circle asked at s = 2 stays at its end, not half a turn further."""
    arc = cartesian.CircularArc([0, 0, 0], 1.0, [1, 0, 0], [0, 1, 0], np.pi / 2)
    np.testing.assert_allclose(arc.position(np.array([2.0, -1.0])), [[0, 1, 0], [1, 0, 0]],
                               atol=1e-15)  # fmt: skip
    first, second = arc.position_derivatives(np.array([-1.0, 2.0]))
    np.testing.assert_allclose(first, [[0, np.pi / 2, 0], [-np.pi / 2, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(
        second, [[-(np.pi**2) / 4, 0, 0], [0, -(np.pi**2) / 4, 0]], atol=1e-15
    )


def test_nested_sequences_are_flattened_and_breaks_sit_at_every_piece():
    """A sequence of a sequence and a line is one flat sequence of three pieces: its breaks are
    the cumulative length shares of the three, and it evaluates like the flat one."""
    p = [np.array(x, dtype=float) for x in ([0, 0, 0], [0.1, 0, 0], [0.1, 0.3, 0], [0.5, 0.3, 0])]
    inner = cartesian.PathSequence([cartesian.Line(p[0], p[1]), cartesian.Line(p[1], p[2])])
    nested = cartesian.PathSequence([inner, cartesian.Line(p[2], p[3])])
    flat = cartesian.Polyline(p)
    assert len(nested.paths) == 3
    np.testing.assert_allclose(nested.breaks, [0.0, 0.125, 0.5, 1.0], atol=1e-15)
    s = np.linspace(0.0, 1.0, 41)
    np.testing.assert_allclose(nested.position(s), flat.position(s), atol=1e-15)


def test_sequence_gaps_and_turns_are_refused_with_the_piece_named():
    """A second piece starting 1 mm away, or turned by 0.5 rad, is refused, naming piece 2."""
    rot = np.eye(3)
    first = cartesian.Line(pin.SE3(rot, np.zeros(3)), pin.SE3(rot, np.array([0.1, 0, 0])))
    away = cartesian.Line(
        pin.SE3(rot, np.array([0.101, 0, 0])), pin.SE3(rot, np.array([0.2, 0, 0]))
    )
    turned_rot = pin.exp3(np.array([0.0, 0.0, 0.5]))
    turned = cartesian.Line(
        pin.SE3(turned_rot, np.array([0.1, 0, 0])), pin.SE3(turned_rot, np.array([0.2, 0, 0]))
    )
    with pytest.raises(InputError, match=r"piece 2 of the sequence starts 0\.001 m"):
        cartesian.PathSequence([first, away])
    with pytest.raises(InputError, match=r"piece 2 .* 0\.5 rad away from where piece 1 ends"):
        cartesian.PathSequence([first, turned])
    # a turn under the 1e-6 rad tolerance is continuous
    nearly = pin.exp3(np.array([0.0, 0.0, 5e-7]))
    cartesian.PathSequence(
        [
            first,
            cartesian.Line(
                pin.SE3(nearly, np.array([0.1, 0, 0])), pin.SE3(nearly, np.array([0.2, 0, 0]))
            ),
        ]
    )


def test_pose_fraction_is_validated_by_name():
    line = cartesian.Line([0, 0, 0], [1, 0, 0])
    with pytest.raises(InputError, match=r"\bs\b"):
        line.pose("half")


def test_slerp_is_the_exponential_map_from_the_start_rotation():
    """R(s) = R0 exp(s log(R0ᵀ R1)) against Pinocchio's exp3 sample by sample, 1e-15: random
    rotations (300 pairs), near half a turn and a tiny turn; exactly R0 where the turn sθ is
    below 1e-12 rad (s = 0, s = 1e-14, a 1e-13 rad turn, none)."""
    rng = np.random.default_rng(12)
    s = np.concatenate([[0.0, 1.0], rng.uniform(0.0, 1.0, 40)])
    pairs = [(pin.exp3(rng.normal(size=3)), pin.exp3(rng.normal(size=3))) for _ in range(300)]
    r0 = pin.exp3(rng.normal(size=3))
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    pairs += [(r0, r0 @ pin.exp3(angle * axis)) for angle in (np.pi - 1e-6, 1e-9)]
    for start, end in pairs:
        slerp = cartesian.paths.Slerp(start, end)
        expected = np.array([start @ pin.exp3(f * slerp.local_axis) for f in s])
        rotations = slerp(s)
        np.testing.assert_allclose(rotations, expected, rtol=0.0, atol=1e-15)
        np.testing.assert_array_equal(rotations[0], start)
        np.testing.assert_array_equal(slerp(np.array([1e-14]))[0], start)
        np.testing.assert_allclose(slerp.angle, np.linalg.norm(slerp.local_axis), rtol=1e-15)
    for end in (r0 @ pin.exp3(1e-13 * axis), r0):
        still = cartesian.paths.Slerp(r0, end)
        np.testing.assert_array_equal(still(s), np.broadcast_to(r0, (len(s), 3, 3)))
