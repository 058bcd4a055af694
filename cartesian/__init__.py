"""Cartesian paths for the tool and their following by a robot arm.

Paths (:class:`Line`, :class:`Arc`, :func:`Circle`, :func:`Polyline`, :class:`PathSequence`,
:class:`FunctionPath`; corners blended by :func:`blend_corners`; weaving :class:`Weave`; torch
angles :class:`TorchOrientation`) are parametrised by the path-length fraction s ∈ [0, 1].
:func:`follow` times a path and solves IK at every sample with reachability and singularity
monitoring; :func:`check_reachability` is the fast geometric pre-check. :func:`plan_seam`
searches the torch's free roll and tilt bands (and a 7-joint arm's self-motion) for a seam, then
follows it.
"""

from __future__ import annotations

from cartesian.blends import CornerBlend, SubPath, blend_corners
from cartesian.events import Event, Status
from cartesian.follow import CartesianPlan, follow
from cartesian.geometry import Reachability, check_reachability
from cartesian.paths import (
    Arc,
    Circle,
    CircularArc,
    FunctionPath,
    HeldOrientation,
    Line,
    Path,
    PathSequence,
    Polyline,
)
from cartesian.seam_path import SeamPath
from cartesian.seam_planner import plan_seam
from cartesian.torch import TorchOrientation, torch_rotations
from cartesian.weave import Weave

__all__ = [
    "Arc",
    "CartesianPlan",
    "Circle",
    "CircularArc",
    "CornerBlend",
    "Event",
    "FunctionPath",
    "HeldOrientation",
    "Line",
    "Path",
    "PathSequence",
    "Polyline",
    "Reachability",
    "SeamPath",
    "Status",
    "SubPath",
    "TorchOrientation",
    "Weave",
    "blend_corners",
    "check_reachability",
    "follow",
    "plan_seam",
    "torch_rotations",
]
