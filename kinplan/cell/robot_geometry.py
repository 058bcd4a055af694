"""The robot's own collision geometry, in its kinplan model, and which of its pairs are checked.

The geometry comes from the URDF's ``<collision>`` elements (its ``<visual>`` ones when its links
have no ``<collision>`` at all, as kinplan's planar arms; said in the log), read by
``pin.buildGeomFromUrdfString`` on the URDF's whole model
(:func:`kinplan.model.urdf_model.full_model`)
and moved onto the robot's reduced model: each element keeps its pose in its link's frame, and
the link's frame in the reduced model carries the held joints' values and the base pose. Meshes
become their convex hulls (coal's ``buildConvexHull``, qhull): a solid that covers the mesh, with
penetration depths.

Self-collision pairs (:func:`self_pairs`): every two bodies of the robot except

* bodies rigidly attached to each other (on the same joint of the model, also through a locked
  or held joint): their distance never changes;
* adjacent links (a movable URDF joint between them, links joined by fixed joints counting as
  one): their housings overlap by design;
* the SRDF's ``<disable_collisions>`` pairs, when there is an SRDF (given, or found next to the
  URDF: ``NAME.srdf`` in the URDF's folder or in ``../srdf/``, NAME the URDF's stem, the robot's
  name, or the stem without ``_robot``);
* without an SRDF, the pairs in contact at the zero configuration (``robot.neutral()``),
  said in the log.

A tool body (:meth:`kinplan.Robot.with_tool`) is checked against every link except those
rigidly attached to it (the flange's link and what is fixed to it) and, when they are in
contact at the zero configuration, the links one joint away from the flange (a tool mount
overlapping the last wrist link); a tool that touches another link there is reported, not
hidden.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from kinplan.cell.body import CellError, convex_hull
from kinplan.errors import KinplanError
from kinplan.model.arm import Arm
from kinplan.model.urdf_model import full_model
from kinplan.model.urdf_read import read_urdf

logger = logging.getLogger(__name__)

#: Two bodies this close [m] (or closer) at the zero configuration are "in contact" there.
CONTACT_TOLERANCE = 1e-5
_FIXED = "fixed"


@dataclass(frozen=True)
class ExcludedPair:
    """A pair of bodies that is not checked, and why.

    Attributes:
        bodies: The two names (links, tool bodies or obstacles).
        reason: Why it is not checked (e.g. "adjacent links", "disabled in ur5.srdf").
    """

    bodies: tuple[str, str]
    reason: str


@dataclass
class RobotGeometry:
    """The robot's collision bodies on its reduced model.

    Attributes:
        objects: One ``pin.GeometryObject`` per URDF collision element, on the robot's model
            (meshes as convex hulls).
        links: The URDF link of each object.
        source: "collision", or "visual" when the URDF has no collision element.
        urdf_links: Every link of the URDF.
        group: URDF link → index of its group of links joined by fixed joints.
        adjacent: Pairs of groups (sorted) joined by a movable URDF joint, with its name.
        tool_links: Links that are tool bodies (:meth:`kinplan.Robot.with_tool`).
    """

    objects: list[pin.GeometryObject]
    links: list[str]
    source: str
    urdf_links: set[str]
    group: dict[str, int]
    adjacent: dict[tuple[int, int], str]
    tool_links: tuple[str, ...] = field(default_factory=tuple)


def robot_geometry(robot: Arm) -> RobotGeometry:
    """Read the robot's collision geometry (see the module docstring).

    Raises:
        CellError: a collision mesh that cannot be found or read (the message lists where it
            was looked for and how to give its folder).
    """
    urdf_path = Path(robot.urdf_path)
    root = read_urdf(urdf_path)
    tool_links = tuple(getattr(robot, "tool_links", ()))
    own = [link for link in root.findall("link") if link.get("name") not in tool_links]
    kind = "collision" if any(link.find("collision") is not None for link in own) else "visual"
    if kind == "visual" and root.find("link/visual") is not None:
        logger.info(
            "%s has no <collision> element: its <visual> geometry is used for collisions",
            urdf_path.name,
        )
    _resolve_meshes(root, kind, urdf_path, getattr(robot, "package_dirs", ()))
    urdf_links = {link.get("name", "") for link in root.findall("link")}
    group, adjacent = _link_groups(root)
    full = full_model(urdf_path)
    geometry_type = pin.GeometryType.COLLISION if kind == "collision" else pin.GeometryType.VISUAL
    try:
        geometry = pin.buildGeomFromUrdfString(
            full, ET.tostring(root, encoding="unicode"), geometry_type
        )
    except Exception as exc:  # Pinocchio raises RuntimeError/ValueError on a bad mesh
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CellError(
            f"Pinocchio cannot read the {kind} geometry of {urdf_path.name}: {reason}; fix the "
            "mesh files or give their folder with load_robot(..., package_dirs=[...])"
        ) from exc
    model = robot.model
    objects, links = [], []
    counts: dict[str, int] = {}
    for source in geometry.geometryObjects:
        link = full.frames[source.parentFrame].name
        if not model.existFrame(link, pin.FrameType.BODY):
            logger.info("collision body of link %s: the link is not in the model", link)
            continue
        frame = model.frames[model.getFrameId(link, pin.FrameType.BODY)]
        in_link = full.frames[source.parentFrame].placement.inverse() * source.placement
        shape = source.geometry
        if isinstance(shape, coal.BVHModelBase):
            shape = convex_hull(shape, f"the {kind} mesh of link {link!r}")
        count = counts.get(link, 0)
        counts[link] = count + 1
        objects.append(
            pin.GeometryObject(
                f"{link}#{count}",
                frame.parentJoint,
                model.getFrameId(link, pin.FrameType.BODY),
                frame.placement * in_link,
                shape,
            )
        )
        links.append(link)
    return RobotGeometry(
        objects=objects,
        links=links,
        source=kind,
        urdf_links=urdf_links,
        group=group,
        adjacent=adjacent,
        tool_links=tool_links,
    )


def _resolve_meshes(root: ET.Element, kind: str, urdf_path: Path, package_dirs) -> None:
    """Write the absolute path of every mesh of the ``kind`` elements into ``root`` (the
    viewer's resolution: ``package://``, ``file://``, relative and absolute names).

    Raises:
        CellError: a mesh file found nowhere.
    """
    from kinplan.model.mesh_files import resolve_mesh, search_folders

    folders = search_folders(urdf_path, package_dirs)
    for link in root.findall("link"):
        for mesh in link.findall(f"{kind}/geometry/mesh"):
            filename = mesh.get("filename", "")
            found, tried = resolve_mesh(filename, urdf_path, folders)
            if found is None:
                shown = ", ".join(str(p) for p in tried[:4]) + (" …" if len(tried) > 4 else "")
                raise CellError(
                    f"the {kind} mesh {filename!r} of link {link.get('name')!r} in "
                    f"{urdf_path.name} is not found (looked at {shown}); give the folder that "
                    "holds its package with load_robot(..., package_dirs=[...])"
                )
            mesh.set("filename", str(found))


def _link_groups(root: ET.Element) -> tuple[dict[str, int], dict[tuple[int, int], str]]:
    """Links joined by fixed joints, as groups, and the groups a movable joint joins."""
    parent = {link.get("name", ""): link.get("name", "") for link in root.findall("link")}

    def find(name: str) -> str:
        while parent.setdefault(name, name) != name:
            parent[name] = parent[parent[name]]
            name = parent[name]
        return name

    joints = []
    for joint in root.findall("joint"):
        a = joint.find("parent")
        b = joint.find("child")
        if a is None or b is None:
            continue
        pair = (a.get("link", ""), b.get("link", ""))
        if joint.get("type") == _FIXED:
            parent[find(pair[0])] = find(pair[1])
        else:
            joints.append((joint.get("name", ""), pair))
    roots = sorted({find(name) for name in list(parent)})
    index = {name: k for k, name in enumerate(roots)}
    group = {name: index[find(name)] for name in list(parent)}
    adjacent: dict[tuple[int, int], str] = {}
    for name, (link_a, link_b) in joints:
        first, second = sorted((group[link_a], group[link_b]))
        adjacent.setdefault((first, second), name)
    return group, adjacent


# ------------------------------------------------------------------------------------ SRDF
def find_srdf(robot: Arm) -> Path | None:
    """The SRDF next to the robot's URDF (see the module docstring), or None."""
    urdf_path = Path(getattr(robot, "source_urdf_path", None) or robot.urdf_path)
    stem = urdf_path.stem
    stems = dict.fromkeys([stem, str(robot.name), stem.removesuffix("_robot")])
    for folder in (urdf_path.parent, urdf_path.parent.parent / "srdf"):
        for name in stems:
            candidate = folder / f"{name}.srdf"
            if candidate.is_file():
                return candidate
    return None


def read_srdf(path: Path, urdf_links: Iterable[str], urdf_name: str) -> list[ExcludedPair]:
    """The ``<disable_collisions>`` pairs of an SRDF file.

    Raises:
        CellError: the file cannot be read or is not XML, or it names a link the URDF does not
            have (the message lists the URDF's links).
    """
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise CellError(f"srdf: {path} is not valid XML ({exc}); fix or drop the file") from None
    except OSError as exc:
        raise CellError(f"srdf: cannot read {path} ({exc.strerror or exc})") from None
    known = set(urdf_links)
    pairs = []
    for k, element in enumerate(root.iter("disable_collisions")):
        names = (element.get("link1"), element.get("link2"))
        for name in names:
            if name not in known:
                raise CellError(
                    f"srdf: {path.name} names link {name!r} (disable_collisions #{k + 1}), which "
                    f"{urdf_name} does not have; its links: {', '.join(sorted(known))}"
                )
        reason = element.get("reason")
        text = f"disabled in {path.name}" + (f" ({reason})" if reason else "")
        pairs.append(ExcludedPair((str(names[0]), str(names[1])), text))
    return pairs


# ------------------------------------------------------------------------------------ pairs
def self_pairs(
    robot: Arm, geometry: RobotGeometry, srdf: list[ExcludedPair] | None
) -> tuple[list[tuple[int, int]], list[ExcludedPair]]:
    """The robot's checked self-collision pairs (indices into ``geometry.objects``) and the
    excluded link pairs with their reasons (see the module docstring).

    Args:
        robot: The robot.
        geometry: Its collision bodies.
        srdf: The SRDF's disabled pairs, or None without an SRDF.
    """
    objects, links = geometry.objects, geometry.links
    disabled = {frozenset(p.bodies): p.reason for p in srdf or []}
    tools = set(geometry.tool_links)
    checked: list[tuple[int, int]] = []
    excluded: dict[frozenset[str], ExcludedPair] = {}
    touching: list[tuple[int, int]] = []
    for a in range(len(objects)):
        for b in range(a + 1, len(objects)):
            names = (links[a], links[b])
            key = frozenset(names)
            reason = None
            joint_a, joint_b = objects[a].parentJoint, objects[b].parentJoint
            if joint_a == joint_b:
                reason = "rigidly attached to each other"
            elif tools & key:
                parents = robot.model.parents
                if parents[joint_a] == joint_b or parents[joint_b] == joint_a:
                    touching.append((a, b))  # a tool next to the flange's neighbour
                else:
                    checked.append((a, b))
                continue
            else:
                first, second = sorted((geometry.group[names[0]], geometry.group[names[1]]))
                joint = geometry.adjacent.get((first, second))
                if joint is not None:
                    reason = f"adjacent links (joint {joint})"
                elif key in disabled:
                    reason = disabled[key]
            if reason is not None:
                excluded.setdefault(key, ExcludedPair(names, reason))
            elif srdf is None:
                touching.append((a, b))
            else:
                checked.append((a, b))
    if touching:
        distances = pair_distances(robot, objects, touching, robot.neutral())
        said = []
        for (a, b), distance in zip(touching, distances):
            names = (links[a], links[b])
            if distance <= CONTACT_TOLERANCE:
                why = "in contact at the zero configuration"
                if not tools & set(names):
                    why += " (no SRDF)"
                excluded.setdefault(frozenset(names), ExcludedPair(names, why))
                said.append(f"{names[0]}–{names[1]}")
            else:
                checked.append((a, b))
        if said:
            logger.info(
                "%s: pairs in contact at the zero configuration are not checked: %s",
                robot.name,
                ", ".join(dict.fromkeys(said)),
            )
    # a link pair is excluded as a whole: drop the other elements of an excluded link pair
    checked = [(a, b) for a, b in checked if frozenset((links[a], links[b])) not in excluded]
    return sorted(checked), list(excluded.values())


def pair_distances(
    robot: Arm, objects: list[pin.GeometryObject], pairs: list[tuple[int, int]], q: np.ndarray
) -> list[float]:
    """Signed distances [m] of ``pairs`` of ``objects`` (on the robot's model) at ``q``."""
    geometry = pin.GeometryModel()
    for obj in objects:
        geometry.addGeometryObject(obj.copy())
    for a, b in pairs:
        geometry.addCollisionPair(pin.CollisionPair(a, b))
    data, geometry_data = robot.model.createData(), geometry.createData()
    pin.updateGeometryPlacements(robot.model, data, geometry, geometry_data, q)
    try:
        pin.computeDistances(geometry, geometry_data)
    except Exception as exc:  # coal's failures (degenerate meshes) surface as RuntimeError
        raise KinplanError(f"coal could not compute distances of {robot.name}: {exc}") from exc
    return [float(r.min_distance) for r in geometry_data.distanceResults]
