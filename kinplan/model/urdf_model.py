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

Everything wrong with the input is a :class:`~kinplan.errors.KinplanError` that says what to do:
a joint that kinplan moves needs a range (lower < upper) and a velocity limit > 0 (a URDF velocity
of 0, an exporter's "unknown", is refused, never read as "no limit"; a continuous joint without
``<limit>`` has an unknown speed, inf) and a direction (an ``<axis xyz="0 0 0">`` is refused); a
locked value must lie within its joint's limits; base poses, joint origins and frames lie within
:data:`MAX_OFFSET` of where they are placed. ``drake:acceleration`` on a ``<limit>`` is read as
the joint's acceleration limit; prefixes a file uses without declaring them (airo-models' UR5e)
are declared before parsing (:func:`read_urdf`).

The XML is read by :mod:`kinplan.model.urdf_read`; the tool frame is chosen by
:mod:`kinplan.model.urdf_frames`.
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.errors import InputError, URDFError
from kinplan.model.urdf_frames import default_tool_frame, frame_id
from kinplan.model.urdf_read import (
    ONE_DOF,
    UrdfJoint,
    float_or_nan,
    joint_specs,
    parse_model,
    read_urdf,
    root_link,
)

logger = logging.getLogger(__name__)

#: Joint limits written into the URDF for continuous joints read as revolute [rad]; kinplan's own
#: limits for them are ±inf.
UNBOUNDED = 1e9
#: Largest distance [m] of a base pose from the world origin, of a joint or frame from its
#: parent, and of a prismatic joint's limits from 0: 10 km. Positions there carry a rounding
#: of 2e-12 m, far below every tolerance; no robot cell is larger (a base at 1e300 m
#: overflows the kinematics).
MAX_OFFSET = 1e4
#: Keys of a ``limits=`` entry.
LIMIT_KEYS = ("lower", "upper", "velocity", "acceleration")
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


# ------------------------------------------------------------------------------ arguments
def check_locked_joints(locked_joints: object, joints: Mapping[str, UrdfJoint]) -> dict[str, float]:
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
        if joint.kind not in ONE_DOF:
            raise InputError(
                f"locked_joints: joint {name!r} is {joint.kind}; only revolute, continuous and "
                "prismatic joints can be locked at a value (a floating or planar root joint is "
                "held at base_pose)"
            )
        locked[name] = checks.number(value, f"locked_joints[{name!r}]", unit="rad or m")
    return locked


def check_limits(limits: object, joints: Mapping[str, UrdfJoint]) -> dict[str, dict[str, float]]:
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
        if joints[name].kind == "continuous" and len({"lower", "upper"} & set(values)) == 1:
            raise InputError(
                f"limits[{name!r}]: {name} is a continuous joint (unbounded); give both 'lower' "
                "and 'upper' to bound it, or neither"
            )
        if "lower" in values and "upper" in values and not values["lower"] < values["upper"]:
            raise InputError(
                f"limits[{name!r}]: lower {values['lower']} must be below upper {values['upper']}"
            )
        checked[name] = values
    return checked


def _known_joint(name: object, joints: Mapping[str, UrdfJoint], what: str) -> UrdfJoint:
    if not isinstance(name, str) or name not in joints:
        movable = [j.name for j in joints.values() if j.kind != "fixed"]
        raise InputError(
            f"{what}: no joint {name!r} in the URDF; its movable joints: {', '.join(movable)}"
        )
    return joints[name]


