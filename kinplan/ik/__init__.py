"""Inverse kinematics: numerical (Levenberg–Marquardt on Pinocchio) and closed forms.

Modules, each importing only those before it:

* :mod:`~kinplan.ik.numeric` — :class:`IKSolver` (damped least squares with the joint limits as
  an active set, Halton restarts), :class:`IKResult`, tolerances, :func:`halton`;
* :mod:`~kinplan.ik.screws` — screw geometry shared by the closed forms (joint screws at q = 0,
  rotations, the choice among 2π equivalents, tolerances);
* :mod:`~kinplan.ik.base` — the :class:`AnalyticIK` protocol, the :class:`ClosedFormIK` base
  class (nearest solution, batches along a path) and :func:`self_check` against FK;
* :mod:`~kinplan.ik.planar` — planar 2R; :mod:`~kinplan.ik.ur` — the UR family;
  :mod:`~kinplan.ik.panda` — panda-type 7-joint arms for a given θ7;
* :mod:`~kinplan.ik.closed_form` — :func:`analytic_solver_for`: which closed form a robot has.
"""

from __future__ import annotations

from kinplan.ik.base import AnalyticIK, ClosedFormIK, self_check
from kinplan.ik.closed_form import analytic_solver_for
from kinplan.ik.numeric import (
    Evaluation,
    IKResult,
    IKSolver,
    finite_bounds,
    frobenius_tolerance,
    halton,
)
from kinplan.ik.panda import PandaIK, panda_solver_for
from kinplan.ik.planar import Planar2RIK
from kinplan.ik.screws import wrap_angle
from kinplan.ik.ur import URIK

__all__ = [
    "Evaluation",
    "AnalyticIK",
    "ClosedFormIK",
    "IKResult",
    "IKSolver",
    "PandaIK",
    "Planar2RIK",
    "URIK",
    "analytic_solver_for",
    "finite_bounds",
    "frobenius_tolerance",
    "halton",
    "panda_solver_for",
    "self_check",
    "wrap_angle",
]
