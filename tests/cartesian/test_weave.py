"""Weaving (`cartesian.Weave`, issue 17): a lateral oscillation across any seam."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from kinplan.errors import InputError

UR5_START = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])


def _seam(robot, q0, offset=(0.0, 0.2, 0.0)):
    start = robot.fk(q0)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + np.asarray(offset)))


@pytest.mark.parametrize("pattern", ["sine", "triangle", "trapezoid"])
def test_offsets_stay_within_the_amplitude_and_oscillate_once_per_wavelength(ur5, pattern):
    """On a 0.2 m line with λ = 10 mm: |offset| ≤ A everywhere and reaches A, 20 oscillations
    (40 sign changes, the last at the end), the offset across the seam (perpendicular to the
    seam and to the tool axis), and the seam-wise progress exactly s · L."""
    seam = _seam(ur5, UR5_START)
    weave = cartesian.Weave(seam, amplitude=0.002, wavelength=0.01, pattern=pattern)
    s = np.linspace(0.0, 1.0, 40001)
    offset = weave.offset(s)
    assert np.max(np.abs(offset)) == pytest.approx(0.002, rel=1e-6)
    assert np.all(np.abs(offset) <= 0.002 * (1 + 1e-12))
    signs = np.sign(offset[np.abs(offset) > 1e-9])
    assert np.count_nonzero(np.diff(signs)) == 2 * 20 - 1
    points = weave.position(s)
    along = (points - seam.a) @ (seam.delta / seam.length)
    np.testing.assert_allclose(along, s * seam.length, atol=1e-12)  # constant travel
    tool_axis = ur5.fk(UR5_START).rotation[:, 2]
    lateral = points - seam.position(s)
    np.testing.assert_allclose(lateral @ tool_axis, 0.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(lateral, axis=1), np.abs(offset), atol=1e-12)
    assert weave.length == seam.length


def test_dwell_holds_the_torch_at_each_side(ur5):
    """A trapezoid with 2 mm dwell in a 10 mm wavelength: the torch is at +A or −A for
    (quarter wavelength of the moving part + dwell) on each side, less the half rounding of the
    corner at each end of the side (λ/16 by default): 2·(1.5 + 2 − 0.625) of every 10 mm."""
    seam = _seam(ur5, UR5_START)
    weave = cartesian.Weave(seam, 0.002, 0.01, pattern="trapezoid", dwell=0.002)
    assert weave.rounding == 0.01 / 16
    s = np.linspace(0.0, 1.0, 200001)
    at_side = np.isclose(np.abs(weave.offset(s)), 0.002, rtol=0, atol=1e-12)
    side = 0.25 * (0.01 - 0.004) + 0.002 - weave.rounding
    assert np.mean(at_side) == pytest.approx(2 * side / 0.01, abs=2e-3)


def test_a_woven_seam_is_followed_at_constant_travel_speed(ur5):
    """Followed at 10 mm/s with dt = 2 ms: ok, the tool on the woven path (1e-7 m), the travel
    along the seam at 10 mm/s during the cruise (1 %), the orientation held."""
    seam = _seam(ur5, UR5_START, (0.0, 0.05, 0.0))
    weave = cartesian.Weave(seam, amplitude=0.002, wavelength=0.005)
    plan = cartesian.follow(ur5, weave, speed=0.01, dt=0.002, q_seed=UR5_START)
    assert plan.ok, plan
    assert plan.max_deviation <= 1e-7
    along = (plan.tool_positions - seam.a) @ (seam.delta / seam.length)
    travel = np.diff(along) / np.diff(plan.t)
    cruise = (plan.t[1:] > 0.3) & (plan.t[1:] < plan.t[-1] - 0.3)
    np.testing.assert_allclose(travel[cruise], 0.01, rtol=0.01)
    rotation = ur5.fk(UR5_START).rotation
    for q in plan.q[::100]:
        np.testing.assert_allclose(ur5.fk(q).rotation, rotation, atol=1e-6)


def test_bad_weaves():
    seam = cartesian.Line([0.4, 0.0, 0.2], [0.4, 0.2, 0.2])
    with pytest.raises(InputError, match="amplitude"):
        cartesian.Weave(seam, -0.001, 0.01)
    with pytest.raises(InputError, match="pattern"):
        cartesian.Weave(seam, 0.001, 0.01, pattern="zigzag")
    with pytest.raises(InputError, match="dwell"):
        cartesian.Weave(seam, 0.001, 0.01, dwell=0.005)
    with pytest.raises(InputError, match="normal"):
        cartesian.Weave(seam, 0.001, 0.01, normal=[0.0, 1.0, 0.0])  # along the seam
    with pytest.raises(InputError, match="path"):
        cartesian.Weave("seam", 0.001, 0.01)
