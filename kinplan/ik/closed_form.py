"""Closed-form inverse kinematics for arms whose geometry allows it: planar 2R and the UR family
here; which closed form an arm has (:func:`closed_form_report`: also the spherical-wrist,
three-parallel-axis, 1-D search and panda-type forms of their own modules).

The geometry is read from the robot's Pinocchio model, never from a table of numbers: at q = 0
every joint is a screw in the world frame (a unit axis ``u`` through a point ``p``, taken from the
world Jacobian), and the tool pose is ``M``. Forward kinematics is then the product of
exponentials ``T(q) = exp(S1 q1) ⋯ exp(Sn qn) M``, and the solutions below are written in those
world-frame terms, so base offsets, axis signs and tool-frame rotations of any URDF are handled
without a Denavit–Hartenberg table.

* **Planar 2R**: two parallel revolute axes; both elbow branches.
* **UR family** (UR3/UR5/UR10 and any arm with the same structure): revolute joints with axis 1
  perpendicular to three parallel axes 2–4, axis 5 perpendicular to them and axes 5 and 6
  intersecting at right angles (the "wrist centre" ``c``). The solution follows Hawkins
  (*Analytic Inverse Kinematics for the Universal Robots UR-5/UR-10 Arms*, 2013), in screw form:

  1. θ1 from the wrist centre: joints 2–6 cannot move ``c`` along the shoulder-axis direction
     ``n(θ1)``, so ``n(θ1)·(c − p1)`` equals its value at q = 0 (two shoulder branches);
  2. θ5 from the tool axis: ``n(θ1)·z6 = cos(θ5 − δ)`` (two wrist branches);
  3. θ6 from the rest of the orientation (free at the wrist singularity sin(θ5 − δ) = 0);
  4. θ2, θ3 from a planar 2R problem in the plane of axes 2–4 (two elbow branches), θ4 from the
     remaining planar rotation.

Every solver is vectorised over poses. ``nearest_batch`` follows one branch along a sampled path
(each sample the solution nearest the previous one) without a Python loop per sample: the
branch-to-branch transitions of consecutive samples are composed by a doubling scan (only
exactly singular samples, whose free joint depends on the previous sample, are solved one by
one).

A single pose (:meth:`URIK.nearest`, :meth:`URIK.solutions`) does not go through that machinery:
numpy's per-call overhead dominates arrays of one pose (about 380 small calls, 250 µs). The same
formulas are written in plain floats instead, in orthonormal shoulder and wrist frames of the
arm at q = 0 (one numpy product per pose), with a branch-and-bound choice of the nearest branch
(about 20–30 µs). Poses near a singularity (|sin(θ5 − δ)| < 1e-4, elbow within ~1.4e-4 rad of
straight or folded, wrist centre within ~1e-4·|d4| of the shoulder-singular cylinder), where the
two paths' roundings would give visibly different (equally valid) angles and where θ6 may be
free, are left to the batch path.

Joint angles are equivalent modulo 2π; :meth:`solutions` lists each geometric solution once (its
representative within the limits closest to mid-range), :meth:`nearest` picks per joint the
representative within the limits closest to the reference.
"""

from __future__ import annotations

import logging

import numpy as np

from kinplan.ik.base import AnalyticIK, ClosedFormIK, self_check
from kinplan.ik.near_wrist import NearWristIK
from kinplan.ik.near_wrist_geometry import near_wrist_geometry
from kinplan.ik.panda import panda_solver_for
from kinplan.ik.planar import planar_2r_solver
from kinplan.ik.screws import Screws, screws_at_zero
from kinplan.ik.spherical_general import GeneralWristIK
from kinplan.ik.spherical_general_geometry import NOT_PARALLEL, general_wrist_geometry
from kinplan.ik.spherical_wrist import SphericalWristIK
from kinplan.ik.spherical_wrist_geometry import wrist_geometry
from kinplan.ik.three_parallel import ThreeParallelIK
from kinplan.ik.three_parallel_geometry import three_parallel_geometry
from kinplan.ik.ur import URIK, ur_geometry
from kinplan.ik.wrist_offset import OffsetWristIK
from kinplan.ik.wrist_offset_geometry import offset_wrist_geometry
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)