# ------------------------------------------------------------------------------ the chain
def _edited_xml(
    root: ET.Element, joints: Mapping[str, UrdfJoint], limits: Mapping[str, Mapping[str, float]]
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
        if kind not in ONE_DOF:
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
    root: ET.Element, joints: Mapping[str, UrdfJoint], xml: str, urdf_path: Path
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
        if joint.mimic is not None and joint.kind in ONE_DOF  # Talos has fixed "mimic" joints
    }
    if not mimics:
        return xml, set()
    walk = list(parse_model(xml, urdf_path, mimic=False).names)
    order = {name: k for k, name in enumerate(walk)}
    uncoupled = set()
    for name, (master, _, _) in mimics.items():
        usable = (
            master in joints
            and joints[master].kind in ONE_DOF
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
    model, joints = _whole_model(Path(urdf_path))
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
    return _whole_model(Path(urdf_path))[0]


def _whole_model(urdf_path: Path) -> tuple[pin.Model, dict[str, UrdfJoint]]:
    """:func:`full_model` and the URDF's joints as written."""
    root = read_urdf(urdf_path)
    joints = joint_specs(root)
    xml, _ = _edited_xml(root, joints, {})
    xml, _ = _uncouple_mimics(root, joints, xml, urdf_path)
    return parse_model(xml, urdf_path), joints


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
    joints = joint_specs(root)
    locked = check_locked_joints(locked_joints, joints)
    overrides = check_limits(limits, joints)
    base = pin.SE3.Identity() if base_pose is None else base_pose
    continuous = {j.name for j in joints.values() if j.kind == "continuous"}
    for name, entry in overrides.items():
        if "lower" in entry or "upper" in entry:
            continuous.discard(name)  # bounded by the caller
    xml, placeholders = _edited_xml(root, joints, overrides)
    xml, uncoupled = _uncouple_mimics(root, joints, xml, urdf_path)
    model = parse_model(xml, urdf_path)

    _check_offsets(model, base, urdf_path)
    tip = tip or default_tip or default_tool_frame(model, urdf_path)
    chain = set(model.supports[model.frames[frame_id(model, tip, urdf_path)].parentJoint]) - {0}
    _check_axes(model, joints, chain, urdf_path)
    _check_locked_values(model, joints, locked, placeholders | continuous)
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
    # joint → [(the limits= keys that fix it, what is unusable)]
    problems: dict[str, list[tuple[tuple[str, ...], str]]] = {}
    for name in independent:
        k, joint, given = order[name], joints[name], overrides.get(name, {})
        found = problems.setdefault(name, [])
        if not lower[k] < upper[k]:
            found.append((("lower", "upper"), f"range [{lower[k]:g}, {upper[k]:g}]"))
        elif joint.kind == "prismatic" and not max(-lower[k], upper[k]) <= MAX_OFFSET:
            travel = f"travel [{lower[k]:g}, {upper[k]:g}] m beyond ±{MAX_OFFSET:g} m"
            found.append((("lower", "upper"), travel))
        if "velocity" not in given and joint.has_limit:
            if joint.velocity is None:
                found.append((("velocity",), "no velocity in its <limit>"))
            elif not velocity[k] > 0:  # exporters write 0 for 'unknown': not 'no limit'
                found.append((("velocity",), f"velocity {joint.velocity}"))
        elif not velocity[k] > 0:  # a continuous joint without <limit>: speed unknown
            velocity[k] = np.inf
        if "acceleration" in given:
            acceleration[k] = given["acceleration"]
        elif joint.acceleration is not None:
            value = float_or_nan(joint.acceleration)
            if value > 0 and math.isfinite(value):
                acceleration[k] = value
            else:
                found.append((("acceleration",), f"drake:acceleration {joint.acceleration}"))
    problems = {name: found for name, found in problems.items() if found}
    if problems:
        shown = "; ".join(
            f"{name} ({', '.join(what for _, what in found)})" for name, found in problems.items()
        )
        example = ", ".join(
            f"{name!r}: {{"
            + ", ".join(f"{key!r}: .." for key in LIMIT_KEYS if any(key in k for k, _ in found))
            + "}"
            for name, found in problems.items()
        )
        raise URDFError(
            f"joint(s) of {urdf_path.name} without usable limits (lower < upper, a prismatic "
            f"joint's within ±{MAX_OFFSET:g} m, velocity and acceleration > 0): {shown}; give them "
            f"with limits={{{example}}} [rad or m, per s, per s²] or lock them with "
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


def _check_offsets(model: pin.Model, base: pin.SE3, urdf_path: Path) -> None:
    """Refuse a base pose, joint origin or frame further than :data:`MAX_OFFSET` from where it
    is placed (or not finite)."""
    distance = math.hypot(*base.translation)
    if not distance <= MAX_OFFSET:
        raise InputError(
            f"base_pose puts the robot {distance:.4g} m from the world origin; kinplan accepts "
            f"base poses within {MAX_OFFSET:g} m of it (give the base's position in metres, in "
            "the frame of the work cell)"
        )
    placed = [
        (f"joint {model.names[j]!r}", model.jointPlacements[j]) for j in range(1, model.njoints)
    ]
    placed += [(f"frame {f.name!r}", f.placement) for f in model.frames if f.name != "universe"]
    for what, placement in placed:
        distance = math.hypot(*placement.translation)
        if not distance <= MAX_OFFSET:
            raise URDFError(
                f"{what} of {urdf_path.name} is placed {distance:.4g} m from its parent (its "
                f"<origin xyz>); kinplan accepts offsets up to {MAX_OFFSET:g} m: fix the file"
            )


def _check_axes(
    model: pin.Model, joints: Mapping[str, UrdfJoint], chain: set[int], urdf_path: Path
) -> None:
    """Refuse a joint of the chain (locked or not) whose ``<axis xyz>`` is 0 0 0: it would
    move nothing."""
    for j in sorted(chain):
        joint = joints.get(model.names[j])
        if joint is None or joint.kind not in ONE_DOF or joint.axis is None:
            continue
        axis = np.array([float_or_nan(v) for v in joint.axis.split()])
        if axis.size == 3 and np.all(axis == 0.0):
            raise URDFError(
                f"joint {joint.name!r} of {urdf_path.name} has the axis 0 0 0, about or along "
                "which nothing moves; write its direction in its <axis xyz> (e.g. "
                '<axis xyz="0 0 1"/>)'
            )


def _check_locked_values(
    model: pin.Model,
    joints: Mapping[str, UrdfJoint],
    locked: Mapping[str, float],
    unbounded: set[str],
) -> None:
    """Refuse a locked value outside its joint's limits (the URDF's, or ``limits=``); joints
    without usable limits (none, lower ≥ upper, continuous: ``unbounded``) take any value."""
    for name, value in locked.items():
        if name in unbounded or not model.existJointName(name):
            continue
        joint_model = model.joints[model.getJointId(name)]
        if joint_model.nq != 1:
            continue
        lower = float(model.lowerPositionLimit[joint_model.idx_q])
        upper = float(model.upperPositionLimit[joint_model.idx_q])
        if lower < upper and not lower <= value <= upper:
            unit = "m" if joints[name].kind == "prismatic" else "rad"
            raise InputError(
                f"locked_joints[{name!r}] = {value:g} {unit} is outside the joint's limits "
                f"[{lower:g}, {upper:g}] {unit}; lock it within them (or change them with "
                f"limits={{{name!r}: {{'lower': .., 'upper': ..}}}})"
            )


def _hold_uncoupled(
    model: pin.Model,
    joints: Mapping[str, UrdfJoint],
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
