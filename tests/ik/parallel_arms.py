"""Synthetic 6R arms with three parallel axes 2 ∥ 3 ∥ 4 and generic axes 1, 5, 6, written as URDF
strings (random axis directions, offsets, axis signs, base and tool frames), and UR5 variants
with a skewed wrist, for the tests of the three-parallel-axes closed form
(:mod:`kinplan.ik.three_parallel`): every machine has them, no download needed."""

from __future__ import annotations

import re

import numpy as np

#: Smallest angle [rad] between axis 2 and axes 1, 5 of :func:`parallel_arm_urdf` (20°).
SPREAD = np.radians(20.0)


def _xyz(values) -> str:
    return " ".join(f"{x:.17g}" for x in values)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _away_from(rng: np.random.Generator, a: np.ndarray) -> np.ndarray:
    """A random unit vector at least :data:`SPREAD` from ±a (not perpendicular to it, mostly)."""
    while True:
        v = _unit(rng.normal(size=3))
        if np.linalg.norm(np.cross(v, a)) >= np.sin(SPREAD):
            return v


def _across(rng: np.random.Generator, a: np.ndarray, low: float, high: float) -> np.ndarray:
    """A random vector normal to the unit ``a`` of length in [low, high] [m]."""
    v = rng.normal(size=3)
    v -= (v @ a) * a
    return _unit(v) * rng.uniform(low, high)


def parallel_arm_urdf(seed: int) -> str:
    """A 6R arm with axes 2 ∥ 3 ∥ 4 (random direction a, axes 3, 4 along ±a) and axes 1, 5, 6
    in random directions (axes 1, 5 at least 20° from a; none perpendicular or meeting by
    construction), with random offsets: axis 1 → 2 (0.05–0.3 m), the links 2 → 3 and 3 → 4
    (0.3–0.9 m and 0.25–0.8 m across a, ±0.15 m along it), axis 4 → 5 and 5 → 6 (random
    directions, 0.05–0.25 m), a random tool offset and rotation, a random base pose. Joint
    frames keep the orientation of the arm frame (rpy 0) and each axis is written in it.
    Limits: ±(π/2 … 2π) per joint.
    """
    rng = np.random.default_rng([seed, 2343])
    a = _unit(rng.normal(size=3))
    sign = lambda: rng.choice([-1.0, 1.0])  # noqa: E731
    axes = [_away_from(rng, a), a * sign(), a * sign(), a * sign(), _away_from(rng, a),
            _unit(rng.normal(size=3))]  # fmt: skip
    offsets = [
        np.array([0.0, 0.0, rng.uniform(0.1, 0.6)]),
        _unit(rng.normal(size=3)) * rng.uniform(0.05, 0.3),
        _across(rng, a, 0.3, 0.9) + a * rng.uniform(-0.15, 0.15),
        _across(rng, a, 0.25, 0.8) + a * rng.uniform(-0.15, 0.15),
        _unit(rng.normal(size=3)) * rng.uniform(0.05, 0.25),
        _unit(rng.normal(size=3)) * rng.uniform(0.05, 0.25),
    ]
    limits = rng.uniform(0.5 * np.pi, 2.0 * np.pi, 6)
    links = ["world", "base", "l1", "l2", "l3", "l4", "l5", "l6", "tool0"]
    parts = ['<?xml version="1.0"?>', f'<robot name="parallel_arm_{seed}">']
    parts += [f'  <link name="{name}"/>' for name in links]
    parts.append(
        f'  <joint name="base_fixed" type="fixed"><parent link="world"/><child link="base"/>'
        f'<origin xyz="{_xyz(rng.uniform(-0.5, 0.5, 3))}" '
        f'rpy="{_xyz(rng.uniform(-np.pi, np.pi, 3))}"/></joint>'
    )
    for j, (axis, offset, limit) in enumerate(zip(axes, offsets, limits)):
        parent, child = links[j + 1], links[j + 2]
        parts.append(
            f'  <joint name="j{j + 1}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{_xyz(offset)}" rpy="0 0 0"/>'
            f'<axis xyz="{_xyz(axis)}"/>'
            f'<limit lower="{-limit:.17g}" upper="{limit:.17g}" effort="1" velocity="3"/></joint>'
        )
    parts.append(
        f'  <joint name="tool_fixed" type="fixed"><parent link="l6"/><child link="tool0"/>'
        f'<origin xyz="{_xyz(rng.uniform(-0.15, 0.15, 3))}" '
        f'rpy="{_xyz(rng.uniform(-np.pi, np.pi, 3))}"/></joint>'
    )
    parts.append("</robot>")
    return "\n".join(parts)


#: UR5 edits that break the UR structure but keep axes 2 ∥ 3 ∥ 4: (joint, old, new) text.
SKEWED_UR5 = {
    # axis 5 turned 0.3 rad out of the plane normal to axis 4 (not ⊥ 4, not ⊥ 6)
    "axis5": [("wrist_2_joint", 'rpy="0.0 0.0 0.0"', 'rpy="0.3 0.0 0.0"')],
    # axis 6 tilted by 0.25 rad and moved 2 cm: axes 5 and 6 neither ⊥ nor meeting
    "axis6": [
        ("wrist_3_joint", 'rpy="0.0 0.0 0.0"', 'rpy="0.25 0.0 0.0"'),
        ("wrist_3_joint", 'xyz="0.0 0.0 0.09465"', 'xyz="0.02 0.0 0.09465"'),
    ],
    # axis 6 moved 2 cm across axes 5 and 6 (still ⊥ 5): the wrist singularity θ5 = 0 remains
    "miss": [("wrist_3_joint", 'xyz="0.0 0.0 0.09465"', 'xyz="0.02 0.0 0.09465"')],
}


def skewed_ur5_urdf(text: str, kind: str) -> str:
    """The UR5 URDF ``text`` with the edits ``SKEWED_UR5[kind]``."""
    for joint, old, new in SKEWED_UR5[kind]:
        pattern = rf'(<joint name="{joint}".*?){re.escape(old)}'
        text, count = re.subn(pattern, rf"\g<1>{new}", text, count=1, flags=re.S)
        assert count == 1, (joint, old)
    return text
