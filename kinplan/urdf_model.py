"""The kinematic chain of a URDF, as a Pinocchio model kinplan can plan with.

:func:`build_chain` reads a URDF and returns a :class:`Chain`: a Pinocchio model of the joints
between the root and the tool frame, one coordinate per joint (radians or metres), with

* **continuous joints** as unbounded revolute joints (lower = −inf, upper = +inf: the angle is
  never wrapped along a motion). Pinocchio models them with (cos θ, sin θ); the URDF is read with
  them as revolute joints instead, so every joint has one coordinate;
* **mimic joints** following their master (Pinocchio's ``mimic=True``): they are not in q, and
  the Jacobian columns of their masters carry the coupling;
* **locked joints** (``locked_joints={name: value}``) and every joint off the tool's chain held at
  a value (the URDF's neutral 0 unless given), and out of q;
* a **floating or planar root joint** (mobile bases, humanoids) held fixed: the whole robot stands
  at ``base_pose`` in the world (an SE3; identity by default);
* **limit overrides** (``limits={joint: {"lower", "upper", "velocity", "acceleration"}}``, any
  subset) that replace the URDF's values, so joints without usable limits load.

Everything wrong with the input is a :class:`~kinplan.errors.KinplanError` that says what to do.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.errors import FrameError, InputError, URDFError

logger = logging.getLogger(__name__)

#: Joint limits written into the URDF for continuous joints read as revolute [rad]; kinplan's own
#: limits for them are ±inf.
UNBOUNDED = 1e9
#: Keys of a ``limits=`` entry.
LIMIT_KEYS = ("lower", "upper", "velocity", "acceleration")
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
_ONE_DOF = {"revolute", "prismatic", "continuous"}
_HELD_ROOT = {"floating", "planar"}


@dataclass
class Chain:
    """A URDF's tool chain as a Pinocchio model (see the module docstring).

    Attributes:
        model: Pinocchio model with one coordinate per independent joint of the chain.
        name: The URDF's robot name.
        base_frame: The URDF's root link.
        tip: The tool frame.
        lower: Lower position limits [rad or m] (−inf for continuous joints).
        upper: Upper position limits [rad or m] (+inf for continuous joints).
        velocity: Speed limits [rad/s or m/s] (inf where unknown).
        acceleration: Acceleration limits [rad/s² or m/s²] (inf where unknown).
        continuous: Names of the continuous joints of the chain.
        mimic: Mimic joints of the chain: name → (master, multiplier, offset).
        locked: Joints held at a value: name → value [rad or m] (the user's and the grippers'
            left out of the default chain; joints off the chain are not listed).
        held_root: A floating or planar root joint held at the base pose, or None.
    """

    model: pin.Model
    name: str
    base_frame: str
    tip: str
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    continuous: list[str] = field(default_factory=list)
    mimic: dict[str, tuple[str, float, float]] = field(default_factory=dict)
    locked: dict[str, float] = field(default_factory=dict)
    held_root: str | None = None


@dataclass
class _Joint:
    """One joint of the URDF's XML."""

    name: str
    kind: str
    parent: str
    child: str
    has_limit: bool
    mimic: tuple[str, float, float] | None


# ------------------------------------------------------------------------------------ reading
def read_urdf(urdf_path: Path) -> ET.Element:
    """The URDF's ``<robot>`` element, or a URDFError saying why it cannot be used."""
    try:
        root = ET.parse(urdf_path).getroot()
    except ET.ParseError as exc:
        raise URDFError(f"{urdf_path} is not valid XML ({exc}); fix the file") from exc
    except OSError as exc:
        raise URDFError(f"cannot read the URDF file {urdf_path}: {exc}") from exc
    if root.tag != "robot":
        raise URDFError(f"{urdf_path} is not a URDF: its root element is <{root.tag}>, not <robot>")
    return root


