"""Synthetic spherical-wrist 6R arms whose axes 2 and 3 are not parallel, written as URDF
strings, for the tests of kinplan.ik.spherical_general: random axes (not perpendicular),
offsets, link frames, base and tool frames; axes 1 and 2 meeting, axes 2 and 3 meeting, or
neither. Every machine has them, no download needed."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

#: The position modes of :func:`general_arm_urdf`.
MODES = ("12", "23", "general")


def _xyz(values) -> str:
    return " ".join(f"{x:.17g}" for x in values)


def _unit(rng: np.random.Generator, away: tuple[np.ndarray, ...] = ()) -> np.ndarray:
    """A random unit vector at least asin(0.3) from each of ``away`` (and their opposites)."""
    while True:
        v = rng.normal(size=3)
        v /= np.linalg.norm(v)
        if all(np.linalg.norm(np.cross(v, a)) >= 0.3 for a in away):
            return v


def _across(rng: np.random.Generator, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The unit common normal of directions a and b, with a random sign."""
    n = np.cross(a, b)
    return rng.choice([-1.0, 1.0]) * n / np.linalg.norm(n)


def _turned(a: np.ndarray, b: np.ndarray, angle: float) -> np.ndarray:
    """The unit vector at ``angle`` [rad] from a, in the plane of a and b (towards b)."""
    across = b - (b @ a) * a
    return np.cos(angle) * a + np.sin(angle) * across / np.linalg.norm(across)


