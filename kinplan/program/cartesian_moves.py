"""Cartesian moves of :class:`~kinplan.program.MotionBuilder`: ``lin``, ``circ``, seams of
lines and arcs (blended, woven, with torch angles, their roll planned by
:func:`cartesian.plan_seam`) and any :class:`cartesian.Path`, each followed by
:func:`cartesian.follow` from the current configuration, on whole periods of the builder's
``dt``, and recorded by :class:`~kinplan.program.builder_base.BuilderBase`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

import cartesian
from kinplan.errors import KinplanError
from kinplan.program.builder_base import BuilderBase
from kinplan.program.plan import MoveReport
from kinplan.program.remedies import (
    SMALL_GAP,
    jump_reason,
    program_remedy,
    start_gap_reason,
    start_turn_reason,
    torch_start_reason,
)
from kinplan.program.schema import (
    DEFAULT_TOOL_SPEED,
    JOIN_TOLERANCE,
    TorchSpec,
    WeaveSpec,
)
from kinplan.program.seams import (
    TORCH_START_TOLERANCE,
    Goal,
    SeamPiece,
    goal_from,
    seam_path,
    start_turn,
    torch_path,
    weave_path,
)

__all__ = ["CartesianMoves"]


class CartesianMoves(BuilderBase):
    """The Cartesian moves of :class:`~kinplan.program.MotionBuilder`."""

    def lin(
        self,
        goal: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "lin",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Straight tool line from the current pose to ``goal`` (SE3 or position [m]).

        A position keeps the current orientation (arms with ≥ 6 joints) or is position-only.
        ``speed`` is the tool cruise speed [m/s] (default
        :data:`~kinplan.program.DEFAULT_TOOL_SPEED`); ``weave``, ``torch`` and
        ``max_acceleration`` as in :meth:`seam`.
        """
        return self.seam(
            [("lin", goal, None)], duration=duration, speed=speed, profile=profile, weave=weave,
            torch=torch, label=label, key=key, kind="lin", max_acceleration=max_acceleration,
        )  # fmt: skip

    def circ(
        self,
        goal: Goal,
        via: Goal,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "circ",
        key: str | None = None,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Arc of the circle through the current tool position, ``via`` and ``goal``.

        The tool orientation moves by slerp from the current one to the goal's (the via point's
        orientation is not used). Options as in :meth:`lin`.
        """
        return self.seam(
            [("circ", goal, via)], duration=duration, speed=speed, profile=profile, weave=weave,
            torch=torch, label=label, key=key, kind="circ", max_acceleration=max_acceleration,
        )  # fmt: skip

    def seam(
        self,
        pieces: Sequence[SeamPiece],
        *,
        blend: float | Sequence[float] = 0.0,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec | None = None,
        label: str = "seam",
        key: str | None = None,
        kind: str = "seam",
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Lines and arcs one after the other as one Cartesian motion, corners blended.

        Each piece starts where the previous one ends; a goal given as a position keeps the
        orientation the tool has there (arms with ≥ 6 joints). The corners are blended within
        ``blend`` (:func:`cartesian.blend_corners`), so the tool passes them at cruise speed.

        Args:
            pieces: (``"lin"``, goal, None) or (``"circ"``, goal, via) for each piece.
            blend: Blend radius [m] at every corner, or one per corner (0: a sharp corner).
            duration, speed, profile: As in :meth:`follow`.
            weave: The torch oscillates across the seam (:class:`cartesian.Weave`, wavelength
                = travel speed / frequency).
            torch: The tool held at welding angles to the seam
                (:class:`cartesian.TorchOrientation`); the seam must start with the tool at
                that orientation.
            label, key, kind: For reports.
            max_acceleration: Joint acceleration limits of this move [rad/s²], one number or
                one per joint (the robot's own still hold); default the builder's. Checked at
                every sample by :func:`cartesian.follow`.
        """
        self._check_open()
        start, flat = self.tool_pose(), self.robot.default_position_only()
        path = self._build_path(kind, label, key, lambda: seam_path(pieces, blend, start, flat))
        if torch is not None:
            if self.robot.default_position_only():
                why = (
                    "invalid: torch angles need an arm with 6 or more joints; "
                    f"{self.robot.name} has {self.robot.nq}"
                )
                self._fail(kind, label, key, status="invalid", why=why)
            path = self._build_path(kind, label, key, lambda: torch_path(path, torch))
            if not torch.searched:
                self._check_torch_start(path, kind, label, key)
        if weave is not None:
            travel = DEFAULT_TOOL_SPEED if speed is None else speed
            path = self._build_path(kind, label, key, lambda: weave_path(path, weave, travel))
        if torch is not None and torch.searched:
            return self._searched_seam(
                path, torch, duration=duration, speed=speed, profile=profile, label=label,
                key=key, kind=kind, max_acceleration=max_acceleration,
            )  # fmt: skip
        return self.follow(
            path, duration=duration, speed=speed, profile=profile, label=label, key=key,
            kind=kind, max_acceleration=max_acceleration,
        )  # fmt: skip

    def seam_start(
        self,
        pieces: Sequence[SeamPiece],
        at: Goal,
        *,
        blend: float | Sequence[float] = 0.0,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        weave: WeaveSpec | None = None,
        torch: TorchSpec,
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> np.ndarray | None:
        """Plan a searched torch seam (roll free or tolerance bands) that will start at ``at``
        before the approach move that takes the arm there, so the approach can go to the start
        configuration :func:`cartesian.plan_seam` chose.

        Args:
            pieces, blend, duration, speed, profile, weave, torch, max_acceleration: As in
                :meth:`seam` (the seam's own move, planned next).
            at: The approach's goal: the seam's start (pose, or position [m] keeping the
                current orientation).

        Returns:
            The seam's first configuration [rad], shape (nq,), for the approach to end at; None
            when the seam cannot be planned from there (the approach then goes as taught and
            :meth:`seam` fails the seam, saying why).
        """
        self._check_open()
        self._ahead = None
        if not torch.searched or self.robot.default_position_only():
            return None
        try:
            start = goal_from(at, self.tool_pose())
            path = torch_path(seam_path(pieces, blend, start, False), torch)
            if weave is not None:
                travel = DEFAULT_TOOL_SPEED if speed is None else speed
                path = weave_path(path, weave, travel)
            plan = self._plan_seam(path, torch, duration, speed, profile, max_acceleration, None)
        except KinplanError:
            return None  # the seam's own move says why
        self._ahead = (path, plan)
        return np.array(plan.q[0]) if plan.ok and len(plan.t) else None

    def _plan_seam(
        self,
        path: cartesian.Path,
        torch: TorchSpec,
        duration: float | None,
        speed: float | None,
        profile: str,
        max_acceleration: object,
        q_start: np.ndarray | None,
    ) -> cartesian.CartesianPlan:
        """:func:`cartesian.plan_seam` of a torch seam (its roll free or fixed at the path's,
        its tolerance bands [rad]) with the builder's cell, dt and acceleration limits."""
        limit = self._acceleration_limit(max_acceleration)
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        return cartesian.plan_seam(
            self.robot, path, speed=speed, duration=duration, dt=self.dt,
            roll="free" if torch.roll is None else 0.0,  # a fixed roll is in the path's poses
            work_tolerance=torch.work_tolerance, travel_tolerance=torch.travel_tolerance,
            q_start=q_start, cell=self.cell, clearance=self.clearance, profile=profile,
            whole_periods=True, max_acceleration=limit if np.all(np.isfinite(limit)) else None,
        )  # fmt: skip

    def _searched_seam(
        self,
        path: cartesian.Path,
        torch: TorchSpec,
        *,
        duration: float | None,
        speed: float | None,
        profile: str,
        label: str,
        key: str | None,
        kind: str,
        max_acceleration: float | Sequence[float] | np.ndarray | None,
    ) -> MoveReport:
        """A torch seam planned by :func:`cartesian.plan_seam`: the plan made before the
        approach (:meth:`seam_start`) when the arm is at its start, else one from the current
        configuration (``q_start``: the roll free from there on)."""
        limit = self._acceleration_limit(max_acceleration)
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = start_gap_reason(path.start.translation, here, gap)
            self._fail(kind, label, key, status="invalid", why=why)
        ahead, self._ahead = self._ahead, None
        plan = None
        if ahead is not None:
            before, planned = ahead
            moved = float(np.linalg.norm(before.start.translation - here))
            joins = not (planned.ok and len(planned.t)) or (
                float(np.max(np.abs(planned.q[0] - self.q))) <= JOIN_TOLERANCE
            )
            if moved <= 1e-4 and joins:
                path, plan = before, planned
        if plan is None:
            axis = self.tool_pose().rotation[:, 2] @ path.start.rotation[:, 2]
            turn = math.acos(min(1.0, max(-1.0, float(axis))))
            band = math.hypot(torch.work_tolerance, torch.travel_tolerance)
            if turn > band + TORCH_START_TOLERANCE:  # the torch axis, whatever its roll
                self._fail(kind, label, key, status="invalid",
                           why=torch_start_reason(path.start, turn))  # fmt: skip
            try:
                plan = self._plan_seam(
                    path, torch, duration, speed, profile, max_acceleration, self.q
                )
            except KinplanError as exc:
                self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")
        return self._take_plan(plan, plan.path, kind, label, key, limit, 0.0)

    def _check_torch_start(
        self, path: cartesian.Path, kind: str, label: str, key: str | None
    ) -> None:
        """Refuse a torch seam whose start orientation is not the tool's (within
        :data:`TORCH_START_TOLERANCE`),
        printing the orientation with the digits that make pasting it work."""
        turn = start_turn(path, self.tool_pose(), False)
        if turn > TORCH_START_TOLERANCE:
            why = torch_start_reason(path.start, turn)
            self._fail(kind, label, key, status="invalid", why=why)

    def follow(
        self,
        path: cartesian.Path,
        *,
        duration: float | None = None,
        speed: float | None = None,
        profile: str = "trapezoid",
        label: str = "path",
        key: str | None = None,
        kind: str = "path",
        max_acceleration: float | Sequence[float] | np.ndarray | None = None,
    ) -> MoveReport:
        """Follow a Cartesian path that starts at the current tool pose (within 0.1 mm, 1 mrad).

        Args:
            path: Any :class:`cartesian.Path` (e.g. a :class:`cartesian.PathSequence` of lines
                and arcs: one move at constant tool speed).
            duration: Duration [s]; or
            speed: Tool cruise speed [m/s] (default :data:`~kinplan.program.DEFAULT_TOOL_SPEED`).
            profile: 1-D time law: ``trapezoid``, ``quintic`` or ``cubic``.
            label: Description for reports.
            key: Key path in a program, for messages.
            kind: Kind shown in reports.
            max_acceleration: As in :meth:`seam`.
        """
        self._check_open()
        limit = self._acceleration_limit(max_acceleration)
        here = self.tool_pose().translation
        gap = float(np.linalg.norm(path.start.translation - here))
        if gap > 1e-4:
            why = start_gap_reason(path.start.translation, here, gap)
            self._fail(kind, label, key, status="invalid", why=why)
        turn = start_turn(path, self.tool_pose(), self.robot.default_position_only())
        if turn > 1e-3:
            self._fail(kind, label, key, status="invalid", why=start_turn_reason(turn))
        if duration is None and speed is None:
            if path.length > 0:
                speed = DEFAULT_TOOL_SPEED
            else:
                duration = 1.0
        try:
            plan = cartesian.follow(
                self.robot, path, duration=duration, speed=speed, profile=profile, dt=self.dt,
                q_seed=self.q, cell=self.cell, clearance=self.clearance, whole_periods=True,
                max_acceleration=limit if np.all(np.isfinite(limit)) else None,
            )  # fmt: skip
        except KinplanError as exc:
            self._fail(kind, label, key, status="invalid", why=f"invalid: {exc}")
        return self._take_plan(plan, path, kind, label, key, limit, turn)

    def _take_plan(
        self,
        plan: cartesian.CartesianPlan,
        path: cartesian.Path,
        kind: str,
        label: str,
        key: str | None,
        limit: np.ndarray,
        turn: float,
    ) -> MoveReport:
        """Record a Cartesian plan from the current configuration: a move, or its failure
        (a jump from the current configuration, the plan's first event). ``turn`` [rad]: the
        path start's angle to the tool's orientation."""
        self.paths.append(path)
        ratio = plan.peak_speed_ratio
        samples = (plan.t, plan.q, plan.qd, plan.qdd) if len(plan.t) else None
        gap = float(np.max(np.abs(plan.q[0] - self.q))) if samples else 0.0
        if gap > JOIN_TOLERANCE:
            offset: float | None = None
            if gap < SMALL_GAP:  # not another branch: the tool is not quite at the path start
                offset = float(
                    np.linalg.norm(path.start.translation - self.tool_pose().translation)
                )
            why = jump_reason(gap, offset, turn)
            self._fail(kind, label, key, status="jump", why=why, ratio=ratio, plan=plan)
        if not plan.ok:
            event = plan.events[0]
            why = f"{event.kind} at s = {event.s:.2f}: {event.message}; {program_remedy(plan)}"
            self._fail(
                kind, label, key, samples, status=plan.status, why=why, ratio=ratio,
                fraction=plan.fraction, plan=plan,
            )  # fmt: skip
        return self._record(
            kind, label, key, samples, ratio=ratio, plan=plan, acceleration_limit=limit
        )
