"""Shortening a certified joint path: every new edge certified too.

A round proposes a shorter chain of straight joint segments (rad, Euclidean over the joints)
using the fast screen (:class:`kinplan.planning.screen.Screen`) alone:

1. **Skipping**: each waypoint is dropped when the last kept one sees the next directly.
2. **Random shortcuts** between two points on the path (anywhere on its segments, not only at
   waypoints), drawn from the caller's generator: deterministic per seed.
3. Skipping again, then waypoints on a straight line dropped.

Then only the round's new segments are certified by the cell's motion check (the others are
parts of certified ones). When one fails it is remembered as blocked and the round is proposed
again (at most :data:`ROUNDS` rounds). When none passes, the path's own edges are certified one
by one and kept; the first that fails is reported to the search, which cuts it. The number of
attempts, not the clock, bounds the work: the result depends on the seed only.
"""

from __future__ import annotations

import numpy as np

from kinplan.planning.search import EdgeChecker

__all__ = ["ROUNDS", "SHORTCUT_ATTEMPTS", "path_length", "shorten"]

SHORTCUT_ATTEMPTS = 40
"""Random shortcuts tried per round between two points of the path."""

ROUNDS = 3
"""Proposals certified before the path is kept as it is."""

_Edge = tuple[bytes, bytes]


def path_length(path: np.ndarray) -> float:
    """Length of the polyline (K, nq) [rad] (Euclidean over the joints)."""
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))


def _key(a: np.ndarray, b: np.ndarray) -> _Edge:
    return (a.tobytes(), b.tobytes())


class _Proposal:
    """A path being shortened with the screen, and which of its segments are new."""

    def __init__(self, path: np.ndarray, checker: EdgeChecker, blocked: set[_Edge]) -> None:
        self.points = [p.copy() for p in path]
        self.new = [False] * (len(path) - 1)  # per segment: not part of a certified one
        self.checker = checker
        self.blocked = blocked

    def sees(self, a: np.ndarray, b: np.ndarray) -> bool:
        return _key(a, b) not in self.blocked and self.checker.screen.segment_free(a, b)

    def skip(self) -> None:
        """Drop each waypoint whose neighbours see each other (one screen per waypoint)."""
        points, new = self.points, self.new
        kept_points, kept_new = [points[0]], []
        pending_new = new[0] if new else False
        for k in range(1, len(points) - 1):
            if self.sees(kept_points[-1], points[k + 1]):
                pending_new = True  # waypoint k dropped: a new segment to k + 1
                continue
            kept_points.append(points[k])
            kept_new.append(pending_new)
            pending_new = new[k]
        kept_points.append(points[-1])
        kept_new.append(pending_new)
        self.points, self.new = kept_points, kept_new

    def shortcut(self, rng: np.random.Generator) -> None:
        path = np.array(self.points)
        if len(path) < 3:
            rng.random(2)  # the same draws whatever the path, for determinism per seed
            return
        lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
        cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
        u, v = np.sort(rng.random(2) * cumulative[-1])
        last = len(lengths) - 1
        i = int(np.clip(np.searchsorted(cumulative, u, side="right") - 1, 0, last))
        j = int(np.clip(np.searchsorted(cumulative, v, side="right") - 1, 0, last))
        if j <= i or lengths[i] <= 0 or lengths[j] <= 0:
            return  # both on one segment: nothing to gain
        a = path[i] + (u - cumulative[i]) / lengths[i] * (path[i + 1] - path[i])
        b = path[j] + (v - cumulative[j]) / lengths[j] * (path[j + 1] - path[j])
        gained = (cumulative[j] - u) + (v - cumulative[j]) - float(np.linalg.norm(b - a))
        if gained < 1e-6 * cumulative[-1] or not self.sees(a, b):
            return
        # path[i] → a and b → path[j+1] are parts of segments i and j: new if those were
        self.points = [*self.points[: i + 1], a, b, *self.points[j + 1 :]]
        self.new = [*self.new[:i], self.new[i], True, self.new[j], *self.new[j + 1 :]]

    def straighten(self) -> None:
        """Drop the waypoints where the path goes straight on (the merged segment is new
        when either part is)."""
        points, new = self.points, self.new
        kept_points, kept_new = [points[0]], []
        pending = False
        for k in range(1, len(points) - 1):
            before = points[k] - kept_points[-1]
            after = points[k + 1] - points[k]
            nb, na = np.linalg.norm(before), np.linalg.norm(after)
            pending = pending or new[k - 1]
            if nb < 1e-12 or (na > 1e-12 and np.linalg.norm(before / nb - after / na) < 1e-9):
                continue
            kept_points.append(points[k])
            kept_new.append(pending)
            pending = False
        kept_points.append(points[-1])
        kept_new.append(pending or new[-1])
        self.points, self.new = kept_points, kept_new


def shorten(
    path: np.ndarray,
    certified: np.ndarray,
    checker: EdgeChecker,
    rng: np.random.Generator,
    attempts: int = SHORTCUT_ATTEMPTS,
) -> tuple[np.ndarray | None, int | None]:
    """The path shortened (see the module), every segment certified.

    Args:
        path: A chain of screened straight segments (K, nq) [rad], K ≥ 2.
        certified: Which of its K − 1 segments are certified already.
        checker: Screens and certifies segments.
        rng: Random generator of the shortcut points.
        attempts: Random shortcuts tried per round.

    Returns:
        (a chain of certified segments from the same start to the same end, None), or (None,
        the index of a segment of ``path`` that failed its certification).
    """
    blocked: set[_Edge] = set()
    for _ in range(ROUNDS):
        proposal = _Proposal(path, checker, blocked)
        proposal.new = [not flag for flag in certified.tolist()]
        proposal.skip()
        for _ in range(attempts):
            proposal.shortcut(rng)
        proposal.skip()
        proposal.straighten()
        failed = False
        for k, is_new in enumerate(proposal.new):
            a, b = proposal.points[k], proposal.points[k + 1]
            if is_new and not checker.certified(a, b):
                blocked.add(_key(a, b))
                failed = True
                break
        if not failed:
            return np.array(proposal.points), None
    for k in range(len(path) - 1):  # no proposal passed: the path's own edges
        if not certified[k] and not checker.certified(path[k], path[k + 1]):
            return None, k
    return path, None
