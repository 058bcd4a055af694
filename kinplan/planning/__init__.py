"""Planners that find motions (not only check them): collision-free transit moves in joint space.

* :func:`free_motion` — a timed joint motion around a work cell's obstacles, from a start
  configuration to a joint goal or a tool pose, every segment certified by the cell's motion
  check (:mod:`kinplan.planning.planner`);
* :class:`MotionPlan` — its result (a :class:`kinplan.trajectory.motion.SampledMotion`), with
  :class:`PlanEvent` when it failed.

Inside: ``plan`` (the result) → ``goals`` (goal configurations) → ``search`` (RRT-Connect on
certified edges) → ``shortcut`` → ``timing`` (time-optimal timing, the timed path checked
again) → ``planner`` (:func:`free_motion`).

The seam planner, being Cartesian, lives beside the follower in :mod:`cartesian`.
"""

from __future__ import annotations

from kinplan.planning.plan import STATUSES, MotionPlan, PlanEvent, WaypointArray
from kinplan.planning.planner import free_motion

__all__ = ["STATUSES", "MotionPlan", "PlanEvent", "WaypointArray", "free_motion"]
