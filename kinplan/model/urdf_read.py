"""Reading a URDF's XML: the file parsed (undeclared prefixes declared), its joints as written,
and Pinocchio's model of an XML text with the URDF parser's own messages kept.

Units as in the URDF: metres, radians. Every failure is a :class:`~kinplan.errors.URDFError` that
says what is wrong with the file.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pinocchio as pin

from kinplan.errors import URDFError

logger = logging.getLogger(__name__)

#: Joint types with one coordinate (the joints kinplan moves).
ONE_DOF = {"revolute", "prismatic", "continuous"}


@dataclass
class UrdfJoint:
    """One joint of the URDF's XML."""

    name: str
    kind: str
    parent: str
    child: str
    has_limit: bool
    mimic: tuple[str, float, float] | None
    #: ``<axis xyz>`` as written (None: no ``<axis>``, the URDF's default 1 0 0).
    axis: str | None = None
    #: ``<limit velocity>`` as written (None: no such attribute, or no ``<limit>``).
    velocity: str | None = None
    #: ``<limit drake:acceleration>`` as written (None: none).
    acceleration: str | None = None


# ------------------------------------------------------------------------------------ reading
#: Namespace of Drake's URDF extensions: ``drake:acceleration`` on a ``<limit>`` is the joint's
#: acceleration limit [rad/s² or m/s²].
DRAKE_NAMESPACE = "http://drake.mit.edu"
#: expat's error code for a prefix used without an ``xmlns:`` declaration.
_UNBOUND_PREFIX = 27
#: What may come before the root element: comments, processing instructions, a doctype.
_PROLOGUE = re.compile(rb"<!--.*?-->|<\?.*?\?>|<!DOCTYPE[^>]*>|<([A-Za-z_][\w.-]*)", re.S)


def read_urdf(urdf_path: Path) -> ET.Element:
    """The URDF's ``<robot>`` element, or a URDFError saying why it cannot be used.

    Prefixed names whose prefix the file never declares (airo-models' UR5e writes
    ``drake:acceleration="..."`` without ``xmlns:drake``) make the file namespace-invalid XML,
    which URDF readers without namespaces (urdfdom, yourdfpy) accept: such prefixes are declared
    on the root element before parsing (``drake`` as :data:`DRAKE_NAMESPACE`, the others as a
    placeholder namespace); every other XML error is reported as it is.
    """
    try:
        data = Path(urdf_path).read_bytes()
    except OSError as exc:
        raise URDFError(f"cannot read the URDF file {urdf_path}: {exc}") from exc
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        declared = _undeclared_prefixes_declared(data) if exc.code == _UNBOUND_PREFIX else None
        if declared is None:
            raise URDFError(f"{urdf_path} is not valid XML ({exc}); fix the file") from exc
        text, prefixes = declared
        try:
            root = ET.fromstring(text)
        except ET.ParseError as other:  # something else is wrong too (same line numbers)
            raise URDFError(f"{urdf_path} is not valid XML ({other}); fix the file") from other
        logger.info(
            "%s uses the XML prefix(es) %s without declaring them (xmlns:...): read as if declared",
            urdf_path,
            ", ".join(prefixes),
        )
    if root.tag != "robot":
        raise URDFError(f"{urdf_path} is not a URDF: its root element is <{root.tag}>, not <robot>")
    return root


def _undeclared_prefixes_declared(data: bytes) -> tuple[bytes, list[str]] | None:
    """The XML text ``data`` with the prefixes its element and attribute names use but never
    declare declared on its root element, and those prefixes; None when there is none (or no
    root element): the unbound prefix is then not one kinplan can bind."""
    used = set(re.findall(rb"<([A-Za-z_][\w.-]*):[A-Za-z_]", data))
    used |= set(re.findall(rb"\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=", data))
    declared = set(re.findall(rb"xmlns:([A-Za-z_][\w.-]*)\s*=", data))
    missing = sorted(used - declared - {b"xml", b"xmlns"})
    start = next((m for m in _PROLOGUE.finditer(data) if m.group(1) is not None), None)
    if not missing or start is None:
        return None
    names = [prefix.decode("ascii", errors="replace") for prefix in missing]
    declarations = b"".join(
        b' xmlns:%s="%s"'
        % (prefix, DRAKE_NAMESPACE.encode() if prefix == b"drake" else b"urn:kinplan:" + prefix)
        for prefix in missing
    )
    return data[: start.end()] + declarations + data[start.end() :], names


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


def joint_specs(root: ET.Element) -> dict[str, UrdfJoint]:
    joints = {}
    for element in root.findall("joint"):
        name = element.get("name", "")
        mimic = element.find("mimic")
        mimic_of = None
        if mimic is not None:
            mimic_of = (
                mimic.get("joint", ""),
                _mimic_number(mimic, "multiplier", "1", name),
                _mimic_number(mimic, "offset", "0", name),
            )
        parent, child = element.find("parent"), element.find("child")
        axis, limit = element.find("axis"), element.find("limit")
        joints[name] = UrdfJoint(
            name,
            element.get("type", ""),
            "" if parent is None else parent.get("link", ""),
            "" if child is None else child.get("link", ""),
            limit is not None,
            mimic_of,
            axis=None if axis is None else axis.get("xyz", "1 0 0"),
            velocity=None if limit is None else limit.get("velocity"),
            acceleration=None if limit is None else limit.get(f"{{{DRAKE_NAMESPACE}}}acceleration"),
        )
    return joints


def float_or_nan(text: str) -> float:
    """``text`` as a float (nan when it is not a number)."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def _mimic_number(mimic: ET.Element, key: str, default: str, joint: str) -> float:
    """The ``<mimic>`` attribute ``key`` of ``joint`` as a finite float."""
    text = mimic.get(key, default)
    value = float_or_nan(text)
    if not math.isfinite(value):
        raise URDFError(
            f"joint {joint!r}: its <mimic {key}={text!r}> is not a finite number; fix the file"
        )
    return value


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


def parse_model(xml: str, urdf_path: Path, mimic: bool = True) -> pin.Model:
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
