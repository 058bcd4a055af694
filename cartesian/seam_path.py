"""A seam with the torch turned about its axis (roll) and tilted within its tolerance bands.

The seam's own path gives the tool position and the torch axis (tool z); :class:`SeamPath`
rotates its poses by smooth laws of the path fraction s:

* **roll** ρ(s) [rad]: a turn about the torch axis, relative to the path's poses;
* **work** w(s) and **travel** τ(s) [rad]: tilts of the torch axis across and along the seam.

Frames: at s the seam frame is F = [x, y, z], z the path's torch axis (its tool z), x the seam's
travel direction made perpendicular to z, y = z × x (the side a positive work angle tilts toward,
as :mod:`cartesian.torch`). The tool rotation is R'(s) = F Rx(w) Ry(τ) Fᵀ · R(s) · Rz(ρ): the
torch axis becomes F (sin τ, −sin w cos τ, cos w cos τ), and the roll turns the tool about it.
All in the robot's base (world) frame.

:class:`SmoothLaw` is the law of one such angle: a C² cubic spline through (or, for noisy values,
near) values at waypoints, so the angle's rate is continuous along the seam.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import (  # type: ignore[import-untyped]
    BSpline,
    make_interp_spline,
    make_lsq_spline,
)

from cartesian.paths import Path, as_fractions
from kinplan.ik.batch import log3

__all__ = [
    "CachedPath",
    "SeamPath",
    "SmoothLaw",
    "seam_frames",
    "tilt_rotations",
    "torch_deviation",
]


class SmoothLaw:
    """A smooth angle law θ(s) over the path fraction s ∈ [0, 1] [rad].

    Built from values at waypoints: a cubic least-squares spline with a knot every
    ``knot_every`` waypoints (a grid search's values come in steps of the grid: the law passes
    near them with a continuous rate instead of through every step), or the interpolating
    cubic when there are too few waypoints; a constant when every value is the same.

    Args:
        s: Waypoint fractions, increasing, from 0 to 1, shape (K,).
        values: The angle at each waypoint [rad], shape (K,) (unwrapped: no 2π jumps).
        knot_every: Waypoints per spline interval (≥ 1; 1 interpolates).
    """

    def __init__(self, s: ArrayLike, values: ArrayLike, knot_every: int = 3) -> None:
        s = np.asarray(s, dtype=float)
        values = np.asarray(values, dtype=float)
        assert isinstance(s, np.ndarray) and isinstance(values, np.ndarray)
        self.constant: float | None = None
        self.spline: BSpline | None = None
        self.offset = 0.0  # the anchor's correction δ·(1 − s)³ (see anchor)
        if len(values) == 0 or np.ptp(values) == 0.0:
            self.constant = float(values[0]) if len(values) else 0.0
            return
        if len(s) < 4:
            self.spline = make_interp_spline(s, values, k=min(3, len(s) - 1))
            return
        intervals = max(1, (len(s) - 1) // max(1, knot_every))
        if intervals >= len(s) - 1:
            self.spline = make_interp_spline(s, values, k=3)
            return
        inner = np.quantile(s, np.linspace(0.0, 1.0, intervals + 1)[1:-1])
        knots = np.concatenate(([s[0]] * 4, inner, [s[-1]] * 4))
        self.spline = make_lsq_spline(s, values, knots, k=3)

    @classmethod
    def fixed(cls, value: float) -> SmoothLaw:
        """The constant law θ(s) = ``value`` [rad]."""
        return cls([0.0, 1.0], [value, value])

    def __call__(self, s: ArrayLike, order: int = 0) -> np.ndarray:
        """θ (order 0), dθ/ds (1) or d²θ/ds² (2) at fractions ``s`` (clipped to [0, 1])."""
        x = np.clip(as_fractions(s), 0.0, 1.0)
        if self.spline is None:
            value = np.full(len(x), self.constant if order == 0 else 0.0)
        else:
            value = np.asarray(self.spline(x, nu=order), dtype=float)
        if self.offset:
            u = 1.0 - x
            value = value + self.offset * (u**3, -3.0 * u**2, 6.0 * u)[order]
        return value

    def anchor(self, value: float) -> None:
        """Make θ(0) = ``value`` exactly by adding δ·(1 − s)³ (a smooth correction that fades
        along the seam), δ = value − θ(0)."""
        self.offset = 0.0
        delta = float(value) - float(self(np.zeros(1))[0])
        if delta and self.spline is None and self.constant is not None:
            self.constant, delta = float(value), 0.0
        self.offset = delta

    @property
    def is_constant(self) -> bool:
        """Whether θ is one value along the whole seam."""
        return self.spline is None and not self.offset

    def scaled_into(self, bound: float, start: float | None = None) -> None:
        """Keep |θ| ≤ ``bound`` on a fine grid (a least-squares spline may overshoot the values
        it was fitted to) by scaling the spline, with θ(0) = ``start`` (|start| ≤ bound) kept
        exactly when given (:meth:`anchor` after each scaling)."""
        if start is not None:
            self.anchor(start)
        if self.spline is None:
            if self.constant is not None and abs(self.constant) > bound:
                self.constant = float(np.sign(self.constant) * bound)
            return
        if bound == 0.0:
            self.spline, self.constant, self.offset = None, 0.0, 0.0
            return
        fine = np.linspace(0.0, 1.0, 2001)
        for _ in range(12):
            peak = float(np.abs(self(fine)).max())
            if peak <= bound:
                return
            factor = bound / peak * (1.0 - 1e-6)
            self.spline = BSpline(self.spline.t, self.spline.c * factor, self.spline.k)
            if start is not None:
                self.anchor(start)


def _rz(angles: np.ndarray) -> np.ndarray:
    c, s = np.cos(angles), np.sin(angles)
    out = np.zeros((len(angles), 3, 3))
    out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1], out[:, 2, 2] = c, -s, s, c, 1.0
    return out


def seam_frames(path: Path, s: np.ndarray, rotations: np.ndarray | None = None) -> np.ndarray:
    """Seam frames F = [x, y, z] (N, 3, 3) at fractions ``s``: z the path's torch axis, x the
    travel direction made perpendicular to z (the tool x where the seam runs along the torch
    axis), y = z × x; world frame."""
    R = path.rotation(s) if rotations is None else rotations
    assert R is not None  # an oriented path
    z = R[:, :, 2]
    tangent, _ = path.position_derivatives(s)
    x = tangent - np.sum(tangent * z, axis=1)[:, None] * z
    norm = np.linalg.norm(x, axis=1)
    scale = np.linalg.norm(tangent, axis=1)
    degenerate = norm <= 1e-9 * np.maximum(scale, 1e-300)
    x = np.where(degenerate[:, None], R[:, :, 0], x / np.where(degenerate, 1.0, norm)[:, None])
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=2)


def tilt_rotations(frames: np.ndarray, work: np.ndarray, travel: np.ndarray) -> np.ndarray:
    """World-frame rotations F Rx(work) Ry(travel) Fᵀ (N, 3, 3) that tilt a torch axis along
    the frames' z by ``work`` (about x, across the seam) and ``travel`` (about y, along it)."""
    cw, sw, ct, st = np.cos(work), np.sin(work), np.cos(travel), np.sin(travel)
    local = np.zeros((len(work), 3, 3))
    # Rx(w) Ry(τ)
    local[:, 0, 0], local[:, 0, 2] = ct, st
    local[:, 1, 0], local[:, 1, 1], local[:, 1, 2] = sw * st, cw, -sw * ct
    local[:, 2, 0], local[:, 2, 1], local[:, 2, 2] = -cw * st, sw, cw * ct
    return frames @ local @ np.swapaxes(frames, 1, 2)


