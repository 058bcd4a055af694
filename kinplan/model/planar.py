"""Planar serial arms written as URDF: revolute joints about z, links along x.

:func:`planar_arm_urdf` writes the URDF text; :func:`kinplan.planar_arm` loads it through the same
path as any URDF file. The bundled ``robots/planar_2r.urdf`` is this function's output for
``lengths=[1, 1]`` (a test keeps the two identical).
"""

from __future__ import annotations

import hashlib
import math
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from kinplan.errors import InputError

DEFAULT_POSITION_LIMIT = math.pi  # [rad], symmetric
DEFAULT_VELOCITY_LIMIT = 2.0 * math.pi  # [rad/s]


def _per_joint(
    value: float | Sequence[float] | None, default: float, n: int, what: str
) -> np.ndarray:
    if value is None:
        return np.full(n, default)
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise InputError(f"{what} must be a finite number or {n} finite numbers, got {value!r}")
    return arr


def _fmt(x: float) -> str:
    return repr(float(x))


def planar_arm_urdf(
    lengths: Sequence[float] | np.ndarray,
    name: str = "planar_arm",
    lower: float | Sequence[float] | None = None,
    upper: float | Sequence[float] | None = None,
    velocity_limit: float | Sequence[float] | None = None,
) -> str:
    """URDF text of a planar arm with ``len(lengths)`` revolute joints about z.

    The base link ``base_link`` sits at the world origin; joint ``joint<k>`` (k = 1..n) is at the
    end of link k-1; the fixed frame ``tip`` is at the end of the last link. At q = 0 the arm is
    stretched along +x.

    Args:
        lengths: Link lengths [m], each > 0.
        name: Robot name written into the URDF.
        lower: Lower position limits [rad] (default −π).
        upper: Upper position limits [rad] (default +π).
        velocity_limit: Joint speed limits [rad/s] (default 2π).

    Raises:
        InputError: no link, a non-positive or non-finite length, inconsistent limits.
    """
    lengths_arr = np.asarray(lengths, dtype=float)
    if lengths_arr.ndim != 1 or lengths_arr.size == 0:
        raise InputError(f"planar_arm needs a list of link lengths [m], got {lengths!r}")
    if not np.all(np.isfinite(lengths_arr)) or np.any(lengths_arr <= 0):
        raise InputError(f"link lengths must be finite and > 0 m, got {list(lengths_arr)}")
    n = lengths_arr.size
    lo = _per_joint(lower, -DEFAULT_POSITION_LIMIT, n, "lower")
    hi = _per_joint(upper, DEFAULT_POSITION_LIMIT, n, "upper")
    vel = _per_joint(velocity_limit, DEFAULT_VELOCITY_LIMIT, n, "velocity_limit")
    if np.any(lo >= hi):
        raise InputError(f"every lower limit must be below its upper limit: {lo} vs {hi}")
    if np.any(vel <= 0):
        raise InputError(f"velocity limits must be > 0 rad/s, got {vel}")

    radius = 0.04 * float(lengths_arr.max())
    robot = ET.Element("robot", name=name)
    for material, rgba in (("link", "0.85 0.45 0.1 1"), ("joint", "0.2 0.2 0.25 1")):
        ET.SubElement(ET.SubElement(robot, "material", name=material), "color", rgba=rgba)

    def add_link(link_name: str, length: float | None) -> None:
        link = ET.SubElement(robot, "link", name=link_name)
        if length is None:
            return
        # Link body: a cylinder along +x from the joint to the next joint.
        visual = ET.SubElement(link, "visual")
        ET.SubElement(
            visual, "origin", xyz=f"{_fmt(length / 2)} 0 0", rpy=f"0 {_fmt(math.pi / 2)} 0"
        )
        geometry = ET.SubElement(visual, "geometry")
        ET.SubElement(geometry, "cylinder", radius=_fmt(radius), length=_fmt(length))
        ET.SubElement(visual, "material", name="link")
        # Joint housing: a short, wider cylinder about z at the joint.
        housing = ET.SubElement(link, "visual")
        ET.SubElement(housing, "origin", xyz="0 0 0", rpy="0 0 0")
        geometry = ET.SubElement(housing, "geometry")
        ET.SubElement(geometry, "cylinder", radius=_fmt(1.6 * radius), length=_fmt(3 * radius))
        ET.SubElement(housing, "material", name="joint")

    add_link("base_link", None)
    parent, offset = "base_link", 0.0
    for k, length in enumerate(lengths_arr, start=1):
        child = f"link{k}"
        add_link(child, float(length))
        joint = ET.SubElement(robot, "joint", name=f"joint{k}", type="revolute")
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=child)
        ET.SubElement(joint, "origin", xyz=f"{_fmt(offset)} 0 0", rpy="0 0 0")
        ET.SubElement(joint, "axis", xyz="0 0 1")
        ET.SubElement(
            joint,
            "limit",
            lower=_fmt(lo[k - 1]),
            upper=_fmt(hi[k - 1]),
            velocity=_fmt(vel[k - 1]),
            effort="100.0",
        )
        parent, offset = child, float(length)
    add_link("tip", None)
    tip_joint = ET.SubElement(robot, "joint", name="tip_joint", type="fixed")
    ET.SubElement(tip_joint, "parent", link=parent)
    ET.SubElement(tip_joint, "child", link="tip")
    ET.SubElement(tip_joint, "origin", xyz=f"{_fmt(offset)} 0 0", rpy="0 0 0")
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def write_planar_arm(urdf_text: str, directory: Path | None = None) -> Path:
    """Write a generated URDF to a cache file named by its content hash and return its path."""
    folder = directory or Path(tempfile.gettempdir()) / "kinplan-urdf"
    folder.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha1(urdf_text.encode()).hexdigest()[:16]
    path = folder / f"planar_{digest}.urdf"
    if not path.is_file() or path.read_text() != urdf_text:
        tmp = path.with_suffix(f".{digest}.tmp")
        tmp.write_text(urdf_text)
        tmp.replace(path)
    return path