def root_link(root: ET.Element, urdf_path: Path) -> str:
    """The URDF's root link (the one link that is no joint's child)."""
    links = [link.get("name", "") for link in root.findall("link")]
    if not links:
        raise URDFError(f"{urdf_path} has no <link>: it describes no robot; check the file")
    children = {child.get("link") for child in root.findall("joint/child")}
    roots = [name for name in links if name not in children]
    if len(roots) != 1:
        raise URDFError(
            f"{urdf_path} must have exactly one root link (a link that is no joint's child); "
            f"found {roots or 'none'}"
        )
    return roots[0]


def _joints(root: ET.Element) -> dict[str, _Joint]:
    joints = {}
    for element in root.findall("joint"):
        mimic = element.find("mimic")
        mimic_of = None
        if mimic is not None:
            mimic_of = (
                mimic.get("joint", ""),
                float(mimic.get("multiplier", "1")),
                float(mimic.get("offset", "0")),
            )
        parent, child = element.find("parent"), element.find("child")
        joints[element.get("name", "")] = _Joint(
            element.get("name", ""),
            element.get("type", ""),
            "" if parent is None else parent.get("link", ""),
            "" if child is None else child.get("link", ""),
            element.find("limit") is not None,
            mimic_of,
        )
    return joints


@contextlib.contextmanager
def _native_stderr_captured() -> Iterator[list[str]]:
    """Redirect file descriptor 2 into a temporary file while the block runs.

    Native code (urdfdom inside Pinocchio) prints its diagnostics straight to file descriptor
    2, past Python's ``sys.stderr``; this keeps them off the terminal. The yielded list receives
    the captured text when the block ends. Without a usable descriptor 2 nothing is captured.
    """
    captured: list[str] = []
    try:
        saved = os.dup(2)
    except OSError:  # no descriptor 2 (a daemon): nothing to keep off the terminal
        yield captured
        return
    with tempfile.TemporaryFile() as sink:
        try:
            sys.stderr.flush()
        except (AttributeError, OSError, ValueError):  # replaced or closed sys.stderr
            pass
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            captured.append(sink.read().decode("utf-8", errors="replace"))


def _parser_messages(text: str) -> str:
    """urdfdom's captured ``Error:``/``Warning:`` lines on one line, without the source
    locations of its C++ code (``at line 105 in .../pose.cpp``)."""
    messages = []
    for line in text.splitlines():
        line = " ".join(line.split())
        if not line or re.match(r"^at line \d+ in ", line):
            continue
        messages.append(re.sub(r"^Error:\s*", "", line))
    return "; ".join(messages)


def _parse_model(xml: str, urdf_path: Path, mimic: bool = True) -> pin.Model:
    """Pinocchio's model of the URDF text (mimic joints as such unless ``mimic`` is False);
    urdfdom's own messages go into the error (or the log)."""
    with _native_stderr_captured() as captured:
        try:
            model = pin.buildModelFromXML(xml, mimic=mimic)
            failure = None
        except Exception as exc:  # RuntimeError, ValueError or Boost.Python errors: all bad URDF
            model, failure = None, exc
    details = _parser_messages("".join(captured))
    if failure is not None:
        said = f" (the URDF parser reported: {details})" if details else ""
        reason = str(failure).strip().rstrip(".")
        raise URDFError(
            f"Pinocchio could not read {urdf_path}: {reason}{said}; fix the file"
        ) from failure
    if details:
        logger.info("URDF parser on %s: %s", urdf_path, details)
    return model