def torch_deviation(frames: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """(work, travel) angles [rad] (N, 2) of torch axes ``axes`` (N, 3, world) in the seam
    frames ``frames``: the inverse of :func:`tilt_rotations` applied to the frames' z."""
    local = np.einsum("nji,nj->ni", frames, axes)
    travel = np.arcsin(np.clip(local[:, 0], -1.0, 1.0))
    work = np.arctan2(-local[:, 1], local[:, 2])
    return np.stack([work, travel], axis=1)


class CachedPath(Path):
    """The seam's own path, evaluated once per array of fractions: a planner tracks several
    rotated copies of it on the same grids. Angular rates of a path that takes them from
    differences of its rotations (the base class's) are taken from the same differences,
    vectorised (:func:`kinplan.batch_ik.log3`).

    Args:
        path: An oriented path.
        size: How many fraction arrays are remembered.
    """

    def __init__(self, path: Path, size: int = 24) -> None:
        self.path = path
        self.length = path.length
        self.has_orientation = path.has_orientation
        self._fd_step = path._fd_step
        self.slerp = path.slerp
        self._size = size
        self._cache: dict[tuple[str, bytes], Any] = {}

    def __repr__(self) -> str:
        return repr(self.path)

    def _memo(self, name: str, s: np.ndarray, compute: Callable[[np.ndarray], Any]) -> Any:
        key = (name, s.tobytes())
        found = self._cache.get(key)
        if found is None:
            if len(self._cache) >= self._size:
                self._cache.pop(next(iter(self._cache)))
            found = self._cache[key] = compute(s)
        return found

    def position(self, s: ArrayLike) -> np.ndarray:
        return self._memo("p", as_fractions(s), self.path.position)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self._memo("dp", as_fractions(s), self.path.position_derivatives)

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        return self._memo("R", s, self.path._rotation)

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self._memo("w", as_fractions(s), self._rates)

    def _rates(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.slerp is not None or type(self.path).angular_rates is not Path.angular_rates:
            return self.path.angular_rates(s)
        s = s.clip(0.0, 1.0)  # Path.angular_rates' central differences, vectorised
        h = self._fd_step
        lo, hi = np.clip(s - h, 0, 1), np.clip(s + h, 0, 1)
        mid = 0.5 * (lo + hi)
        r_lo, r_mid, r_hi = (self.path._rotation(x) for x in (lo, mid, hi))
        half = (0.5 * (hi - lo))[:, None]
        w_lo = log3(r_mid @ np.swapaxes(r_lo, 1, 2)) / half
        w_hi = log3(r_hi @ np.swapaxes(r_mid, 1, 2)) / half
        return 0.5 * (w_lo + w_hi), (w_hi - w_lo) / half


class SeamPath(Path):
    """The seam ``path`` with the torch rolled by ``roll`` and tilted by ``work`` / ``travel``.

    Positions are the seam's; rotations R'(s) = F Rx(w) Ry(τ) Fᵀ R(s) Rz(ρ) (module docstring).
    Without tilt the angular rates are exact: ω' = ω + ρ' z, dω'/ds = dω/ds + ρ'' z + ρ' ω × z
    (z the torch axis, ω the seam's rate [rad per unit s]); with tilt they come from central
    differences, as for any path with a rotation function.

    Args:
        path: The seam, with orientation (tool z = torch axis).
        roll: Law of the roll about the torch axis [rad].
        work: Law of the work-angle deviation [rad], or None (0).
        travel: Law of the travel-angle deviation [rad], or None (0).
    """

    def __init__(
        self,
        path: Path,
        roll: SmoothLaw,
        work: SmoothLaw | None = None,
        travel: SmoothLaw | None = None,
    ) -> None:
        self.path = path
        self.roll = roll
        self.work = work if work is not None else SmoothLaw.fixed(0.0)
        self.travel = travel if travel is not None else SmoothLaw.fixed(0.0)
        self.tilted = not (
            self.work.is_constant
            and self.travel.is_constant
            and self.work.constant == 0.0
            and self.travel.constant == 0.0
        )
        self.length = path.length
        self.has_orientation = True
        self._fd_step = path._fd_step

    def __repr__(self) -> str:
        return f"SeamPath({self.path!r})"

    def position(self, s: ArrayLike) -> np.ndarray:
        return self.path.position(s)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self.path.position_derivatives(s)

    def tilt(self, s: ArrayLike) -> np.ndarray:
        """(work, travel) deviations [rad] at fractions ``s``, shape (N, 2)."""
        return np.stack([self.work(s), self.travel(s)], axis=1)

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        base = self.path.rotation(s)
        assert base is not None  # plan_seam checks the seam has an orientation
        rotated = base @ _rz(self.roll(s))
        if not self.tilted:
            return rotated
        frames = seam_frames(self.path, s, base)
        return tilt_rotations(frames, self.work(s), self.travel(s)) @ rotated

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        if self.tilted:
            return super().angular_rates(s)
        s = np.clip(as_fractions(s), 0.0, 1.0)
        base = self.path.rotation(s)
        assert base is not None
        z = base[:, :, 2]
        omega, omega_rate = self.path.angular_rates(s)
        rate, curvature = self.roll(s, 1)[:, None], self.roll(s, 2)[:, None]
        return omega + rate * z, omega_rate + curvature * z + rate * np.cross(omega, z)
