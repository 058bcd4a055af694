"""Bidirectional RRT-Connect in joint space with lazy certification of its edges.

Two trees grow towards each other (Kuffner & LaValle 2000): one from the start, one from every
goal configuration at once (a forest with several roots). Each round samples a configuration
within the limits, extends the current tree one step towards it (at most :data:`STEP` rad,
Euclidean over the joints) and then tries to join the other tree to the new node: first with the
whole straight segment from its nearest node, else step by step as far as it goes. The trees then
swap roles.

**Certification.** Growing, the trees take an edge when the fast :class:`Screen` passes it
(boolean collision tests along it, inflated). When the trees meet, the path between the start and
the goal goes to the caller's ``finish`` (shortcuts), which returns a chain of segments each
certified by :class:`EdgeChecker` — :meth:`kinplan.WorkCell.check_motion` of its two ends: the
pair distances at both ends and a motion bound of every pair, bisected where the bound does not
certify, so no shortfall below the clearance deeper than :data:`kinplan.cell.TOLERANCE` is
missed anywhere on it — or the index of a tree edge that failed its certification. That edge is
cut from its tree with everything that grew beyond it, and the search goes on. The returned path
is a chain of certified segments; the start and goals are checked by the caller.

**Determinism.** All randomness comes from one ``numpy.random.Generator`` seeded by the caller;
nearest neighbours are exact (brute force), ties to the earliest node. The time limit only
decides whether the search gives up: a search that succeeds returns the same path for the same
seed.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from kinplan.cell import WorkCell
from kinplan.planning.screen import Screen

__all__ = ["STEP", "EdgeChecker", "SearchResult", "Tree", "rrt_connect"]

STEP = 1.0
"""Longest edge of an extension [rad] (Euclidean over the joints)."""

_CONNECT_STEPS = 8
"""Most steps of a step-by-step connection when the straight join is blocked."""

_DIRECT_GOALS = 4
"""Goals (nearest the start first) whose straight move from the start is tried first."""


@dataclass
class EdgeChecker:
    """Certifies straight joint segments against a cell (screened first), and counts.

    Attributes:
        cell: The work cell.
        clearance: Margin from the obstacles [m] (self pairs: contact only).
        screen: The fast screen of the same cell and clearance.
        checks: Segments certified (cell motion checks) so far.
    """

    cell: WorkCell
    clearance: float
    screen: Screen = field(init=False)
    checks: int = 0

    def __post_init__(self) -> None:
        self.screen = Screen(self.cell, self.clearance)

    def certified(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        """Whether the cell's motion check certifies the segment ``qa`` → ``qb`` [rad]."""
        self.checks += 1
        return self.cell.check_motion(np.stack([qa, qb]), self.clearance).ok

    def free(self, qa: np.ndarray, qb: np.ndarray) -> bool:
        """Screened, then certified: whether the segment keeps the clearance all along."""
        return self.screen.segment_free(qa, qb) and self.certified(qa, qb)


@dataclass
class Tree:
    """Nodes (rows of a growing array) with their parents (-1 for a root), the certified
    edges and the nodes cut off."""

    nq: int
    nodes: np.ndarray = field(init=False)
    parents: list[int] = field(default_factory=list)
    certified: list[bool] = field(default_factory=list)
    dead: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.nodes = np.empty((64, self.nq))
        self.dead = np.zeros(64, dtype=bool)

    def __len__(self) -> int:
        return len(self.parents)

    def add(self, q: np.ndarray, parent: int) -> int:
        """Add node ``q`` under ``parent``; returns its index."""
        n = len(self.parents)
        if n == len(self.nodes):
            self.nodes = np.vstack([self.nodes, np.empty_like(self.nodes)])
            self.dead = np.concatenate([self.dead, np.zeros_like(self.dead)])
        self.nodes[n] = q
        self.dead[n] = False
        self.parents.append(parent)
        self.certified.append(parent < 0)
        return n

    def nearest(self, q: np.ndarray) -> int:
        """Index of the live node nearest ``q`` (Euclidean; the earliest on ties)."""
        n = len(self.parents)
        delta = self.nodes[:n] - q
        distance = np.einsum("ij,ij->i", delta, delta)
        distance[self.dead[:n]] = np.inf
        return int(np.argmin(distance))

    def branch(self, index: int) -> list[int]:
        """The node indices from ``index`` up to its root, in that order."""
        out = []
        while index >= 0:
            out.append(index)
            index = self.parents[index]
        return out

    def cut(self, index: int) -> None:
        """Cut node ``index`` and everything that grew beyond it (parents come first)."""
        self.dead[index] = True
        for k in range(index + 1, len(self.parents)):
            if self.parents[k] >= 0 and self.dead[self.parents[k]]:
                self.dead[k] = True

    def live(self) -> int:
        """Number of live nodes."""
        return int(np.count_nonzero(~self.dead[: len(self.parents)]))