# ------------------------------------------------------------------------------ arguments
def check_locked_joints(locked_joints: object, joints: Mapping[str, _Joint]) -> dict[str, float]:
    """``locked_joints`` as {name: value}, every name a movable 1-dof joint of the URDF."""
    if locked_joints is None:
        return {}
    if not isinstance(locked_joints, Mapping):
        raise InputError(
            "locked_joints must be a dict {joint name: value [rad or m]}, got "
            f"{checks.describe(locked_joints)}"
        )
    locked = {}
    for name, value in locked_joints.items():
        joint = _known_joint(name, joints, "locked_joints")
        if joint.kind not in _ONE_DOF:
            raise InputError(
                f"locked_joints: joint {name!r} is {joint.kind}; only revolute, continuous and "
                "prismatic joints can be locked at a value (a floating or planar root joint is "
                "held at base_pose)"
            )
        locked[name] = checks.number(value, f"locked_joints[{name!r}]", unit="rad or m")
    return locked


def check_limits(limits: object, joints: Mapping[str, _Joint]) -> dict[str, dict[str, float]]:
    """``limits`` as {joint: {key: value}} with keys among :data:`LIMIT_KEYS`."""
    if limits is None:
        return {}
    if not isinstance(limits, Mapping):
        raise InputError(
            'limits must be a dict {joint name: {"lower": .., "upper": .., "velocity": .., '
            f'"acceleration": ..}}}} (any subset), got {checks.describe(limits)}'
        )
    checked: dict[str, dict[str, float]] = {}
    for name, entry in limits.items():
        _known_joint(name, joints, "limits")
        if not isinstance(entry, Mapping) or not entry:
            raise InputError(
                f"limits[{name!r}] must be a dict with any of {', '.join(LIMIT_KEYS)}, got "
                f"{checks.describe(entry)}"
            )
        values = {}
        for key, value in entry.items():
            if key not in LIMIT_KEYS:
                raise InputError(
                    f"limits[{name!r}] has an unknown key {key!r}; use {', '.join(LIMIT_KEYS)}"
                )
            positive = key in ("velocity", "acceleration")
            values[key] = checks.number(value, f"limits[{name!r}][{key!r}]", positive=positive)
        if "lower" in values and "upper" in values and not values["lower"] < values["upper"]:
            raise InputError(
                f"limits[{name!r}]: lower {values['lower']} must be below upper {values['upper']}"
            )
        checked[name] = values
    return checked


def _known_joint(name: object, joints: Mapping[str, _Joint], what: str) -> _Joint:
    if not isinstance(name, str) or name not in joints:
        movable = [j.name for j in joints.values() if j.kind != "fixed"]
        raise InputError(
            f"{what}: no joint {name!r} in the URDF; its movable joints: {', '.join(movable)}"
        )
    return joints[name]


# ------------------------------------------------------------------------------ the chain
def _edited_xml(
    root: ET.Element, joints: Mapping[str, _Joint], limits: Mapping[str, Mapping[str, float]]
) -> tuple[str, set[str]]:
    """The URDF text with continuous joints as revolute ones (limits ±UNBOUNDED), the limit
    overrides written in, and placeholder limits (0, 0) where a revolute or prismatic joint has
    none (the parser needs one; such a joint is refused only if the chain uses it).

    Returns:
        (text, names of the joints that got a placeholder).
    """
    placeholders = set()
    for element in root.findall("joint"):
        name, kind = element.get("name", ""), element.get("type", "")
        if kind not in _ONE_DOF:
            continue
        limit = element.find("limit")
        if limit is None:
            limit = ET.SubElement(element, "limit", effort="0", velocity="0")
            if kind != "continuous":
                placeholders.add(name)
                limit.set("lower", "0")
                limit.set("upper", "0")
        if kind == "continuous":
            element.set("type", "revolute")
            limit.set("lower", repr(-UNBOUNDED))
            limit.set("upper", repr(UNBOUNDED))
        for key, value in limits.get(name, {}).items():
            if key in ("lower", "upper", "velocity"):
                limit.set(key, repr(float(value)))
                placeholders.discard(name)
        limit.attrib.setdefault("effort", "0")
        limit.attrib.setdefault("velocity", "0")
    return ET.tostring(root, encoding="unicode"), placeholders


