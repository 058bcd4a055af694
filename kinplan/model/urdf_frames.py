"""Choosing a tool frame in a URDF's model: where each chain ends (grippers left out), the
candidate tool frames, the default tool frame, and a frame looked up by name with the candidates
listed when it is missing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from kinplan.errors import FrameError, URDFError

#: Joint (and link) names of a gripper or hand, left out of the default tool chain (held at 0)
#: and of the candidate tool frames.
_DIGITS = r"(^|_)(index|middle|ring|pinky|little|mrl)(_|\d|$)"
GRIPPER_JOINT = re.compile(rf"gripper|finger|jaw|claw|thumb|hand_joint|(^|_)hand_|{_DIGITS}", re.I)
#: Link names of fingers, left out of the candidate tool frames (a gripper or hand link may be
#: the tool: baxter's ``left_gripper``, panda's ``panda_hand_tcp``).
FINGER_LINK = re.compile(rf"finger|jaw|claw|thumb|knuckle|{_DIGITS}", re.IGNORECASE)
#: Link names that make a tool frame, preferred (in this order) as the default tip among the
#: links fixed to the last joint of the chain.
TOOL_LINKS = tuple(
    re.compile(pattern, re.IGNORECASE)
    for pattern in (r"tcp", r"tool", r"eef|end_?effector", r"flange", r"ee_link")
)


@dataclass
class ChainEnd:
    """Where one chain of the tree ends, grippers left out (see :func:`chain_ends`)."""

    joint: int
    links: list[str]
    gripper_parent: str | None


def chain_ends(model: pin.Model) -> list[ChainEnd]:
    """The end of every chain (one per leaf joint) of ``model``, grippers left out.

    A chain ends at its last joint that is not a gripper's (:data:`GRIPPER_JOINT`; unless every
    joint of the chain is named like a gripper's: a finger robot such as finger_edu keeps
    them). Its links are the links and frames fixed to that joint, finger links
    (:data:`FINGER_LINK`) left out unless there are no others, in the model's order;
    ``gripper_parent`` is the link the first gripper joint hangs from (None without one).
    """
    parents = {model.parents[j] for j in range(1, model.njoints)}
    ends = []
    for leaf in (j for j in range(1, model.njoints) if j not in parents):
        j, first_gripper = leaf, None
        while j > 0 and GRIPPER_JOINT.search(model.names[j]):
            first_gripper, j = j, model.parents[j]
        if j == 0:  # the whole chain is a finger (finger_edu): it is the arm
            j, first_gripper = leaf, None
        frames = [
            f.name
            for f in model.frames
            if f.parentJoint == j and f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)
        ]
        plain = [name for name in frames if not FINGER_LINK.search(name)] or frames
        gripper_parent = None
        if first_gripper is not None:
            joint_frame = model.frames[
                model.getFrameId(model.names[first_gripper], pin.FrameType.JOINT)
            ]
            gripper_parent = model.frames[joint_frame.parentFrame].name
        ends.append(ChainEnd(j, plain, gripper_parent))
    return ends


def tip_candidates(model: pin.Model) -> list[str]:
    """Candidate tool frames: the links and frames fixed to the end of every chain (its last
    joint that is not a gripper's), fingers left out."""
    names = [name for end in chain_ends(model) for name in end.links]
    return list(dict.fromkeys(names))


def frame_id(model: pin.Model, name: str, urdf_path: Path) -> int:
    """Index of the frame ``name``: a link first (a link and a joint may share a name), then
    any other frame; a FrameError listing the candidate tool frames if there is none."""
    for kind in (pin.FrameType.BODY, pin.FrameType.OP_FRAME, pin.FrameType.FIXED_JOINT):
        if model.existFrame(name, kind):
            return model.getFrameId(name, kind)
    if model.existFrame(name):
        return model.getFrameId(name)
    raise FrameError(
        f"no frame {name!r} in {urdf_path.name}; candidate tool frames (chain ends and the "
        f"frames below them): {', '.join(tip_candidates(model))} (`kinplan info ROBOT --frames` "
        "lists every frame)"
    )


def default_tool_frame(model: pin.Model, urdf_path: Path) -> str:
    """The tool link of the only chain, grippers left out (their joints stay at 0).

    The chain ends at its last joint that is not a gripper's (see :func:`chain_ends`). Of the
    links fixed to that joint, a tool-like one (:data:`TOOL_LINKS`: ``tcp``, ``tool``, ``eef``,
    ``end_effector``, ``flange``, ``ee_link``, in this order) is the tip; else the link the
    first gripper joint hangs from; else the last of them.
    """
    if model.njoints < 2:
        raise URDFError(f"{urdf_path} has no movable joint; kinplan plans for arms with joints")
    ends = []
    for end in chain_ends(model):
        tools = [name for pattern in TOOL_LINKS for name in end.links if pattern.search(name)]
        ends.append(tools[0] if tools else end.gripper_parent or end.links[-1])
    ends = list(dict.fromkeys(ends))
    if len(ends) != 1:
        raise FrameError(
            f"{urdf_path} has several kinematic chains; choose the tool frame with tip=<name>; "
            f"candidates: {', '.join(tip_candidates(model))} (`kinplan info ROBOT --frames` lists "
            "every frame)"
        )
    return ends[0]