@dataclass(frozen=True)
class SearchResult:
    """What :func:`rrt_connect` found.

    Attributes:
        path: The joint path (K, nq) from the start to a goal, a chain of certified edges; None
            when the time ran out.
        iterations: Rounds of the search.
        nodes: Nodes of both trees (cut ones included).
        rejected: Edges the screen passed but the certification refused (cut).
    """

    path: np.ndarray | None
    iterations: int
    nodes: int
    rejected: int = 0


Finish = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray | None, int | None]]
"""``finish(points, certified)``: from the path's points (K, nq) and which of its K − 1 edges
are certified already, a chain of certified segments from the same start to the same end, or
(None, the index of an edge of ``points`` that failed its certification)."""


def rrt_connect(
    start: np.ndarray,
    goals: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    checker: EdgeChecker,
    rng: np.random.Generator,
    deadline: float,
    finish: Finish,
    step: float = STEP,
) -> SearchResult:
    """Search a chain of certified straight segments from ``start`` to one of ``goals``.

    Args:
        start: Start configuration (nq,) [rad], collision-free.
        goals: Goal configurations (G, nq) [rad], collision-free, the preferred ones first.
        lower, upper: Sampling box (nq,) [rad] (the joint limits, finite).
        checker: Screens and certifies segments.
        rng: The random generator (the only source of randomness).
        deadline: ``time.perf_counter()`` value after which the search gives up [s].
        finish: Turns a path of screened edges into a certified one (see :data:`Finish`).
        step: Longest extension [rad].

    Returns:
        The path (start first, a goal last) or None, with counters.
    """
    nq = start.size
    span = upper - lower
    screen = checker.screen
    start_tree, goal_tree = Tree(nq), Tree(nq)
    start_tree.add(start, -1)
    for q in goals:
        goal_tree.add(q, -1)
    for g in range(min(len(goals), _DIRECT_GOALS)):  # the straight move first
        if checker.free(start, goals[g]):
            return SearchResult(np.array([start, goals[g]]), 0, 1 + len(goals))
    trees = [start_tree, goal_tree]
    iterations = rejected = 0
    while time.perf_counter() < deadline:
        iterations += 1
        grow, other = trees
        target = lower + span * rng.random(nq)
        new = _extend(grow, target, screen, step)
        if new is not None:
            joined = _connect(other, grow.nodes[new], screen, step)
            if joined is not None:
                a, b = (new, joined) if grow is start_tree else (joined, new)
                points, edges = _joined_path(start_tree, a, goal_tree, b)
                certified = np.array([tree.certified[k] for tree, k in edges], dtype=bool)
                path, failed = finish(points, certified)
                if path is not None:
                    return SearchResult(path, iterations, _count(trees), rejected)
                rejected += 1
                if failed is not None:
                    tree, k = edges[failed]
                    tree.cut(k)
        trees = [other, grow]
    return SearchResult(None, iterations, _count(trees), rejected)


def _joined_path(
    start_tree: Tree, a: int, goal_tree: Tree, b: int
) -> tuple[np.ndarray, list[tuple[Tree, int]]]:
    """The path from the start root to node ``a``, then from node ``b`` (the same point) to its
    goal root: its points (K, nq) and, per edge, (tree, the node whose parent edge it is)."""
    forward = start_tree.branch(a)[::-1]
    backward = goal_tree.branch(b)
    points = [start_tree.nodes[i] for i in forward] + [goal_tree.nodes[i] for i in backward[1:]]
    edges = [(start_tree, k) for k in forward[1:]] + [(goal_tree, k) for k in backward[:-1]]
    return np.array(points), edges


def _extend(tree: Tree, target: np.ndarray, screen: Screen, step: float) -> int | None:
    """One step (≤ ``step``) from the node nearest ``target`` towards it; the new node's
    index, or None when the screen blocks that edge."""
    near = tree.nearest(target)
    origin = tree.nodes[near]
    delta = target - origin
    length = float(np.linalg.norm(delta))
    if length < 1e-9:
        return None
    q = origin + delta * min(1.0, step / length)
    if not screen.segment_free(origin, q, end=True):
        return None
    return tree.add(q, near)


def _connect(tree: Tree, target: np.ndarray, screen: Screen, step: float) -> int | None:
    """Join ``tree`` to ``target`` (a node of the other tree): the straight segment from its
    nearest node, else step by step; the index of the node at ``target``, or None."""
    near = tree.nearest(target)
    if screen.segment_free(tree.nodes[near], target):
        return tree.add(target.copy(), near)
    for steps in range(_CONNECT_STEPS):
        origin = tree.nodes[near]
        delta = target - origin
        length = float(np.linalg.norm(delta))
        if length <= step:  # the last step lands on the target
            if steps == 0 or not screen.segment_free(origin, target):
                return None  # (at step 0 it is the straight segment found blocked)
            return tree.add(target.copy(), near)
        q = origin + delta * (step / length)
        if not screen.segment_free(origin, q, end=True):
            return None
        near = tree.add(q, near)
    return None


def _count(trees: list[Tree]) -> int:
    return sum(len(tree) for tree in trees)
