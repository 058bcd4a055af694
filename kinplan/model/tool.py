"""A tool on the flange: its TCP offset and its collision body, as a URDF for a new robot.

:func:`tool_urdf` writes a copy of the robot's URDF with two links fixed to the link that carries
the robot's tip frame (the flange); :meth:`kinplan.Robot.with_tool` loads it as the new robot:

* the **TCP** link, at ``pose`` in the flange frame: the new robot's tip, so forward and inverse
  kinematics, Jacobians and Cartesian paths all work at the TCP;
* the **tool body** link (when a body is given), at the body's pose in the flange frame, with
  the body as its ``<visual>`` and ``<collision>`` geometry: a work cell
  (:class:`kinplan.WorkCell`) checks it like a link, and the viewer draws it from the URDF.

Everything else is kept: locked joints, base pose, joint limits (as the robot has them), mesh
paths (made absolute). The closed-form IK of UR-type arms and of the panda is rebuilt for the
new tip and checked against the forward kinematics (:func:`kinplan.ik.self_check`); an
arm whose closed form does not hold for the TCP uses the numerical solver.
"""

from __future__ import annotations

import hashlib
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import pinocchio as pin

from kinplan import checks
from kinplan.cell.body import Body, CellError, as_pose
from kinplan.model.arm import Arm
from kinplan.model.sources import RobotSpec
from kinplan.model.urdf_read import read_urdf


class FlangedArm(Arm, Protocol):
    """What a tool needs of the arm it goes on (a :class:`kinplan.Robot` has it)."""

    tip_frame: str
    package_dirs: tuple[Path, ...]


#: Colour of a tool body in the viewer (RGBA).
TOOL_RGBA = "0.72 0.74 0.78 1"


@dataclass(frozen=True)
class Tool:
    """A tool attached by :meth:`kinplan.Robot.with_tool`.

    Attributes:
        tcp: The TCP in the flange frame.
        body: The tool body (its pose in the flange frame), or None.
        flange: The frame the tool is mounted on (the previous robot's tip).
        tcp_link: The URDF link of the TCP (the new robot's ``tip_frame``).
        body_link: The URDF link that carries the body, or None.
    """

    tcp: pin.SE3
    body: Body | None
    flange: str
    tcp_link: str
    body_link: str | None


@dataclass(frozen=True)
class ToolUrdf:
    """The URDF of an arm with a tool (:func:`tool_urdf`).

    Attributes:
        spec: Where the new URDF is (a :class:`~kinplan.model.sources.RobotSpec` to load).
        tool: The tool (its ``tcp_link`` is the new robot's tip frame).
    """

    spec: RobotSpec
    tool: Tool


def tool_urdf(robot: FlangedArm, pose: object, body: Body | None = None) -> ToolUrdf:
    """The robot's URDF with a tool on its flange (see the module docstring).

    Args:
        robot: A :class:`kinplan.Robot`; its tip frame is the flange.
        pose: The TCP in the flange frame: ``pin.SE3``, 4×4 matrix or position 3-vector [m].
        body: The tool's collision body, posed in the flange frame
            (:class:`kinplan.cell.Body`), or None.

    Returns:
        The new URDF (written to a temporary folder, mesh paths made absolute) and the tool.

    Raises:
        CellError: a pose that is not a pose, a body that is not a ``Body``.
    """
    tcp = as_pose(pose, "pose (the TCP in the flange frame)")
    if body is not None and not isinstance(body, Body):
        raise CellError(
            "body must be a kinplan.cell.Body (Body.cylinder(radius, length, pose), Body.box, "
            f"Body.sphere, Body.mesh) or None, got {checks.describe(body)}"
        )
    urdf_path = Path(robot.urdf_path)
    root = read_urdf(urdf_path)
    _absolute_meshes(root, urdf_path, robot.package_dirs)
    link, offset = _flange_link(robot)
    links = {element.get("name", "") for element in root.findall("link")}
    joints = {element.get("name", "") for element in root.findall("joint")}
    body_link = None
    if body is not None:
        body_link = _unique("tool", links | joints)
        links.add(body_link)
        _add_link(root, body_link, link, offset * body.pose, joints, body)
    tcp_link = _unique("tcp", links | joints)
    _add_link(root, tcp_link, link, offset * tcp, joints, None)
    ET.indent(root)
    text = '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    path = _write(text, urdf_path.stem)
    spec = RobotSpec(
        name=robot.name,
        urdf_path=path,
        package_dirs=tuple(robot.package_dirs) + (urdf_path.parent,),
    )
    return ToolUrdf(spec, Tool(pin.SE3(tcp), body, robot.tip_frame, tcp_link, body_link))