def _uncouple_mimics(
    root: ET.Element, joints: Mapping[str, _Joint], xml: str, urdf_path: Path
) -> tuple[str, set[str]]:
    """Drop the ``<mimic>`` of the mimic joints Pinocchio cannot couple, so the URDF loads.

    Pinocchio couples a mimic joint to its master only when the master is a 1-dof joint that
    is not itself a mimic joint and that its depth-first walk of the tree reaches first. Talos'
    and Romeo's grippers (master on a sibling branch reached later) and Alex's hands (master
    missing) break that; such a joint becomes an independent joint of the model, which
    :func:`build_chain` holds at the value of the relation (or refuses on the tool chain).

    Args:
        root: The URDF's ``<robot>`` element, edited in place.
        joints: The URDF's joints.
        xml: The URDF text of ``root`` (continuous joints already read as revolute).
        urdf_path: The file, for messages.

    Returns:
        (the URDF text, names of the uncoupled mimic joints).
    """
    mimics = {
        name: joint.mimic
        for name, joint in joints.items()
        if joint.mimic is not None and joint.kind in _ONE_DOF  # Talos has fixed "mimic" joints
    }
    if not mimics:
        return xml, set()
    walk = list(_parse_model(xml, urdf_path, mimic=False).names)
    order = {name: k for k, name in enumerate(walk)}
    uncoupled = set()
    for name, (master, _, _) in mimics.items():
        usable = (
            master in joints
            and joints[master].kind in _ONE_DOF
            and master not in mimics
            and order.get(master, len(walk)) < order.get(name, -1)
        )
        if not usable:
            uncoupled.add(name)
    if not uncoupled:
        return xml, set()
    for element in root.findall("joint"):
        mimic = element.find("mimic")
        if element.get("name", "") in uncoupled and mimic is not None:
            element.remove(mimic)
    logger.info(
        "%s: Pinocchio cannot couple the mimic joint(s) %s to their masters; held at the "
        "value of the relation where they are off the tool chain",
        urdf_path.name,
        ", ".join(sorted(uncoupled)),
    )
    return ET.tostring(root, encoding="unicode"), uncoupled


def _reduced_model(model: pin.Model, to_hold: Sequence[int], q_ref: np.ndarray) -> pin.Model:
    """``pin.buildReducedModel``, safe for joints named like a link.

    Pinocchio looks frames up by name while it reduces a model, which fails when a joint
    shares its name with a link (so100's ``gripper``); such joints are renamed meanwhile and
    get their names back in the reduced model.
    """
    if not to_hold:
        return model
    links = {f.name for f in model.frames if f.type != pin.FrameType.JOINT}
    renamed = {}
    for j in range(1, model.njoints):
        name = model.names[j]
        if name in links:
            temporary = f"{name}__kinplan_joint_{j}"
            renamed[temporary] = name
            _rename_joint(model, name, temporary)
    try:
        reduced = pin.buildReducedModel(model, list(to_hold), q_ref)
    finally:
        for temporary, name in renamed.items():
            _rename_joint(model, temporary, name)
    for temporary, name in renamed.items():
        _rename_joint(reduced, temporary, name)
    return reduced


def _rename_joint(model: pin.Model, old: str, new: str) -> None:
    """Rename a joint of ``model`` and its joint frame (or the fixed frame a held joint left)."""
    for j in range(1, model.njoints):
        if model.names[j] == old:
            model.names[j] = new
    for k in range(len(model.frames)):
        frame = model.frames[k]
        if frame.name == old and frame.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
            frame.name = new
            model.frames[k] = frame


@dataclass
class _ChainEnd:
    """Where one chain of the tree ends, grippers left out (see :func:`_chain_ends`)."""

    joint: int
    links: list[str]
    gripper_parent: str | None


def _chain_ends(model: pin.Model) -> list[_ChainEnd]:
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
        ends.append(_ChainEnd(j, plain, gripper_parent))
    return ends


