"""Inverse kinematics: numerical (Levenberg–Marquardt on Pinocchio) and closed forms.

Modules, each importing only those before it:

* :mod:`~kinplan.ik.numeric` — :class:`IKSolver` (damped least squares with the joint limits as
  an active set, Halton restarts), :class:`IKResult`, tolerances, :func:`halton`; its attempts
  on serial revolute arms compiled in :mod:`~kinplan.ik.numeric_kernel` (numba, loaded on the
  first numerical solve);
* :mod:`~kinplan.ik.screws` — screw geometry shared by the closed forms (joint screws at q = 0,
  rotations, the choice among 2π equivalents, tolerances);
* :mod:`~kinplan.ik.base` — the :class:`AnalyticIK` protocol, the :class:`ClosedFormIK` base
  class (nearest solution, batches along a path) and :func:`self_check` against FK;
* :mod:`~kinplan.ik.planar` — planar 2R;
* the UR family, :class:`URIK`: :mod:`~kinplan.ik.ur_geometry` (the arm read from the model) →
  :mod:`~kinplan.ik.ur_single` (one pose in plain floats) → :mod:`~kinplan.ik.ur_many` (the same
  formulas over many poses) → :mod:`~kinplan.ik.ur` (the solver); both forms compiled in
  :mod:`~kinplan.ik.ur_kernel` (numba, loaded with the first solver);
* panda-type 7-joint arms, :class:`PandaIK` (closed form for a given θ7, θ7 searched):
  :mod:`~kinplan.ik.panda_geometry` (the arm read from the model, float 3-vector arithmetic) →
  :mod:`~kinplan.ik.panda_subproblems` (Paden–Kahan subproblems 1 and 2) →
  :mod:`~kinplan.ik.panda_intervals` (the θ7 search's intervals) →
  :mod:`~kinplan.ik.panda_batch` (the search over many poses) → :mod:`~kinplan.ik.panda` (the
  solver, :func:`panda_solver_for`); its whole θ7 search (one pose, and a loop over poses)
  compiled in :mod:`~kinplan.ik.panda_kernel` (numba, on :mod:`kinplan.compiled` and
  :mod:`~kinplan.ik.screws`, loaded on first use);
* spherical-wrist 6R arms (ABB, KUKA, Fanuc, ...), :class:`SphericalWristIK`, by Paden–Kahan
  subproblems (IK-Geo): :mod:`~kinplan.ik.subproblems` (subproblems 1, 2, 4 on arrays) →
  :mod:`~kinplan.ik.spherical_wrist_geometry` (the structure read from the screw axes, or why
  not) → :mod:`~kinplan.ik.spherical_wrist_kernel` (one pose, numba, loaded with the first
  solver) → :mod:`~kinplan.ik.spherical_wrist` (the solver, vectorised over poses);
* 6R arms whose URDF rounds a spherical wrist (axes 4, 5, 6 missing one point, or axes 2, 3
  missing parallel, by at most 1e-4 m or rad: compas-fab's IRB4600, Doosan's, a Denso VS060),
  :class:`~kinplan.ik.near_wrist.NearWristIK`: the spherical-wrist closed form on the idealised
  arm, each solution polished by Newton's method on the URDF's screws and certified, the exact
  1-D search near singularities: :mod:`~kinplan.ik.near_wrist_geometry` →
  :mod:`~kinplan.ik.near_wrist_kernel` (numba) → :mod:`~kinplan.ik.near_wrist` (the solver);
* 6R arms whose axes 4 and 5 meet with axis 6 offset (rtb-data's IRB140, Kinova's Gen3),
  :class:`~kinplan.ik.wrist_offset.OffsetWristIK`, IK-Geo's 1-D search over θ6:
  :mod:`~kinplan.ik.wrist_offset_geometry` → :mod:`~kinplan.ik.wrist_offset_branches` (the
  branch residuals) → :mod:`~kinplan.ik.wrist_offset_search` (their roots) →
  :mod:`~kinplan.ik.wrist_offset_kernel` (solutions, FK check, nearest; numba) →
  :mod:`~kinplan.ik.wrist_offset` (the solver);
* spherical-wrist 6R arms whose axes 2 and 3 are not parallel (axes 1, 2 or axes 2, 3 meeting,
  or neither), :class:`~kinplan.ik.spherical_general.GeneralWristIK`, IK-Geo's spherical forms
  by subproblems 3, 2, 1 or subproblem 5 (a quartic):
  :mod:`~kinplan.ik.spherical_general_geometry` → :mod:`~kinplan.ik.spherical_general_quartic`
  (real roots; numba) → :mod:`~kinplan.ik.spherical_general_positions` (θ1–θ3; numba) →
  :mod:`~kinplan.ik.spherical_general_kernel` (the wrist, FK check, nearest; numba) →
  :mod:`~kinplan.ik.spherical_general` (the solver);
* 6R arms with three parallel axes 2 ∥ 3 ∥ 4 and axes 1, 5, 6 anywhere (Unitree's Z1, UR-like
  arms with a skewed or offset wrist), :class:`~kinplan.ik.three_parallel.ThreeParallelIK`,
  IK-Geo's subproblem-6 closed form: :mod:`~kinplan.ik.three_parallel_geometry` →
  :mod:`~kinplan.ik.three_parallel_quartic` (real roots of a quartic; numba) →
  :mod:`~kinplan.ik.three_parallel_kernel` (solutions, FK check, nearest; numba) →
  :mod:`~kinplan.ik.three_parallel` (the solver);
* :mod:`~kinplan.ik.batch_kinematics` (FK and Jacobians of many configurations, its FK check
  compiled in :mod:`~kinplan.ik.batch_kinematics_kernel`) → :mod:`~kinplan.ik.batch` (what
  ``Robot.ik_batch`` runs: the closed forms over many poses, or the numerical solve compiled
  target by target, :func:`kinplan.ik.numeric_kernel.solve_many`);
* :mod:`~kinplan.ik.closed_form` — :func:`analytic_solver_for`: which closed form a robot has
  (:func:`closed_form_report`: and why none fits).

The closed forms and :mod:`~kinplan.ik.closed_form` load on first use (``from kinplan.ik import
URIK`` works as before): commands that need none start faster.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from kinplan._lazy import lazy_attributes
from kinplan.ik.base import AnalyticIK, ClosedFormIK, self_check
from kinplan.ik.numeric import (
    Evaluation,
    IKResult,
    IKSolver,
    finite_bounds,
    frobenius_tolerance,
    halton,
)
from kinplan.ik.screws import wrap_angle

if TYPE_CHECKING:  # the closed forms load on first use (see __getattr__)
    from kinplan.ik.closed_form import analytic_solver_for, closed_form_report
    from kinplan.ik.near_wrist import NearWristIK
    from kinplan.ik.panda import PandaIK, panda_solver_for
    from kinplan.ik.planar import Planar2RIK
    from kinplan.ik.spherical_general import GeneralWristIK
    from kinplan.ik.spherical_wrist import SphericalWristIK
    from kinplan.ik.three_parallel import ThreeParallelIK
    from kinplan.ik.ur import URIK
    from kinplan.ik.wrist_offset import OffsetWristIK

#: Names loaded on first use, by module: a robot that needs no closed form (``kinplan info``,
#: numerical arms) does not import them.
_LAZY = {
    "analytic_solver_for": "closed_form",
    "closed_form_report": "closed_form",
    "NearWristIK": "near_wrist",
    "PandaIK": "panda",
    "panda_solver_for": "panda",
    "Planar2RIK": "planar",
    "GeneralWristIK": "spherical_general",
    "SphericalWristIK": "spherical_wrist",
    "ThreeParallelIK": "three_parallel",
    "URIK": "ur",
    "OffsetWristIK": "wrist_offset",
}


__getattr__ = lazy_attributes(__name__, _LAZY)


__all__ = [
    "Evaluation",
    "AnalyticIK",
    "ClosedFormIK",
    "GeneralWristIK",
    "IKResult",
    "IKSolver",
    "NearWristIK",
    "OffsetWristIK",
    "PandaIK",
    "Planar2RIK",
    "SphericalWristIK",
    "ThreeParallelIK",
    "URIK",
    "analytic_solver_for",
    "closed_form_report",
    "finite_bounds",
    "frobenius_tolerance",
    "halton",
    "panda_solver_for",
    "self_check",
    "wrap_angle",
]
