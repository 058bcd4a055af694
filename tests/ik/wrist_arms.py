"""Synthetic spherical-wrist 6R arms written as URDF strings (random offsets, axis signs, base
and tool frames), and their variants with axis 6 offset (the 1-D search family), for the
closed-form tests: every machine has them, no download needed."""

from __future__ import annotations

import numpy as np


def _rpy(rng: np.random.Generator, scale: float = np.pi) -> str:
    return " ".join(f"{x:.17g}" for x in rng.uniform(-scale, scale, 3))


def _xyz(values) -> str:
    return " ".join(f"{x:.17g}" for x in values)


def wrist_arm_urdf(
    seed: int,
    *,
    skew_wrist: bool = False,
    lateral: bool = True,
    tilt: float = 0.0,
    wrist_offset: float = 0.0,
    skew3: float = 0.0,
) -> str:
    """An industrial-style arm: axis 1 vertical, 2 ∥ 3 horizontal, a spherical wrist.

    Random: base pose, shoulder offset (along x and z), lateral offset along axis 2 (when
    ``lateral``), link 2 length and direction, elbow offset, forearm length, axis signs,
    tool pose; with ``skew_wrist`` the wrist axes are not perpendicular (still meeting); ``tilt``
    [rad] turns axes 2 and 3 (together) out of the plane normal to axis 1.
    Limits: ±(π/2 … 2π) per joint.

    The 1-D search family (:mod:`kinplan.ik.wrist_offset`): ``wrist_offset`` [m] moves axis 6
    off the meeting point of axes 4 and 5 by that distance (a random direction across axis 6);
    ``skew3`` [rad] turns axis 3 by that angle away from axis 2 (about axis 1's direction at
    q = 0) and puts axes 1 and 2 through one point (no shoulder or lateral offset), as Kinova's
    Gen3. Both draw from their own generator: the other numbers of a seed do not change.
    """
    rng = np.random.default_rng(seed)
    sign = lambda: rng.choice([-1.0, 1.0])  # noqa: E731
    d1 = rng.uniform(0.1, 0.8)
    a1 = rng.uniform(0.0, 0.4)
    lat = rng.uniform(-0.2, 0.2) if lateral else 0.0
    a2 = rng.uniform(0.2, 1.2)
    a3 = rng.uniform(-0.2, 0.2)
    d4 = rng.uniform(0.2, 1.2)
    d6 = rng.uniform(0.0, 0.3)
    axis5 = np.array([0.0, 1.0, 0.0])
    axis6 = np.array([1.0, 0.0, 0.0])
    if skew_wrist:
        axis5 = np.array([rng.uniform(-0.5, 0.5), 1.0, rng.uniform(-0.5, 0.5)])
        axis6 = np.array([1.0, rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5)])
    axis5, axis6 = sign() * axis5 / np.linalg.norm(axis5), sign() * axis6 / np.linalg.norm(axis6)
    if skew3:
        a1 = lat = 0.0
    joints = [
        ("j1", "base", "l1", [0, 0, d1], "0 0 0", [0, 0, sign()]),
        ("j2", "l1", "l2", [a1, lat, 0], f"{tilt:.17g} 0 0", [0, sign(), 0]),
        ("j3", "l2", "l3", [rng.uniform(-0.3, 0.3), 0, a2], "0 0 0", [0, sign(), 0]),
        ("j4", "l3", "l4", [0.1, 0, a3], "0 0 0", [sign(), 0, 0]),
        ("j5", "l4", "l5", [d4, 0, 0], "0 0 0", list(axis5)),
        ("j6", "l5", "l6", [0, 0, 0], "0 0 0", list(axis6)),
    ]
    if skew3:  # axis 3 turned about z (axis 1 at q = 0) away from axis 2
        name, parent, child, xyz, rpy, axis = joints[2]
        axis = [axis[1] * np.sin(skew3), axis[1] * np.cos(skew3), 0.0]
        joints[2] = (name, parent, child, xyz, rpy, axis)
    if wrist_offset:  # axis 6 moved across itself, off the meeting point of axes 4 and 5
        across = np.cross(axis6, np.random.default_rng([seed, 6]).normal(size=3))
        joints[5] = ("j6", "l5", "l6", list(wrist_offset * across / np.linalg.norm(across)),
                     "0 0 0", list(axis6))  # fmt: skip
    limits = rng.uniform(0.5 * np.pi, 2.0 * np.pi, 6)
    links = ["world", "base", "l1", "l2", "l3", "l4", "l5", "l6", "tool0"]
    parts = ['<?xml version="1.0"?>', f'<robot name="wrist_arm_{seed}">']
    parts += [f'  <link name="{name}"/>' for name in links]
    parts.append(
        f'  <joint name="base_fixed" type="fixed"><parent link="world"/><child link="base"/>'
        f'<origin xyz="{_xyz(rng.uniform(-0.5, 0.5, 3))}" rpy="{_rpy(rng, 0.3)}"/></joint>'
    )
    for (name, parent, child, xyz, rpy, axis), limit in zip(joints, limits):
        parts.append(
            f'  <joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{_xyz(xyz)}" rpy="{rpy}"/>'
            f'<axis xyz="{_xyz(axis)}"/>'
            f'<limit lower="{-limit:.17g}" upper="{limit:.17g}" effort="1" velocity="3"/></joint>'
        )
    tool = np.array(axis6) * d6 + rng.uniform(-0.05, 0.05, 3)
    parts.append(
        f'  <joint name="tool_fixed" type="fixed"><parent link="l6"/><child link="tool0"/>'
        f'<origin xyz="{_xyz(tool)}" rpy="{_rpy(rng)}"/></joint>'
    )
    parts.append("</robot>")
    return "\n".join(parts)