def tip_candidates(model: pin.Model) -> list[str]:
    """Candidate tool frames: the links and frames fixed to the end of every chain (its last
    joint that is not a gripper's), fingers left out."""
    names = [name for end in _chain_ends(model) for name in end.links]
    return list(dict.fromkeys(names))


@dataclass(frozen=True)
class FrameRow:
    """One frame of a URDF, as ``kinplan info ROBOT --frames`` lists it.

    Attributes:
        name: The frame's name (a link, a joint, or a frame a fixed joint leaves).
        kind: "link", "joint", "fixed joint" or "frame".
        parent_joint: The movable joint that carries it ("(root)": none, it is fixed to the
            root link).
        joint_type: That joint's URDF type ("revolute", "continuous", "prismatic", "floating",
            "planar"), with "mimic: multiplier × master + offset" for a mimic joint.
    """

    name: str
    kind: str
    parent_joint: str
    joint_type: str


_FRAME_KINDS = {
    pin.FrameType.BODY: "link",
    pin.FrameType.JOINT: "joint",
    pin.FrameType.FIXED_JOINT: "fixed joint",
    pin.FrameType.OP_FRAME: "frame",
    pin.FrameType.SENSOR: "sensor",
}


def frame_table(urdf_path: Path) -> list[FrameRow]:
    """Every frame of the URDF (links, joints, fixed joints), in the tree's order, with the
    movable joint that carries it: what a tool frame (``tip``) can be chosen from.

    Raises:
        URDFError: a file that is not a usable URDF.
    """
    urdf_path = Path(urdf_path)
    root = read_urdf(urdf_path)
    joints = _joints(root)
    xml, _ = _edited_xml(root, joints, {})
    xml, _ = _uncouple_mimics(root, joints, xml, urdf_path)
    model = _parse_model(xml, urdf_path)
    rows = []
    for frame in model.frames:
        if frame.name == "universe":
            continue
        parent = model.names[frame.parentJoint] if frame.parentJoint else "(root)"
        joint_type = "-"
        if parent in joints:
            joint = joints[parent]
            joint_type = joint.kind
            if joint.mimic is not None:
                master, multiplier, offset = joint.mimic
                joint_type += f", mimic: {multiplier:g} × {master} {offset:+g}"
        kind = _FRAME_KINDS.get(frame.type, "frame")
        rows.append(FrameRow(frame.name, kind, parent, joint_type))
    return rows


def full_model(urdf_path: Path) -> pin.Model:
    """The whole URDF as kinplan reads it, before :func:`build_chain` reduces it to the chain:
    every joint movable, continuous joints as revolute ones, mimic joints coupled where
    Pinocchio can, every link a BODY frame under its URDF name (what
    ``pin.buildGeomFromUrdf`` needs to attach the URDF's geometry).

    Raises:
        URDFError: a file that is not a usable URDF.
    """
    urdf_path = Path(urdf_path)
    root = read_urdf(urdf_path)
    joints = _joints(root)
    xml, _ = _edited_xml(root, joints, {})
    xml, _ = _uncouple_mimics(root, joints, xml, urdf_path)
    return _parse_model(xml, urdf_path)


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


def _default_tip(model: pin.Model, urdf_path: Path) -> str:
    """The tool link of the only chain, grippers left out (their joints stay at 0).

    The chain ends at its last joint that is not a gripper's (see :func:`_chain_ends`). Of the
    links fixed to that joint, a tool-like one (:data:`TOOL_LINKS`: ``tcp``, ``tool``, ``eef``,
    ``end_effector``, ``flange``, ``ee_link``, in this order) is the tip; else the link the
    first gripper joint hangs from; else the last of them.
    """
    if model.njoints < 2:
        raise URDFError(f"{urdf_path} has no movable joint; kinplan plans for arms with joints")
    ends = []
    for end in _chain_ends(model):
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


