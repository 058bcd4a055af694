"""An independent model of how a Universal Robots controller moves through native commands.

Written from the URScript manual's description of each command, not from kinplan's planners,
so that a native program can be checked before it is written (:mod:`kinplan.export.native`):

* ``movej(q, a, v)``: linear in joint space; the leading axis (the joint with the largest
  travel) follows a trapezoid at joint speed ``v`` [rad/s] and acceleration ``a`` [rad/s²]
  (a triangle when it cannot reach ``v``), the others scaled to start and stop with it.
* ``movel(pose, a, v)``: linear in tool space; the TCP position on the straight line, its
  orientation turning about one axis (slerp), the path length timed by a trapezoid at tool
  speed ``v`` [m/s] and acceleration ``a`` [m/s²].
* ``movec(pose_via, pose_to, a, v, mode=0)``: the circle through the current TCP position,
  the via position and the target, timed as ``movel``; the orientation turns from the start
  to the target's (mode 0, "unconstrained": the via pose's orientation is not used).
* ``movep(pose, a, v, r)`` chains: straight lines between the waypoints at constant tool speed
  ``v``, each corner blended within ``r`` [m]: the TCP leaves the line where it comes within
  ``r`` of the waypoint and joins the next ``r`` after it, on the circular arc tangent to both
  lines there (the manual: "blend circular (in tool-space) and move linear (in tool-space)");
  the chain accelerates from rest at its start and stops at its last waypoint (``r = 0``).
  Blends must not overlap: ``r`` is at most half of each neighbouring segment.

Times in seconds, positions in metres, angles in radians; poses in the robot's world frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

__all__ = [
    "ToolTrack",
    "arc_track",
    "blended_track",
    "line_track",
    "movej_samples",
    "trapezoid_law",
]

_STRAIGHT = 1e-9
"""Turning angle below which a corner is straight [rad]."""


def trapezoid_law(length: float, v: float, a: float, t: np.ndarray | None = None,
                  step: float = 0.004) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The controller's rest-to-rest trapezoid over a distance.

    Args:
        length: Distance [m or rad], ≥ 0.
        v: Cruise speed [per s], > 0.
        a: Acceleration and deceleration [per s²], > 0.
        t: Times to evaluate [s], or None: a grid of ``step`` ending exactly at the end.
        step: Grid step [s] when ``t`` is None.

    Returns:
        (t [s], s: the distance travelled at each time).
    """
    if length <= 0.0:
        times = np.zeros(1) if t is None else np.asarray(t, dtype=float)
        return times, np.zeros_like(times)
    ramp = v / a
    if a * ramp * ramp >= length:  # never reaches v: a triangle
        ramp = math.sqrt(length / a)
        v = a * ramp
    cruise = (length - a * ramp * ramp) / v
    total = 2.0 * ramp + cruise
    if t is None:
        count = max(2, math.ceil(total / step) + 1)
        t = np.linspace(0.0, total, count)
    times = np.clip(np.asarray(t, dtype=float), 0.0, total)
    s = np.where(
        times < ramp,
        0.5 * a * times**2,
        np.where(
            times < ramp + cruise,
            0.5 * a * ramp**2 + v * (times - ramp),
            length - 0.5 * a * (total - times) ** 2,
        ),
    )
    return np.asarray(t, dtype=float), np.minimum(s, length)


def movej_samples(q0: np.ndarray, q1: np.ndarray, v: float, a: float,
                  step: float = 0.004) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """``movej``: joint-linear, the leading axis on the trapezoid (``v`` [rad/s], ``a`` [rad/s²]).

    Returns:
        (t [s], q [rad]: shape (K, nq)).
    """
    delta = np.asarray(q1, dtype=float) - np.asarray(q0, dtype=float)
    lead = float(np.max(np.abs(delta)))
    t, s = trapezoid_law(lead, v, a, step=step)
    share = s / lead if lead > 0 else np.ones_like(s)
    return t, np.asarray(q0, dtype=float) + share[:, None] * delta[None, :]


@dataclass
class ToolTrack:
    """A TCP motion of the controller: sampled poses and their times.

    Attributes:
        t: Times from the command's start [s], shape (K,).
        positions: TCP positions [m], shape (K, 3).
        rotations: TCP rotations, shape (K, 3, 3).
        length: Path length [m].
    """

    t: np.ndarray
    positions: np.ndarray
    rotations: np.ndarray
    length: float

    def poses(self) -> list[pin.SE3]:
        """The samples as poses."""
        return [pin.SE3(r, p) for r, p in zip(self.rotations, self.positions, strict=True)]


def _slerp(r0: np.ndarray, r1: np.ndarray, share: np.ndarray) -> np.ndarray:
    """Rotations turning from ``r0`` to ``r1`` about one axis, at path shares 0..1."""
    log = pin.log3(r0.T @ r1)
    return np.array([r0 @ pin.exp3(log * u) for u in share])


def line_track(start: pin.SE3, end: pin.SE3, v: float, a: float, step: float) -> ToolTrack:
    """``movel`` from ``start`` to ``end``: a straight line, slerped orientation, trapezoid."""
    chord = end.translation - start.translation
    length = float(np.linalg.norm(chord))
    t, s = trapezoid_law(length, v, a, step=step)
    share = s / length if length > 0 else np.ones_like(s)
    positions = start.translation + share[:, None] * chord[None, :]
    return ToolTrack(t, positions, _slerp(start.rotation, end.rotation, share), length)