def analytic_solver_for(robot: Arm, weights: np.ndarray | None = None) -> AnalyticIK | None:
    """A closed-form IK solver for ``robot`` when its geometry allows one, else None.

    Planar 2R arms (two parallel revolute axes), UR-type arms (see :func:`ur_geometry`),
    spherical-wrist 6R arms (axes 4, 5, 6 meeting, axes 2 ∥ 3; see
    :func:`~kinplan.ik.spherical_wrist_geometry.wrist_geometry`; with axes 2 ∦ 3, axes 1, 2
    or axes 2, 3 meeting, or neither and subproblem 5; see
    :func:`~kinplan.ik.spherical_general_geometry.general_wrist_geometry`), 6R arms with axes
    2 ∥ 3 ∥ 4 and axes 1, 5, 6 anywhere (subproblem 6; see
    :func:`~kinplan.ik.three_parallel_geometry.three_parallel_geometry`), 6R arms with axes 4
    and 5 meeting and axis 6 offset (a 1-D search over θ6; see
    :func:`~kinplan.ik.wrist_offset_geometry.offset_wrist_geometry`) and panda-type 7-joint arms
    (closed form for a given θ7, θ7 searched; :mod:`kinplan.ik.panda`) are recognised from the
    Pinocchio model's joint placements and tool frame; the solver is then checked against
    Pinocchio's forward kinematics on a few random configurations. Any other arm gives None,
    and the caller falls back to the numerical solver (:meth:`kinplan.Robot.ik`).

    Args:
        robot: A :class:`kinplan.Robot`.
        weights: Joint weights w of the distance Σ wᵢ Δqᵢ² by which :meth:`nearest` and
            :meth:`nearest_batch` choose (default: all ones), shape (nq,).
    """
    return closed_form_report(robot, weights)[0]


def closed_form_report(
    robot: Arm, weights: np.ndarray | None = None
) -> tuple[AnalyticIK | None, str]:
    """:func:`analytic_solver_for` with what it found: (solver or None, a sentence naming the
    closed form, or why the arm has none), e.g. ``"numerical: no closed form (no spherical
    wrist: axes 4 and 5 do not intersect (2.0e-02 m apart); not the UR structure)"``."""
    if robot.nq == 7:  # panda-type arms: semi-analytic, θ7 searched (see kinplan.ik.panda)
        panda = panda_solver_for(robot, weights)
        if panda is not None:
            return panda, "closed form: panda-type 7-joint arm (θ7 searched)"
        return None, _NUMERICAL + "a 7-joint arm without the panda's structure)"
    if robot.nq not in (2, 6):
        return None, _NUMERICAL + f"{robot.nq} joints; closed forms are for 2, 6 and 7)"
    screws = screws_at_zero(robot)
    if screws is None:
        return None, _NUMERICAL + "not a serial chain of revolute joints)"
    solver: ClosedFormIK | None
    if robot.nq == 2:
        solver = planar_2r_solver(robot, screws, weights)
        description = "closed form: planar 2R"
        reason = "the two axes are not parallel"
    else:
        solver, description, reason = _six_joint_form(robot, screws, weights)
    if solver is None:
        return None, _NUMERICAL + reason + ")"
    if not self_check(
        robot,
        lambda pose, q: solver.solutions(pose.translation, pose.rotation),
        answers_every_pose=solver.answers_every_pose,
    ):
        logger.debug("closed-form IK of %s disagrees with its forward kinematics", robot.name)
        form = description.removeprefix("closed form: ")
        return None, _NUMERICAL + f"the {form} disagrees with the model's FK)"
    return solver, description


def _six_joint_form(
    robot: Arm, screws: Screws, weights: np.ndarray | None
) -> tuple[ClosedFormIK | None, str, str]:
    """The first 6R closed form whose structure the screws have, tried in order (UR family,
    spherical wrist with axes 2 ∥ 3, spherical wrist with axes 2 ∦ 3, three parallel axes,
    the 1-D search): (solver, its description, "") or (None, "", why each one does not fit)."""
    lower, upper = robot.lower, robot.upper
    geometry = ur_geometry(screws)
    if geometry is not None:
        ur = URIK(geometry, lower, upper, weights, screws=screws)
        description = "closed form: UR family (axes 2 ∥ 3 ∥ 4)"
        if ur._fast is None:
            description += ", without the single-pose fast path (axes not orthonormal)"
        return ur, description, ""
    wrist, why = wrist_geometry(screws)
    if wrist is not None:
        return SphericalWristIK(wrist, lower, upper, weights), SphericalWristIK.description, ""
    reasons = [why]
    solver: ClosedFormIK
    near, near_why = near_wrist_geometry(screws)  # a spherical wrist the URDF's numbers round
    if near is not None:
        solver = NearWristIK(near, lower, upper, weights)
        return solver, solver.description, ""
    reasons.append(f"not a rounded spherical wrist: {near_why}")
    if why == NOT_PARALLEL:  # a spherical wrist, axes 2 ∦ 3: IK-Geo's other forms
        general, why = general_wrist_geometry(screws)
        if general is not None:
            solver = GeneralWristIK(general, lower, upper, weights)
            return solver, solver.description, ""
        reasons.append(f"no IK-Geo spherical form: {why}")
    parallel, why = three_parallel_geometry(screws)  # axes 2 ∥ 3 ∥ 4: subproblem 6
    if parallel is not None:
        solver = ThreeParallelIK(parallel, lower, upper, weights)
        return solver, solver.description, ""
    reasons.append(f"not three parallel axes: {why}")
    offset, why = offset_wrist_geometry(screws)  # axes 4, 5 meeting: the 1-D search
    if offset is not None:
        solver = OffsetWristIK(offset, lower, upper, weights)
        return solver, solver.description, ""
    reasons += [f"no 1-D search form: {why}", "not the UR structure"]
    return None, "", "; ".join(reasons)


_NUMERICAL = "numerical (Levenberg–Marquardt): no closed form ("
