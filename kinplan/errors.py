"""Exceptions raised by kinplan.

Every error the library raises on purpose derives from :class:`KinplanError`. Messages say what
was wrong and how to fix it. Expected outcomes (an unreachable target, a singular path) are not
exceptions: they are reported as results with a status.
"""

from __future__ import annotations


class KinplanError(Exception):
    """Base class of every error kinplan raises on purpose."""


class RobotNotFoundError(KinplanError):
    """A robot source (bundled name, example-robot-data name or file path) does not exist."""


class URDFError(KinplanError):
    """A URDF file could not be parsed or does not describe a usable serial arm."""


class FrameError(KinplanError):
    """A frame or link name does not exist in the robot model."""


class InputError(KinplanError, ValueError):
    """An argument has the wrong shape, a non-finite value or an impossible value."""


class InfeasibleError(KinplanError):
    """A motion cannot satisfy the given limits (for example an acceleration that is too low)."""


class ViewerError(KinplanError):
    """The MeshCat viewer could not be started, reached or written."""