def arc_track(start: pin.SE3, via: np.ndarray, end: pin.SE3, v: float, a: float,
              step: float) -> ToolTrack:  # fmt: skip
    """``movec`` (mode 0) from ``start`` through the ``via`` position to ``end``."""
    p0, p1, p2 = start.translation, np.asarray(via, dtype=float), end.translation
    u, w = p1 - p0, p2 - p0
    cross = np.cross(u, w)
    area = float(np.dot(cross, cross))
    if area < 1e-24:
        raise ValueError("the three points of the arc are on one line")
    # the circumcentre of the triangle p0, p1, p2
    centre = p0 + (np.dot(u, u) * np.cross(w, cross) + np.dot(w, w) * np.cross(cross, u)) / (
        2.0 * area
    )
    normal = cross / math.sqrt(area)
    radius = float(np.linalg.norm(p0 - centre))
    x = (p0 - centre) / radius
    y = np.cross(normal, x)

    def angle_of(p: np.ndarray) -> float:
        d = p - centre
        return math.atan2(float(np.dot(d, y)), float(np.dot(d, x))) % (2.0 * math.pi)

    sweep = angle_of(p2)
    if angle_of(p1) > sweep:  # the via point is on the other side: the long way round
        sweep -= 2.0 * math.pi
    length = abs(sweep) * radius
    t, s = trapezoid_law(length, v, a, step=step)
    angle = sweep * (s / length)
    positions = centre + radius * (np.cos(angle)[:, None] * x + np.sin(angle)[:, None] * y)
    rotations = _slerp(start.rotation, end.rotation, s / length)
    return ToolTrack(t, positions, rotations, length)


def blended_track(start: pin.SE3, waypoints: list[np.ndarray], radii: list[float],
                  rotation: np.ndarray, v: float, a: float,
                  step: float) -> ToolTrack:  # fmt: skip
    """A ``movep`` chain from ``start`` through ``waypoints`` (positions [m]), corner ``k``
    (at ``waypoints[k]``, k < last) blended on the circular arc that leaves and joins the lines
    ``radii[k]`` from it; constant orientation ``rotation``; one trapezoid over the whole path.

    Raises:
        ValueError: a blend longer than half of a neighbouring segment, or repeated waypoints.
    """
    corners = [np.asarray(start.translation, dtype=float)] + [np.asarray(p) for p in waypoints]
    pieces: list[tuple[str, tuple]] = []  # ("line", (p, q)) or ("arc", (centre, x, y, R, phi))
    here = corners[0]
    for k in range(1, len(corners)):
        p, nxt = corners[k], corners[k + 1] if k + 1 < len(corners) else None
        r = radii[k - 1] if nxt is not None else 0.0
        incoming = p - corners[k - 1]
        if np.linalg.norm(incoming) < 1e-12:
            raise ValueError(f"waypoint {k} repeats the one before it")
        if nxt is None or r <= 0.0:
            pieces.append(("line", (here, p)))
            here = p
            continue
        outgoing = nxt - p
        for side, segment in (("before", incoming), ("after", outgoing)):
            if r > 0.5 * float(np.linalg.norm(segment)) + 1e-12:
                raise ValueError(
                    f"the blend radius {r:g} m at waypoint {k} is more than half the segment "
                    f"{side} it ({float(np.linalg.norm(segment)):.4g} m): blends would overlap"
                )
        u1, u2 = incoming / np.linalg.norm(incoming), outgoing / np.linalg.norm(outgoing)
        enter, leave = p - r * u1, p + r * u2
        pieces.append(("line", (here, enter)))
        phi = math.acos(float(np.clip(np.dot(u1, u2), -1.0, 1.0)))
        if phi < _STRAIGHT:
            pieces.append(("line", (enter, leave)))
        else:
            radius = r / math.tan(0.5 * phi)
            towards = u2 - np.dot(u2, u1) * u1
            towards /= np.linalg.norm(towards)
            centre = enter + radius * towards
            pieces.append(("arc", (centre, (enter - centre) / radius, u1, radius, phi)))
        here = leave
    lengths = []
    for kind, data in pieces:
        lengths.append(
            float(np.linalg.norm(data[1] - data[0])) if kind == "line" else data[3] * data[4]
        )
    total = float(sum(lengths))
    t, s = trapezoid_law(total, v, a, step=step)
    ends = np.cumsum(lengths)
    positions = np.empty((len(s), 3))
    for i, d in enumerate(s):
        k = min(int(np.searchsorted(ends, d)), len(pieces) - 1)
        local = d - (ends[k] - lengths[k])
        kind, data = pieces[k]
        if kind == "line":
            share = local / lengths[k] if lengths[k] > 0 else 1.0
            positions[i] = data[0] + share * (data[1] - data[0])
        else:
            centre, x, y, radius, _ = data
            angle = local / radius
            positions[i] = centre + radius * (math.cos(angle) * x + math.sin(angle) * y)
    rotations = np.repeat(np.asarray(rotation, dtype=float)[None], len(s), axis=0)
    return ToolTrack(t, positions, rotations, total)
