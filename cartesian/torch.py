"""Welding torch angles: the tool orientation along a seam from its tangent and the surface normal.

Welding procedures give the torch orientation relative to the seam (AWS A3.0 terms): the
**work angle** tilts the torch across the seam, the **travel angle** along it (positive: push,
the torch pointing ahead in the direction of travel; negative: drag), the **roll** turns it about
its own axis. :class:`TorchOrientation` turns these into the tool rotation at every point of a
seam, so the torch keeps its angles to the seam through arcs and blended corners.

Frames: the tool's z axis is the torch axis, pointing from the torch to the work (the direction
a Universal Robots or Panda flange points). At angles 0 the torch stands along −n (n the surface
normal), its x axis along the travel direction t. With the seam frame F = [t, z₀ × t, z₀] where
z₀ = −(n − (n·t) t)/|…|, the tool rotation is R = F · Rx(work) · Ry(travel) · Rz(roll): a positive
work angle tilts the torch axis toward the left of the travel direction (seen from the side the
normal points to), a positive travel angle tilts it forward.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from cartesian.paths import Path, Slerp, as_fractions
from kinplan import checks
from kinplan.errors import InputError

__all__ = ["TorchOrientation", "torch_rotations"]


def _axis_rotation(axis: int, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3  # cyclic: y rotates z toward x
    rotation = np.eye(3)
    rotation[i, i], rotation[i, j], rotation[j, i], rotation[j, j] = c, -s, s, c
    return rotation


def torch_rotations(
    tangents: np.ndarray,
    normal: ArrayLike,
    work_angle: float = 0.0,
    travel_angle: float = 0.0,
    roll: float = 0.0,
) -> np.ndarray:
    """Tool rotations (N, 3, 3) for seam tangents (N, 3), a surface normal and torch angles.

    Args:
        tangents: Seam directions (need not be unit), world frame.
        normal: Surface normal n (world frame), pointing away from the work.
        work_angle: Tilt across the seam [rad].
        travel_angle: Tilt along the seam [rad], positive = push.
        roll: Turn about the torch axis [rad].

    Raises:
        InputError: a tangent parallel to the normal (the seam runs into the surface).
    """
    n = np.asarray(normal, dtype=float)
    t = tangents / np.linalg.norm(tangents, axis=1)[:, None]
    in_plane = n - (t @ n)[:, None] * t
    norms = np.linalg.norm(in_plane, axis=1)
    if np.any(norms < 1e-6):
        raise InputError(
            "torch: the seam runs along the surface normal somewhere, so the torch angles are "
            "undefined there; give the normal of the surface the seam lies on"
        )
    z = -in_plane / norms[:, None]
    y = np.cross(z, t)
    frames = np.stack([t, y, z], axis=2)  # columns: x = t, y, z
    local = _axis_rotation(0, work_angle) @ _axis_rotation(1, travel_angle)
    local = local @ _axis_rotation(2, roll)
    return frames @ local


class TorchOrientation(Path):
    """A seam with the torch held at welding angles to it (see the module docstring).

    The position is the seam's; the rotation follows its tangent. On a straight seam the
    rotation is constant (exact zero angular rates); on curved seams the angular rates come from
    central differences of the rotations.

    Args:
        path: The seam (its own orientation, if any, is replaced).
        normal: Surface normal (world frame), 3-vector, default +z (a seam on a horizontal
            surface).
        work_angle: Tilt across the seam [rad], |angle| < π/2.
        travel_angle: Tilt along the seam [rad], |angle| < π/2, positive = push.
        roll: Turn about the torch axis [rad].
    """

    def __init__(
        self,
        path: Path,
        normal: ArrayLike = (0.0, 0.0, 1.0),
        work_angle: float = 0.0,
        travel_angle: float = 0.0,
        roll: float = 0.0,
    ) -> None:
        if not isinstance(path, Path):
            raise InputError(f"TorchOrientation needs a seam path, got {checks.describe(path)}")
        if path.length <= 0:
            raise InputError("TorchOrientation needs a seam of non-zero length")
        n = checks.vector(normal, "normal", 3)
        if np.linalg.norm(n) < 1e-9:
            raise InputError(f"normal must be a non-zero 3-vector, got {n.tolist()}")
        self.normal = n / np.linalg.norm(n)
        angles = {"work_angle": work_angle, "travel_angle": travel_angle}
        for name, value in angles.items():
            angle = checks.number(value, name, unit="rad")
            if abs(angle) >= 0.5 * np.pi:
                raise InputError(
                    f"{name} must be within ±90° (±π/2 rad) of the surface normal, got "
                    f"{np.degrees(angle):.1f}°"
                )
        self.work_angle = float(work_angle)
        self.travel_angle = float(travel_angle)
        self.roll = checks.number(roll, "roll", unit="rad")
        self.path = path
        self.length = path.length
        self.has_orientation = True
        self._fd_step = path._fd_step
        grid = np.linspace(0.0, 1.0, 65)
        rotations = self._rotation(grid)  # checks the tangents along the whole seam
        straight = np.max(np.abs(rotations - rotations[0])) < 1e-12
        self.slerp = Slerp(rotations[0], rotations[0]) if straight else None

    def __repr__(self) -> str:
        angles = (np.degrees(a) for a in (self.work_angle, self.travel_angle, self.roll))
        return "TorchOrientation({!r}, work {:.1f}°, travel {:.1f}°, roll {:.1f}°)".format(
            self.path, *angles
        )

    def position(self, s: ArrayLike) -> np.ndarray:
        return self.path.position(s)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self.path.position_derivatives(s)

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        if self.slerp is not None:
            return self.slerp(s)
        tangents, _ = self.path.position_derivatives(as_fractions(s))
        return torch_rotations(tangents, self.normal, self.work_angle, self.travel_angle, self.roll)
