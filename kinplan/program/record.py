"""The motion planned so far: samples of every move appended in time, and one report per move.

A :class:`MotionRecord` is what a :class:`~kinplan.program.MotionBuilder` writes into: each move
appends its samples (in the move's local time) and its :class:`~kinplan.program.MoveReport`
(:meth:`MotionRecord.append`); a failed move is recorded, then raised as a
:class:`~kinplan.program.MoveError` (:meth:`MotionRecord.fail`).
"""

from __future__ import annotations

import logging
from typing import NoReturn

import numpy as np

import cartesian
from kinplan.cell import MotionCheck
from kinplan.program.errors import MoveError
from kinplan.program.peaks import segment_peaks
from kinplan.program.plan import MoveReport, move_span
from kinplan.program.segments import hermite_segments
from kinplan.trajectory import Segment

logger = logging.getLogger(__name__)

__all__ = ["MotionRecord"]


class MotionRecord:
    """Samples and reports of the moves planned so far, from a start configuration at t = 0.

    Args:
        q_start: Start configuration [rad], shape (nq,).

    Attributes:
        reports: One report per move recorded (a failed one last).
        reason: The failed move's one-line message, or "" while every move was done.
    """

    def __init__(self, q_start: np.ndarray) -> None:
        nq = len(q_start)
        self.reports: list[MoveReport] = []
        self.reason = ""
        self._t = [np.zeros(1)]
        self._q = [np.array(q_start, dtype=float)[None, :]]
        self._qd = [np.zeros((1, nq))]
        self._qdd = [np.zeros((1, nq))]
        self._time = 0.0
        self._count = 1
        self._segments: list[Segment] = []

    def __len__(self) -> int:
        """Number of samples so far (the start included)."""
        return self._count

    @property
    def time(self) -> float:
        """End time of the motion so far [s]."""
        return self._time

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The samples so far: t [s] (N,), q [rad], qd [rad/s], qdd [rad/s²] (N, nq)."""
        return (
            np.concatenate(self._t),
            np.vstack(self._q),
            np.vstack(self._qd),
            np.vstack(self._qdd),
        )

    @property
    def segments(self) -> list[Segment]:
        """The motion so far as polynomial pieces in program time: each move's own segments
        where it gave them (ptp profiles, dwells), else quintic Hermite pieces through its
        samples; a single still piece when nothing moved."""
        if not self._segments:
            return [Segment(0.0, 0.0, self._q[0].T.copy())]
        return list(self._segments)

    def append(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None = None,
        *,
        ratio: float = 0.0,
        plan: cartesian.CartesianPlan | None = None,
        check: MotionCheck | None = None,
        segments: list[Segment] | None = None,
        acceleration_limit: np.ndarray | None = None,
    ) -> MoveReport:
        """Append a move that was done: its samples and its report.

        Args:
            kind: Kind shown in reports (``ptp``, ``lin``, ``circ``, ``path``, ...).
            label: Description for reports.
            key: Key path in a program, or None.
            samples: (t [s] from 0, q, qd, qdd) of the move, the first sample being the end of
                the motion so far; or None when the move produced none.
            ratio: Peak joint speed over its limit [-].
            plan: The move's :class:`cartesian.CartesianPlan`, if any.
            check: The move's work-cell check (:meth:`kinplan.WorkCell.check_motion` on its
                samples), if any; a Cartesian plan's own check by default.
            segments: The move's own motion in its local time (from 0 to its last sample
                time), or None: quintic Hermite pieces through its samples.
            acceleration_limit: The joint acceleration limits the move kept [rad/s²], shape
                (nq,), inf where none; None: not recorded.

        Returns:
            The move's report.
        """
        return self._add(
            kind, label, key, samples, "ok", "", ratio, 1.0, plan, check, segments,
            acceleration_limit,
        )  # fmt: skip

    def fail(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None = None,
        *,
        status: str,
        why: str,
        ratio: float = 0.0,
        fraction: float = 0.0,
        plan: cartesian.CartesianPlan | None = None,
        check: MotionCheck | None = None,
    ) -> NoReturn:
        """Record a move that failed (the samples are the part achieved) and raise.

        Args:
            kind, label, key, samples, ratio, plan, check: As in :meth:`append`.
            status: Why the move failed (``unreachable``, ``velocity_limit``, ``ik``, ...).
            why: What went wrong and what to do, after the status.
            fraction: Share of the move achieved [-].

        Raises:
            MoveError: always; its message is one line naming the move (number, label, key)
                and ``why``, also kept in :attr:`reason`.
        """
        report = self._add(kind, label, key, samples, status, why, ratio, fraction, plan, check)
        self.reason = report.message
        logger.info("planning stopped: %s", report.message)
        raise MoveError(report.message, report)

    def _end(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) of the last sample so far, each of shape (1, nq) (a move of a single
        sample adds no rows, so the last non-empty block holds it)."""
        last = max(k for k, block in enumerate(self._q) if len(block))
        return self._q[last][-1:], self._qd[last][-1:], self._qdd[last][-1:]

    def _number(self, kind: str, key: str | None) -> int:
        """A report's move number: the program's (``moves[2]`` is move 3, its dwell too, moves
        blended together the first's), else one more than the last (a dwell its move's)."""
        span = move_span(key)
        if span is not None:
            return span[0]
        last = self.reports[-1].number if self.reports else 0
        return last if kind == "dwell" and self.reports else last + 1

    def _add(
        self,
        kind: str,
        label: str,
        key: str | None,
        samples: tuple[np.ndarray, ...] | None,
        status: str,
        why: str,
        ratio: float,
        fraction: float,
        plan: cartesian.CartesianPlan | None,
        check: MotionCheck | None = None,
        segments: list[Segment] | None = None,
        acceleration_limit: np.ndarray | None = None,
    ) -> MoveReport:
        if check is None and plan is not None:
            check = plan.cell_check
        number = self._number(kind, key)
        first, t0 = self._count - 1, self._time
        peak = None
        if samples is not None and len(samples[0]) > 1:
            t, q, qd, qdd = samples
            if segments is None:  # from the end of the motion so far, as the samples join it
                ends = self._end()
                segments = hermite_segments(
                    np.asarray(t, dtype=float), *(np.vstack([e, x[1:]]) for e, x in
                                                  zip(ends, (q, qd, qdd), strict=True))
                )  # fmt: skip
            offset = self._time
            self._segments += [
                Segment(s.t0 + offset, s.t1 + offset, s.coefficients)
                for s in segments
                if s.t1 > s.t0
            ]
            peak = segment_peaks(segments, q[0]).acceleration
        if samples is not None:
            t, q, qd, qdd = samples
            self._t.append(np.asarray(t[1:], dtype=float) + self._time)
            self._q.append(q[1:])
            self._qd.append(qd[1:])
            self._qdd.append(qdd[1:])
            self._count += len(t) - 1
            self._time += float(t[-1])
        message = ""
        if status != "ok":
            where = f"{label}, {key}" if key else label
            span = move_span(key)
            which = f"moves {span[0]}–{span[1]}" if span and span[1] > span[0] else f"move {number}"
            message = f"{which} ({where}): {why}"
        report = MoveReport(
            number=number,
            kind=kind,
            label=label,
            key=key,
            status=status,
            t0=t0,
            t1=self._time,
            first=first,
            last=self._count - 1,
            peak_speed_ratio=ratio,
            fraction=fraction,
            message=message,
            cartesian_plan=plan,
            acceleration_limit=acceleration_limit,
            peak_acceleration=peak,
        )
        if check is not None:
            report.min_clearance = float(check.min_obstacle_clearance)
            report.min_clearance_pair = check.min_obstacle_pair
            report.min_self_clearance = float(check.min_self_clearance)
            report.clearances = np.array(check.obstacle_distances, dtype=float)
            report.self_clearances = np.array(check.self_distances, dtype=float)
            report.clearance_margin = float(check.clearance)
            report.collision = None if check.ok else check
        self.reports.append(report)
        return report
