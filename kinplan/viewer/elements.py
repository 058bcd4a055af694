"""The URDF's ``<visual>`` and ``<collision>`` elements, as the viewer draws them.

Read from the file with the standard XML parser, the way urdfdom (Pinocchio, ROS) reads them:
each element's link, origin, geometry (box, cylinder, sphere or mesh file with its scale) and
material colour. Where the mesh files are is :mod:`kinplan.mesh_files`' job.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan.model.urdf_read import read_urdf
from kinplan.viewer.meshes import DEFAULT_RGBA

__all__ = ["Geometry", "LinkElement", "read_urdf_elements"]


@dataclass(frozen=True)
class Geometry:
    """A URDF ``<geometry>``: a primitive, or a mesh file with its scale."""

    kind: str  # "box", "cylinder", "sphere" or "mesh"
    size: tuple[float, ...] = ()  # box (x, y, z); cylinder (radius, length); sphere (radius,) [m]
    filename: str = ""  # the URDF's mesh file name, as written
    scale: tuple[float, ...] = (1.0, 1.0, 1.0)  # (x, y, z)


@dataclass(frozen=True)
class LinkElement:
    """A URDF ``<visual>`` or ``<collision>`` of a link."""

    link: str
    name: str  # scene node name: link name and index among the link's visuals
    origin: np.ndarray  # (4, 4) pose of the geometry in the link frame [m]
    geometry: Geometry | None  # None: a geometry kinplan does not draw
    rgba: tuple[float, ...] | None  # the URDF material's colour, RGBA in [0, 1]


def _floats(text: str | None, default: Sequence[float]) -> tuple[float, ...]:
    if text is None:
        return tuple(default)
    return tuple(float(v) for v in text.split())


def _origin(element: ET.Element) -> np.ndarray:
    """The 4×4 pose of an ``<origin xyz rpy>`` child (identity when absent) [m, rad]."""
    origin = element.find("origin")
    matrix = np.eye(4)
    if origin is not None:
        roll, pitch, yaw = _floats(origin.get("rpy"), (0.0, 0.0, 0.0))
        matrix[:3, :3] = pin.rpy.rpyToMatrix(roll, pitch, yaw)
        matrix[:3, 3] = _floats(origin.get("xyz"), (0.0, 0.0, 0.0))
    return matrix


def _geometry(element: ET.Element) -> Geometry | None:
    """The geometry of a ``<visual>`` or ``<collision>``; None if none kinplan draws."""
    geometry = element.find("geometry")
    shape = None if geometry is None else next(iter(geometry), None)
    if shape is None:
        return None
    if shape.tag == "box":
        return Geometry("box", _floats(shape.get("size"), (0.0, 0.0, 0.0)))
    if shape.tag == "cylinder":
        return Geometry("cylinder", (float(shape.get("radius", 0)), float(shape.get("length", 0))))
    if shape.tag == "sphere":
        return Geometry("sphere", (float(shape.get("radius", 0)),))
    if shape.tag == "mesh" and shape.get("filename"):
        scale = _floats(shape.get("scale"), (1.0, 1.0, 1.0))
        scale = scale * 3 if len(scale) == 1 else scale
        return Geometry("mesh", filename=shape.get("filename", "").strip(), scale=scale[:3])
    return None


def _material_colours(root: ET.Element) -> dict[str, tuple[float, ...]]:
    """Colours of the URDF's top-level named materials."""
    colours = {}
    for material in root.findall("material"):
        color = material.find("color")
        if material.get("name") and color is not None and color.get("rgba"):
            colours[material.get("name", "")] = _floats(color.get("rgba"), DEFAULT_RGBA)
    return colours


def _colour(element: ET.Element, named: dict[str, tuple[float, ...]]) -> tuple[float, ...] | None:
    """A visual's material colour, as urdfdom (Pinocchio, ROS) reads it; None without one.

    A material name keeps its first colour: a top-level ``<material>``, else the first visual
    that defines it inline (registered in ``named``); a later inline colour under a known name
    is ignored. An unnamed material has its own colour.
    """
    material = element.find("material")
    if material is None:
        return None
    name = material.get("name", "")
    if name in named:
        return named[name]
    color = material.find("color")
    if color is None or not color.get("rgba"):
        return None
    rgba = _floats(color.get("rgba"), DEFAULT_RGBA)
    if name:
        named[name] = rgba
    return rgba


def read_urdf_elements(
    urdf_path: Path,
) -> tuple[list[LinkElement], dict[str, list[LinkElement]]]:
    """The visuals of a URDF, in file order, and the collision elements of each link.

    A link's visuals are named ``<link>_<index>`` (as Pinocchio names them), with ``/`` made
    ``_``.

    Raises:
        URDFError: the file cannot be read or is not XML.
    """
    root = read_urdf(urdf_path)  # the loader's reader: undeclared prefixes load here too
    named = _material_colours(root)
    visuals: list[LinkElement] = []
    collisions: dict[str, list[LinkElement]] = {}
    for link in root.findall("link"):
        link_name = link.get("name", "")
        for index, visual in enumerate(link.findall("visual")):
            name = f"{link_name}_{index}".replace("/", "_")
            geometry = _geometry(visual)
            visuals.append(
                LinkElement(link_name, name, _origin(visual), geometry, _colour(visual, named))
            )
        collisions[link_name] = [
            LinkElement(link_name, f"{link_name}_collision{k}", _origin(c), _geometry(c), None)
            for k, c in enumerate(link.findall("collision"))
        ]
    return visuals, collisions