def general_arm_axes(
    seed: int,
    mode: str,
    *,
    gap: float | None = None,
    near: float = 0.0,
    angle12: float | None = None,
    angle23: float | None = None,
    parallel12: bool = False,
    parallel23: bool = False,
    wrist_offset: float = 0.0,
    centre_on_axis3: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The arm at q = 0 in the world frame: (axes (6, 3), points (6, 3) [m], tool position
    [m], tool rotation).

    ``mode``: "12" (axes 1 and 2 meet), "23" (axes 2 and 3 meet) or "general" (axes 1, 2 and
    axes 2, 3 apart by ``gap`` [m], random 0.05–0.3 m by default); ``near`` [m] moves the
    meeting axes of modes "12" and "23" that far apart (nearly meeting); ``angle12``,
    ``angle23`` [rad] set the angle between axes 1, 2 or 2, 3 (random, ≥ 0.3 rad otherwise).
    Variants outside the family: ``parallel12`` (axis 2 ∥ axis 1), ``parallel23`` (axis 3 ∥ axis 2),
    ``wrist_offset`` [m] (axis 6 moved off the wrist centre), ``centre_on_axis3`` (the wrist
    centre on axis 3).
    """
    rng = np.random.default_rng([seed, MODES.index(mode)])
    h1 = _unit(rng)
    p1 = np.array([*rng.uniform(-0.2, 0.2, 2), rng.uniform(0.1, 0.6)])  # [m], as all below
    h2 = h1.copy() if parallel12 else _unit(rng, (h1,))
    if angle12 is not None:
        h2 = _turned(h1, h2, angle12)
    p2 = p1 + rng.uniform(0.1, 0.5) * h1
    if mode == "12" and near:
        p2 = p2 + near * _across(np.random.default_rng([seed, 7]), h1, h2)
    if mode != "12":
        if parallel12:
            across = np.cross(h1, _unit(rng, (h1,)))
            across /= np.linalg.norm(across)
        else:
            across = _across(rng, h1, h2)
        p2 = p2 + (gap if gap is not None else rng.uniform(0.05, 0.3)) * across
    h3 = h2.copy() if parallel23 else _unit(rng, (h2,))
    if angle23 is not None:
        h3 = _turned(h2, h3, angle23)
    if mode == "23":
        p3 = p2 + rng.uniform(0.2, 0.8) * h2 * rng.choice([-1.0, 1.0])
        if near:
            p3 = p3 + near * _across(np.random.default_rng([seed, 7]), h2, h3)
    else:
        side = np.cross(h2, _unit(rng, (h2,)) if parallel23 else h3)  # across axes 2, 3
        along = rng.uniform(-0.2, 0.2) * h2 + rng.uniform(0.2, 0.8) * side / np.linalg.norm(side)
        p3 = p2 + along
        if mode == "general" and not parallel23:
            n23 = _across(rng, h2, h3)
            apart = gap if gap is not None else rng.uniform(0.05, 0.3)
            p3 = p3 - (p3 - p2) @ n23 * n23 + apart * n23
    forearm = rng.normal(size=3)
    forearm *= rng.uniform(0.3, 1.0) / np.linalg.norm(forearm)
    centre = p3 + forearm
    if centre_on_axis3:
        centre = p3 + rng.uniform(0.3, 1.0) * h3
    h4 = _unit(rng)
    h5 = _unit(rng, (h4,))
    h6 = _unit(rng, (h5,))
    p4 = centre - rng.uniform(0.0, 0.3) * h4
    p5 = centre + rng.uniform(-0.1, 0.1) * h5
    p6 = centre + rng.uniform(0.0, 0.2) * h6
    if wrist_offset:
        p6 = p6 + wrist_offset * _across(rng, h6, _unit(rng, (h6,)))
    tool_position = centre + rng.uniform(0.05, 0.3) * h6 + rng.uniform(-0.05, 0.05, 3)
    tool_rotation = pin.exp3(rng.normal(size=3))
    axes = np.array([h1, h2, h3, h4, h5, h6]) * rng.choice([-1.0, 1.0], size=(6, 1))
    return axes, np.array([p1, p2, p3, p4, p5, p6]), tool_position, tool_rotation


def general_arm_urdf(seed: int, mode: str, **variants) -> str:
    """The arm of :func:`general_arm_axes` as a URDF string: a random base frame, a random
    rotation of every link frame (so the axes are written in rotated frames), joint limits
    ±(0.75π … 2π) and a tool frame ``tool0``."""
    axes, points, tool_position, tool_rotation = general_arm_axes(seed, mode, **variants)
    rng = np.random.default_rng([seed, MODES.index(mode), 1])
    base = pin.SE3(pin.exp3(rng.normal(size=3) * 0.3), rng.uniform(-0.5, 0.5, 3))
    frames = [base]  # world frames of base, l1 … l6 at q = 0
    for point in points:
        frames.append(pin.SE3(pin.exp3(rng.normal(size=3)), point))
    limits = rng.uniform(0.75 * np.pi, 2.0 * np.pi, 6)
    links = ["world", "base", "l1", "l2", "l3", "l4", "l5", "l6", "tool0"]
    parts = ['<?xml version="1.0"?>', f'<robot name="general_wrist_{mode}_{seed}">']
    parts += [f'  <link name="{name}"/>' for name in links]

    def origin(parent: pin.SE3, child: pin.SE3) -> str:
        relative = parent.actInv(child)
        rpy = pin.rpy.matrixToRpy(relative.rotation)
        return f'<origin xyz="{_xyz(relative.translation)}" rpy="{_xyz(rpy)}"/>'

    parts.append(
        '  <joint name="base_fixed" type="fixed"><parent link="world"/><child link="base"/>'
        f"{origin(pin.SE3.Identity(), base)}</joint>"
    )
    for i in range(6):
        axis = frames[i + 1].rotation.T @ axes[i]
        parts.append(
            f'  <joint name="j{i + 1}" type="revolute"><parent link="{links[i + 1]}"/>'
            f'<child link="{links[i + 2]}"/>{origin(frames[i], frames[i + 1])}'
            f'<axis xyz="{_xyz(axis)}"/>'
            f'<limit lower="{-limits[i]:.17g}" upper="{limits[i]:.17g}" effort="1" '
            'velocity="3"/></joint>'
        )
    tool = pin.SE3(tool_rotation, tool_position)
    parts.append(
        '  <joint name="tool_fixed" type="fixed"><parent link="l6"/><child link="tool0"/>'
        f"{origin(frames[6], tool)}</joint>"
    )
    parts.append("</robot>")
    return "\n".join(parts)