def build_chain(
    urdf_path: Path,
    tip: str | None = None,
    default_tip: str | None = None,
    locked_joints: Mapping[str, float] | None = None,
    base_pose: pin.SE3 | None = None,
    limits: Mapping[str, Mapping[str, float]] | None = None,
) -> Chain:
    """Read a URDF and build the model of the chain from its root to the tool frame.

    Args:
        urdf_path: The URDF file.
        tip: Tool frame (a link or frame name); default ``default_tip``, else the last link of
            the only chain (grippers left out).
        default_tip: The source's default tool frame (e.g. ``tool0`` for UR arms).
        locked_joints: Joints held at a value {name: value [rad or m]}, out of q.
        base_pose: Pose of the URDF's root in the world (a valid SE3); default identity.
        limits: Limit overrides {joint: {"lower", "upper", "velocity", "acceleration"}}.

    Raises:
        URDFError: a file that is not a usable URDF; a chain joint without usable limits (the
            message says how to give them or lock the joint); a floating joint inside the chain.
        FrameError: an unknown tool frame, or several chains and no ``tip``.
        InputError: malformed ``locked_joints``, ``limits`` or ``base_pose``.
    """
    root = read_urdf(urdf_path)
    base_frame = root_link(root, urdf_path)
    joints = _joints(root)
    locked = check_locked_joints(locked_joints, joints)
    overrides = check_limits(limits, joints)
    base = pin.SE3.Identity() if base_pose is None else base_pose
    continuous = {j.name for j in joints.values() if j.kind == "continuous"}
    for name, entry in overrides.items():
        if "lower" in entry or "upper" in entry:
            continuous.discard(name)  # bounded by the caller
    xml, placeholders = _edited_xml(root, joints, overrides)
    xml, uncoupled = _uncouple_mimics(root, joints, xml, urdf_path)
    model = _parse_model(xml, urdf_path)

    tip = tip or default_tip or _default_tip(model, urdf_path)
    chain = set(model.supports[model.frames[frame_id(model, tip, urdf_path)].parentJoint]) - {0}
    held_root = None
    hold: set[int] = set()
    for j in sorted(chain):
        name, kind = model.names[j], joints[model.names[j]].kind
        if kind in _HELD_ROOT:
            if model.parents[j] != 0:
                raise URDFError(
                    f"joint {name!r} of {urdf_path.name} is {kind} inside the chain; kinplan "
                    "holds a floating or planar joint only at the root (at base_pose)"
                )
            held_root = name
            hold.add(j)
        elif name in locked:
            hold.add(j)
    q_ref = pin.neutral(model)
    for name, value in locked.items():
        j = model.getJointId(name)
        if model.joints[j].nq == 1:
            q_ref[model.joints[j].idx_q] = value
    off_chain = {j for j in range(1, model.njoints) if j not in chain}
    _hold_uncoupled(model, joints, uncoupled, chain, hold, locked, q_ref, urdf_path)
    # a mimic joint whose master is held goes with it (Pinocchio needs both held)
    for j in range(1, model.njoints):
        relation = joints[model.names[j]].mimic
        if relation is not None and model.existJointName(relation[0]):
            if model.getJointId(relation[0]) in hold | off_chain:
                hold.add(j)
    if model.nq and len(chain - hold) == 0:
        raise URDFError(
            f"no movable joint between {base_frame!r} and {tip!r} in {urdf_path.name} (every "
            "joint of the chain is locked or held)"
        )
    to_hold = sorted(hold | off_chain)
    reduced = _reduced_model(model, to_hold, q_ref)
    _place_at(reduced, base)

    names = [reduced.names[j] for j in range(1, reduced.njoints)]
    independent = [n for n in names if reduced.joints[reduced.getJointId(n)].nq == 1]
    unusable = sorted(set(independent) & placeholders)
    if unusable:
        raise URDFError(
            f"joint(s) {', '.join(unusable)} of {urdf_path.name} have no <limit>; give them with "
            "limits={name: {'lower': .., 'upper': .., 'velocity': ..}} or lock them with "
            "locked_joints={name: value}"
        )
    lower = np.array(reduced.lowerPositionLimit, dtype=float)
    upper = np.array(reduced.upperPositionLimit, dtype=float)
    velocity = np.array(reduced.velocityLimit, dtype=float)
    acceleration = np.full(reduced.nq, np.inf)
    order = {name: reduced.joints[reduced.getJointId(name)].idx_q for name in independent}
    for name in continuous & set(order):
        lower[order[name]], upper[order[name]] = -np.inf, np.inf
    for name, entry in overrides.items():
        if name in order and "acceleration" in entry:
            acceleration[order[name]] = entry["acceleration"]
    velocity = np.where(velocity > 0, velocity, np.inf)
    bad = [n for n in independent if not lower[order[n]] < upper[order[n]]]
    if bad:
        shown = ", ".join(f"{n} [{lower[order[n]]:g}, {upper[order[n]]:g}]" for n in bad)
        raise URDFError(
            f"joint(s) of {urdf_path.name} without a usable range (lower < upper): {shown}; give "
            "them with limits={name: {'lower': .., 'upper': ..}} or lock them with "
            "locked_joints={name: value}"
        )
    mimic: dict[str, tuple[str, float, float]] = {}
    for n in names:
        relation = joints[n].mimic
        if reduced.joints[reduced.getJointId(n)].nq == 0 and relation is not None:
            mimic[n] = relation
    return Chain(
        model=reduced,
        name=root.get("name", urdf_path.stem),
        base_frame=base_frame,
        tip=tip,
        lower=lower,
        upper=upper,
        velocity=velocity,
        acceleration=acceleration,
        continuous=[n for n in independent if n in continuous],
        mimic=mimic,
        locked={n: v for n, v in locked.items()},
        held_root=held_root,
    )