def _flange_link(robot) -> tuple[str, pin.SE3]:
    """The URDF link that carries the robot's tip frame, and the tip in that link's frame."""
    model = robot.model
    frame = model.frames[robot.tip_id]
    offset = pin.SE3.Identity()
    while frame.type != pin.FrameType.BODY:
        parent = model.frames[frame.parentFrame]
        if frame.parentFrame == 0 or parent.parentJoint != frame.parentJoint:
            break
        offset = parent.placement.inverse() * frame.placement * offset
        frame = parent
    if frame.type != pin.FrameType.BODY:  # pragma: no cover - a tip is a link or under one
        raise CellError(f"cannot find the URDF link that carries the tip {robot.tip_frame!r}")
    return frame.name, offset


def _unique(stem: str, taken: set[str]) -> str:
    """``stem``, ``stem_2``, ``stem_3``, … : the first name not in ``taken``."""
    if stem not in taken:
        return stem
    k = 2
    while f"{stem}_{k}" in taken:
        k += 1
    return f"{stem}_{k}"


def _origin(parent: ET.Element, pose: pin.SE3) -> None:
    """Add an ``<origin>`` of ``pose`` (xyz [m], rpy [rad], URDF's fixed-axis convention)."""
    rpy = pin.rpy.matrixToRpy(pose.rotation)
    ET.SubElement(
        parent,
        "origin",
        xyz=" ".join(repr(float(v)) for v in pose.translation),
        rpy=" ".join(repr(float(v)) for v in rpy),
    )


def _geometry(parent: ET.Element, body: Body) -> None:
    """Add a ``<geometry>`` of the body's shape (its pose goes into the link's joint)."""
    geometry = ET.SubElement(parent, "geometry")
    if body.shape == "box":
        ET.SubElement(geometry, "box", size=" ".join(repr(v) for v in body.size))
    elif body.shape == "cylinder":
        radius, length = body.size
        ET.SubElement(geometry, "cylinder", radius=repr(radius), length=repr(length))
    elif body.shape == "sphere":
        ET.SubElement(geometry, "sphere", radius=repr(body.size[0]))
    else:
        ET.SubElement(
            geometry,
            "mesh",
            filename=str(body.path),
            scale=" ".join(repr(v) for v in body.scale),
        )


def _add_link(
    root: ET.Element,
    name: str,
    parent: str,
    pose: pin.SE3,
    joints: set[str],
    body: Body | None,
) -> None:
    """Add link ``name`` fixed to ``parent`` at ``pose``, with ``body`` as its geometry."""
    link = ET.SubElement(root, "link", name=name)
    if body is not None:
        visual = ET.SubElement(link, "visual")
        _origin(visual, pin.SE3.Identity())
        _geometry(visual, body)
        material = ET.SubElement(visual, "material", name=f"kinplan_{name}")
        ET.SubElement(material, "color", rgba=TOOL_RGBA)
        collision = ET.SubElement(link, "collision")
        _origin(collision, pin.SE3.Identity())
        _geometry(collision, body)
    joint_name = _unique(f"{name}_joint", joints)
    joints.add(joint_name)
    joint = ET.SubElement(root, "joint", name=joint_name, type="fixed")
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=name)
    _origin(joint, pose)


def _absolute_meshes(root: ET.Element, urdf_path: Path, package_dirs) -> None:
    """Write the absolute path of every mesh file found into ``root`` (the copy lives in a
    cache folder, where relative and ``package://`` names would not resolve)."""
    from kinplan.model.mesh_files import resolve_mesh, search_folders

    folders = search_folders(urdf_path, package_dirs)
    for mesh in root.iter("mesh"):
        found, _ = resolve_mesh(mesh.get("filename", ""), urdf_path, folders)
        if found is not None:
            mesh.set("filename", str(found.resolve()))


def _write(text: str, stem: str) -> Path:
    """Write a generated URDF to a cache file named by its content hash; return its path."""
    folder = Path(tempfile.gettempdir()) / "kinplan-urdf"
    folder.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha1(text.encode()).hexdigest()[:16]
    path = folder / f"{stem}_tool_{digest}.urdf"
    if not path.is_file() or path.read_text() != text:
        tmp = path.with_suffix(f".{digest}.tmp")
        tmp.write_text(text)
        tmp.replace(path)
    return path
