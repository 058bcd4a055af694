"""Torch angles (cartesian.torch): the tool axis against the seam tangent and the surface
normal, on lines and arcs, and a UR5 following a torch seam."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
from kinplan.errors import InputError

UR5_START = np.array([0.0, -1.6, 1.6, -1.57, -1.57, 0.0])


def frame_parts(path: cartesian.TorchOrientation, s: np.ndarray):
    """Torch axis (tool z) expressed in the seam frame: (along t, along y0, along z0)."""
    rotations = path.rotation(s)
    tangents, _ = path.position_derivatives(s)
    t = tangents / np.linalg.norm(tangents, axis=1)[:, None]
    n = path.normal
    z0 = -(n - (t @ n)[:, None] * t)
    z0 /= np.linalg.norm(z0, axis=1)[:, None]
    y0 = np.cross(z0, t)
    axis = rotations[:, :, 2]
    return np.sum(axis * t, 1), np.sum(axis * y0, 1), np.sum(axis * z0, 1), rotations


def test_zero_angles_point_the_torch_into_the_surface():
    seam = cartesian.Line([0.4, 0.0, 0.1], [0.6, 0.0, 0.1])
    torch = cartesian.TorchOrientation(seam, [0, 0, 1])
    rotation = torch.rotation(np.array([0.3]))[0]
    np.testing.assert_allclose(rotation[:, 2], [0, 0, -1], atol=1e-15)  # torch axis down
    np.testing.assert_allclose(rotation[:, 0], [1, 0, 0], atol=1e-15)  # x along the travel
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    assert torch.slerp is not None  # a straight seam: constant rotation, exact zero rates
    rates, _ = torch.angular_rates(np.array([0.0, 0.5]))
    assert np.all(rates == 0.0)


@pytest.mark.parametrize(
    ("work", "travel", "roll"), [(30.0, 0.0, 0.0), (0.0, 15.0, 0.0), (45.0, -10.0, 20.0)]
)
def test_angles_hold_along_an_arc(work, travel, roll):
    """Torch axis in the seam frame: (sin θ, −sin φ cos θ, cos φ cos θ) for work φ, travel θ,
    whatever the roll, at every point of a tilted arc."""
    normal = np.array([0.2, -0.1, 1.0])
    normal /= np.linalg.norm(normal)
    e1 = np.cross(normal, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(normal, e1)
    arc = cartesian.CircularArc([0.4, 0.1, 0.2], 0.08, e1, e2, 2.5)
    phi, theta = np.radians(work), np.radians(travel)
    torch = cartesian.TorchOrientation(arc, normal, phi, theta, np.radians(roll))
    s = np.linspace(0.0, 1.0, 51)
    along, across, down, rotations = frame_parts(torch, s)
    np.testing.assert_allclose(along, np.sin(theta), atol=1e-12)
    np.testing.assert_allclose(across, -np.sin(phi) * np.cos(theta), atol=1e-12)
    np.testing.assert_allclose(down, np.cos(phi) * np.cos(theta), atol=1e-12)
    products = rotations @ rotations.transpose(0, 2, 1)
    np.testing.assert_allclose(products, np.broadcast_to(np.eye(3), products.shape), atol=1e-12)
    # angular rate = d(rotation)/ds, by differences of the rotations themselves
    h = 1e-6
    mid = np.linspace(0.1, 0.9, 9)
    omega, _ = torch.angular_rates(mid)
    numeric = np.array(
        [
            pin.log3(b @ a.T) / (2 * h)
            for a, b in zip(torch.rotation(mid - h), torch.rotation(mid + h))
        ]
    )
    np.testing.assert_allclose(omega, numeric, atol=1e-5)


def test_ur5_follows_a_torch_seam(ur5):
    p0 = ur5.fk(UR5_START).translation
    seam = cartesian.Line(p0, p0 + [0.12, 0.05, 0.0])
    torch = cartesian.TorchOrientation(seam, [0, 0, 1], np.radians(20), np.radians(10))
    seed = ur5.ik(torch.start, q_seed=UR5_START).q
    plan = cartesian.follow(ur5, torch, speed=0.03, q_seed=seed)
    assert plan.ok, plan.summary()
    expected = torch.rotation(np.array([0.0]))[0]
    for q in plan.q[::25]:
        np.testing.assert_allclose(ur5.fk(q).rotation, expected, atol=1e-6)


def test_bad_torch_angles():
    seam = cartesian.Line([0.4, 0.0, 0.1], [0.6, 0.0, 0.1])
    with pytest.raises(InputError, match="work_angle"):
        cartesian.TorchOrientation(seam, [0, 0, 1], np.radians(95.0))
    with pytest.raises(InputError, match="normal"):
        cartesian.TorchOrientation(seam, [0, 0, 0])
    with pytest.raises(InputError, match="along the surface normal"):
        cartesian.TorchOrientation(seam, [1, 0, 0])
    with pytest.raises(InputError, match="seam path"):
        cartesian.TorchOrientation("seam")