def _hold_uncoupled(
    model: pin.Model,
    joints: Mapping[str, _Joint],
    uncoupled: set[str],
    chain: set[int],
    hold: set[int],
    locked: Mapping[str, float],
    q_ref: np.ndarray,
    urdf_path: Path,
) -> None:
    """Hold the mimic joints Pinocchio could not couple (see :func:`_uncouple_mimics`) at
    multiplier · master + offset, the master at its held value (its lock, else 0; a missing
    master counts as 0, as yourdfpy reads it); ``hold`` and ``q_ref`` are updated.

    Raises:
        URDFError: such a joint on the tool chain whose master moves with the chain.
    """
    for name in sorted(uncoupled):
        j = model.getJointId(name)
        relation = joints[name].mimic
        assert relation is not None  # an uncoupled joint is a mimic joint
        master, multiplier, offset = relation
        master_id = model.getJointId(master) if model.existJointName(master) else None
        if j in chain and master_id in chain - hold and name not in locked:
            raise URDFError(
                f"joint {name!r} of {urdf_path.name} mimics {master!r}, which comes after it "
                "in the tree: kinplan cannot couple them; lock one of them with "
                "locked_joints={name: value} or choose a tip before them"
            )
        if name not in locked:
            master_value = 0.0
            if master_id is not None and model.joints[master_id].nq == 1:
                master_value = float(q_ref[model.joints[master_id].idx_q])
            q_ref[model.joints[j].idx_q] = multiplier * master_value + offset
        hold.add(j)


def _place_at(model: pin.Model, base: pin.SE3) -> None:
    """Stand the model at ``base`` in the world: the placements of the joints and frames on the
    world (universe) are moved by it."""
    if base.isIdentity():
        return
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = base * model.jointPlacements[j]
    for k in range(len(model.frames)):
        if model.frames[k].parentJoint == 0 and model.frames[k].name != "universe":
            frame = model.frames[k]
            frame.placement = base * frame.placement
            model.frames[k] = frame
