"""The work cell's verdict on a seam's candidate configurations, asked lazily.

Checking every candidate of every waypoint against the cell (one distance query each) costs
seconds on a long seam, while the ladder's least-cost path uses one candidate per waypoint.
As LazyPRM and Descartes' lazy collision checking do, :func:`solve` solves the ladder with the
candidates unchecked, checks only the candidates its paths pass through, removes the ones in
collision and solves again, until every candidate on the paths it returns is clear. Since
removing candidates only removes paths, the paths returned are least-cost paths of the ladder
whose every candidate was checked. A candidate in collision has its roll row checked at once
(the same waypoint, tilt and branch at every roll sample: when the roll only turns the last
joint, a collision of the arm's upper links is the same at every roll, and one search would
otherwise find it roll by roll). When no path is left, or after :data:`ROUNDS` searches
whose paths met a collision (or :data:`BUDGET` of the candidates checked), every candidate is
checked (:meth:`CellVerdict.check_all`) and the ladder solved again: the refusal then says
where and why, with the colliding pairs, as a full check would. Every plan is still checked
against the cell by the follower (at its samples and between them).
"""

from __future__ import annotations

import logging

import numpy as np

from cartesian.seam_candidates import Candidates
from cartesian.seam_ladder import Blocked, Ladder, LadderPath
from kinplan import checks
from kinplan.cell import WorkCell
from kinplan.errors import InputError
from kinplan.model.robot import Robot

__all__ = ["LAZY", "CellVerdict", "solve"]

logger = logging.getLogger(__name__)

#: Private switch for tests and benchmarks: False checks every candidate before the search.
LAZY = True
#: Searches whose paths met a colliding candidate before every candidate is checked: a cell
#: that blocks the seam's way would otherwise be found one path at a time.
ROUNDS = 4
#: Share of the candidates checked lazily after which every candidate is checked.
BUDGET = 0.5


class CellVerdict:
    """Which candidates collide with the cell (robot–obstacle distance below ``clearance``
    [m], or contact between the robot's own checked links), checked on demand.

    Args:
        candidates: The ladder's candidates; colliding ones are marked invalid in place.
        cell: The work cell (moved to ``robot`` when made for another).
        robot: The arm.
        clearance: Margin [m] to the obstacles (None: 0).

    Raises:
        InputError: ``cell`` is not a :class:`kinplan.WorkCell`, or a negative clearance.
    """

    def __init__(
        self, candidates: Candidates, cell: WorkCell, robot: Robot, clearance: float | None
    ) -> None:
        if not isinstance(cell, WorkCell):
            raise InputError(f"cell must be a kinplan.WorkCell, got {checks.describe(cell)}")
        self.cell = cell if cell.robot is robot else cell.for_robot(robot)
        self.margin = (
            0.0 if clearance is None else checks.number(clearance, "clearance", minimum=0.0)
        )
        self.candidates = candidates
        self.checked = np.zeros(candidates.valid.shape, dtype=bool)
        #: How many candidates were checked, and how many searches met a colliding one.
        self.count = self.rounds = 0
        #: How many candidates there are to check (valid before the cell).
        self.total = int(candidates.valid.sum())
        #: Whether every candidate has been checked (then the counts and pairs are complete).
        self.complete = False

    def _check(self, index: tuple[int, ...]) -> bool:
        """Check one candidate (K, S, B, I index); False (and marked invalid) when it collides."""
        self.checked[index] = True
        self.count += 1
        hits = self.cell.collisions(self.candidates.q[index], self.margin)
        if not hits:
            return True
        self.candidates.valid[index] = False
        pairs = self.candidates.pairs
        pairs[hits[0].bodies] = pairs.get(hits[0].bodies, 0) + 1
        return False

    def verify(self, paths: list[LadderPath]) -> bool:
        """Check the candidates ``paths`` pass through that were not checked yet, and the roll
        row of each that collides (module docstring); True when every candidate on the paths
        is clear (the paths stand), False when some collide (now invalid)."""
        _, S, B, I = self.candidates.valid.shape
        clear = True
        for path in paths:
            for k, node in enumerate(path.nodes.tolist()):
                if node < 0:  # the given start configuration: not a candidate
                    continue
                index = (k, *(int(i) for i in np.unravel_index(node, (S, B, I))))
                if self.checked[index] or self._check(index):
                    continue
                clear = False
                # its roll row (the same waypoint, slot and branch: the other rolls) likely
                # collides too: a factored roll only turns the last joint
                for i in np.flatnonzero(
                    self.candidates.valid[index[:3]] & ~self.checked[index[:3]]
                ):
                    self._check((*index[:3], int(i)))
        return clear

    def check_all(self) -> None:
        """Check every valid candidate not checked yet; set the candidates' per-waypoint
        "collision" counts."""
        if self.complete:
            return
        logger.debug("seam cell: every candidate checked after %d (%d rounds)", self.count,
                     self.rounds)  # fmt: skip
        valid = self.candidates.valid
        for index in zip(*np.nonzero(valid & ~self.checked)):
            self._check(tuple(int(i) for i in index))
        self.candidates.counts["collision"] = valid.sum(axis=(1, 2, 3))
        # most frequent pair first (the order a refusal names them in, whatever the order of
        # the checks)
        pairs = self.candidates.pairs
        self.candidates.pairs = dict(sorted(pairs.items(), key=lambda item: (-item[1], item[0])))
        self.complete = True


def solve(
    ladder: Ladder, verdict: CellVerdict | None, count: int
) -> tuple[list[LadderPath], Blocked | None]:
    """:meth:`Ladder.solve` with the cell checked lazily (module docstring): up to ``count``
    least-cost paths whose candidates are all clear of the cell, or none and why."""
    if verdict is not None and not LAZY:
        verdict.check_all()
    while True:
        paths, blocked = ladder.solve(count)
        if verdict is None or verdict.complete:
            return paths, blocked
        if not paths or verdict.rounds >= ROUNDS or verdict.count > BUDGET * verdict.total:
            # nothing left, or the cell blocks path after path: check everything (a refusal
            # then says what blocks where)
            verdict.check_all()
            return ladder.solve(count)
        if verdict.verify(paths):
            return paths, blocked
        verdict.rounds += 1
