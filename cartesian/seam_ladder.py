"""The ladder graph of a seam and its least-cost path (dynamic programming), after Descartes.

Rungs are the seam's waypoints, each holding its candidate configurations
(:mod:`cartesian.seam_candidates`, indexed (slot, branch, roll)). An edge joins a candidate to
one of the next waypoint's when the free coordinates move to a neighbouring sample (the roll by
at most ``roll_steps`` samples, tilts and self-motion by one) and every joint's change fits in
the time between the waypoints at its speed limit, capped by the jump a branch flip would make.
Each path is tracked with its joint values *unwrapped* (joints whose range exceeds a turn can
wind): the lowest and highest value each such joint reaches must fit within its limits after a
shift by whole turns (chosen at the end, which picks the start configuration's equivalents), or
without shift when the start is given.

Cost of an edge: Σ |Δq| [rad] (joint travel) + ``roll_weight``·|Δroll| + the node's cost
(``singular_weight``·m_ref/m for the manipulability m, ``tilt_weight``·(|work| + |travel|)).
Forward dynamic programming, vectorised over each rung's edges; the best paths are read back
from the last rung.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from cartesian.seam_candidates import TAU, Candidates

#: Cost per rad of roll change between waypoints (a constant roll wins ties).
ROLL_WEIGHT = 0.02
#: Cost per unit of m_ref / m at every waypoint (away from singularities).
SINGULAR_WEIGHT = 0.01
#: Cost per rad of tilt at every waypoint (the nominal torch angles win ties).
TILT_WEIGHT = 0.05

START_ROLL_TOLERANCE = 1e-5
"""How far [rad] a given start configuration's roll may be from a roll sample it starts on (a
start taught to a few decimals of a degree is that far off; plan_seam's own start tolerance)."""


@dataclass
class LadderPath:
    """One path through the ladder.

    Attributes:
        nodes: Flat candidate index (slot, branch, roll) per waypoint (K,).
        q: Joint values along it [rad], unwrapped and shifted into the limits (K, nq).
        roll: Roll per waypoint [rad], unwrapped (K,).
        tilt: (work, travel) per waypoint [rad] (K, 2).
        cost: Its cost.
        searched: Whether ``q`` is the ladder's own path (its self-motion chosen by the
            search, to be followed as chosen), not a start or a constant roll put in by hand.
    """

    nodes: np.ndarray
    q: np.ndarray
    roll: np.ndarray
    tilt: np.ndarray
    cost: float
    searched: bool = True


@dataclass
class Blocked:
    """Why the ladder breaks between two waypoints.

    Attributes:
        step: The waypoint no path reaches (≥ 1).
        kind: "velocity_limit", "jump" or "joint_limit".
        joint: Index of the joint concerned.
        ratio: For "velocity_limit": the least factor by which some joint would exceed its
            speed limit on the best continuation.
        reached: The waypoint before it was reached by some path.
    """

    step: int
    kind: str
    joint: int
    ratio: float = 0.0
    reached: bool = True


@dataclass
class Ladder:
    """The graph's data and settings (see the module docstring).

    Attributes:
        candidates: The rungs' candidates.
        adjacency: (A, 2) pairs (previous slot, slot) that may follow each other.
        roll_steps: Largest roll change between waypoints, in roll samples.
        roll_circular: Whether the roll samples go all round (index I wraps to 0).
        caps: Largest joint change between waypoints k − 1 and k [rad] (K − 1, nq).
        jump_caps: The branch-flip part of those caps [rad] (nq,).
        wide: (nq,) joints tracked unwrapped.
        lower, upper: Joint limits (nq,).
        factored: Whether the roll samples only turn the last joint.
        reference_manipulability: m_ref of the node cost.
        start: The given start configuration (nq,), or None.
        start_roll, start_tilt: Its roll [rad] and (work, travel) [rad].
    """

    candidates: Candidates
    adjacency: np.ndarray
    roll_steps: int
    roll_circular: bool
    caps: np.ndarray
    jump_caps: np.ndarray
    wide: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    factored: bool
    reference_manipulability: float
    start: np.ndarray | None = None
    start_roll: float = 0.0
    start_tilt: np.ndarray = field(default_factory=lambda: np.zeros(2))

    # ------------------------------------------------------------------ shapes
    @property
    def shape(self) -> tuple[int, int, int, int]:
        """(K, S, B, I)."""
        K, S, B, I = self.candidates.valid.shape
        return K, S, B, I

    def _node_cost(self, k: int) -> np.ndarray:
        c = self.candidates
        K, S, B, I = self.shape
        with np.errstate(divide="ignore"):
            singular = SINGULAR_WEIGHT * self.reference_manipulability / c.manipulability[k]
        tilt = TILT_WEIGHT * np.abs(c.tilt).sum(axis=1)  # (S,)
        cost = singular + tilt[:, None]
        return np.repeat(cost[:, :, None], I, axis=2).reshape(-1)

    # ------------------------------------------------------------------ edges
    def _edges(self, k: int, filtered: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Candidate edges (pred, node) from rung k − 1 to rung k, flat indices; ``filtered``:
        only slot/branch pairs whose roll-independent joints fit the caps."""
        c = self.candidates
        K, S, B, I = self.shape
        nq = c.q.shape[-1]
        src_slot, dst_slot = self.adjacency[:, 0], self.adjacency[:, 1]
        cols = slice(0, nq - 1) if self.factored else slice(0, nq)
        a = c.rest[k - 1][src_slot][:, :, None, cols]  # (A, B', 1, n)
        b = c.rest[k][dst_slot][:, None, :, cols]  # (A, 1, B, n)
        with np.errstate(invalid="ignore"):
            delta = b - a
            wide = self.wide[cols]
            delta = np.where(wide, (delta + math.pi) % TAU - math.pi, delta)
            fits = np.all(np.abs(delta) <= self.caps[k - 1, cols], axis=-1)
        if not filtered:
            fits = np.all(np.isfinite(delta), axis=-1)
        pair, bp, bn = np.nonzero(fits)
        src = src_slot[pair] * B + bp
        dst = dst_slot[pair] * B + bn
        if I == 1:
            return src, dst
        shifts = np.arange(-self.roll_steps, self.roll_steps + 1)
        i = np.arange(I)
        prev_i = i[:, None] - shifts[None, :]  # (I, D)
        if self.roll_circular:
            prev_i %= I
            ok = np.ones(prev_i.shape, dtype=bool)
        else:
            ok = (prev_i >= 0) & (prev_i < I)
        ii, dd = np.nonzero(ok)
        pred = (src[:, None] * I + prev_i[ii, dd][None, :]).ravel()
        node = (dst[:, None] * I + i[ii][None, :]).ravel()
        return pred, node

    # ------------------------------------------------------------------ search
    def solve(self, count: int = 4) -> tuple[list[LadderPath], Blocked | None]:
        """Up to ``count`` least-cost paths with distinct start candidates (best first), or
        none and why the ladder breaks."""
        c = self.candidates
        K, S, B, I = self.shape
        nq = c.q.shape[-1]
        q_flat = c.q.reshape(K, -1, nq)
        valid = c.valid.reshape(K, -1)
        roll = np.broadcast_to(c.roll[:, None, :], (S, B, I)).reshape(-1)
        # rung 0
        if self.start is not None:
            U = self.start[None, :].copy()
            cost = np.zeros(1)
            R = np.array([self.start_roll])
            index0 = np.array([-1])
        else:
            index0 = np.flatnonzero(valid[0])
            U = q_flat[0, index0]
            cost = self._node_cost(0)[index0]
            R = roll[index0]
        lo, hi = U.copy(), U.copy()
        states = [(U, lo, hi, R)]  # per rung, indexed like `rows`
        rows = [index0]  # per rung: node index of each state row
        backs: list[np.ndarray] = []
        for k in range(1, K):
            prev_rows = rows[-1]
            if self.start is not None and k == 1:
                node = np.flatnonzero(valid[1])
                pred_row = np.zeros(len(node), dtype=int)
            else:
                pred, node = self._edges(k)
                lookup = np.full(valid.shape[1], -1)
                lookup[prev_rows] = np.arange(len(prev_rows))
                pred_row = lookup[pred]
                keep = (pred_row >= 0) & valid[k, node]
                pred_row, node = pred_row[keep], node[keep]
            prev_cost = cost
            delta, step_ok, droll = self._steps(k, pred_row, node, states[-1], q_flat, roll)
            # the edges within the caps only: their unwrapped values and ranges
            every = pred_row, node
            kept = np.flatnonzero(step_ok)
            pred_row, node, delta, droll = pred_row[kept], node[kept], delta[kept], droll[kept]
            U, lo, hi, _ = states[-1]
            new_u = U[pred_row] + delta
            new_lo = np.minimum(lo[pred_row], new_u)
            new_hi = np.maximum(hi[pred_row], new_u)
            ok = self._fits(new_lo, new_hi)
            if not ok.any():
                pred_row, node = every
                if not (self.start is not None and k == 1):  # diagnose on every slot pair
                    pred, node = self._edges(k, filtered=False)
                    lookup = np.full(valid.shape[1], -1)
                    lookup[prev_rows] = np.arange(len(prev_rows))
                    pred_row = lookup[pred]
                    keep = (pred_row >= 0) & valid[k, node]
                    pred_row, node = pred_row[keep], node[keep]
                delta, step_ok, _ = self._steps(k, pred_row, node, states[-1], q_flat, roll)
                new_u = U[pred_row] + delta
                new_lo = np.minimum(lo[pred_row], new_u)
                new_hi = np.maximum(hi[pred_row], new_u)
                return [], self._blocked(k, delta, step_ok, new_lo, new_hi, bool(valid[k].any()))
            edge = (
                prev_cost[pred_row]
                + np.abs(delta).sum(axis=1)
                + ROLL_WEIGHT * np.abs(droll)
                + self._node_cost(k)[node]
            )
            idx = np.flatnonzero(ok)
            order = idx[np.lexsort((edge[idx], node[idx]))]
            first = np.ones(len(order), dtype=bool)
            first[1:] = node[order][1:] != node[order][:-1]
            best = order[first]
            rows.append(node[best])
            backs.append(pred_row[best])
            cost = edge[best]
            states.append(
                (
                    new_u[best],
                    new_lo[best],
                    new_hi[best],
                    states[-1][3][pred_row[best]] + droll[best],
                )
            )
        return self._paths(rows, backs, states, cost, count), None

    def _steps(self, k, pred_row, node, state, q_flat, roll):
        """Joint changes (wide joints by the shortest turn), whether they fit the caps, and
        the roll changes of the edges (state row ``pred_row`` of rung k − 1 → node ``node`` of
        rung k)."""
        U, _, _, R = state
        delta = q_flat[k, node] - U[pred_row]
        w = self.wide_columns
        if len(w):
            delta[:, w] = (delta[:, w] + math.pi) % TAU - math.pi
        step_ok = np.all(np.abs(delta) <= self.caps[k - 1], axis=1)
        droll = (roll[node] - R[pred_row] + math.pi) % TAU - math.pi
        if self.start is not None and k == 1:
            # the given start's roll is measured, not sampled: it joins the roll samples within
            # the steps a waypoint may take (2 roll slots when the roll is free and not
            # factored into the last joint, as the slot adjacency), within START_ROLL_TOLERANCE
            slots = self.roll_steps or (2 if self.candidates.roll.shape[0] > 1 else 0)
            step_ok &= np.abs(droll) <= slots * self._roll_step() + START_ROLL_TOLERANCE
        return delta, step_ok, droll

    @property
    def wide_columns(self) -> np.ndarray:
        """Indices of the joints tracked unwrapped."""
        return np.flatnonzero(self.wide)

    def _roll_step(self) -> float:
        roll = self.candidates.roll
        if roll.shape[1] > 1:
            return float(abs(roll[0, 1] - roll[0, 0]))
        values = np.unique(roll[:, 0])
        return float(np.diff(values).min()) if len(values) > 1 else math.pi

    def _fits(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """(E,) whether every wide joint's unwrapped range fits its limits (after a shift by
        whole turns when the start is free)."""
        w = self.wide
        if not w.any():
            return np.ones(len(lo), dtype=bool)
        lower, upper = self.lower[w], self.upper[w]
        low, high = lo[:, w], hi[:, w]
        if self.start is None:
            turns = np.ceil((lower - low) / TAU - 1e-12)
            return np.all(high + TAU * turns <= upper + 1e-9, axis=1)
        return np.all((low >= lower - 1e-9) & (high <= upper + 1e-9), axis=1)

    def _shift(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Whole turns (nq,) [rad] that centre each wide joint's range within its limits."""
        shift = np.zeros(len(lo))
        if self.start is not None:
            return shift
        for j in np.flatnonzero(self.wide):
            first = math.ceil((self.lower[j] - lo[j]) / TAU - 1e-12)
            last = math.floor((self.upper[j] - hi[j]) / TAU + 1e-12)
            centre = round((0.5 * (self.lower[j] + self.upper[j]) - 0.5 * (lo[j] + hi[j])) / TAU)
            shift[j] = TAU * min(max(centre, first), max(first, last))
        return shift

    def _paths(self, rows, backs, states, cost, count) -> list[LadderPath]:
        K = len(rows)
        order = np.argsort(cost, kind="stable")
        paths: list[LadderPath] = []
        starts: set[int] = set()
        c = self.candidates
        tilt_of = c.tilt
        _, S, B, I = self.shape
        for end in order.tolist():
            chain = [end]
            for k in range(K - 1, 0, -1):
                chain.append(int(backs[k - 1][chain[-1]]))
            chain.reverse()
            start_node = int(rows[0][chain[0]])
            if start_node in starts:
                continue
            starts.add(start_node)
            U = np.array([states[k][0][chain[k]] for k in range(K)])
            roll = np.array([states[k][3][chain[k]] for k in range(K)])
            nodes = np.array([rows[k][chain[k]] for k in range(K)])
            lo, hi = states[-1][1][end], states[-1][2][end]
            slots = np.where(nodes >= 0, nodes // (B * I), 0)
            tilt = tilt_of[slots]
            if self.start is not None:
                tilt[0] = self.start_tilt
            paths.append(LadderPath(nodes, U + self._shift(lo, hi), roll, tilt, float(cost[end])))
            if len(paths) >= count:
                break
        return paths

    def _blocked(self, k, delta, step_ok, lo, hi, reached) -> Blocked:
        """Why no edge into rung k survives (the edges tested: ``delta`` etc.)."""
        if step_ok.any():  # joints fit the time but some wide joint winds beyond its limits
            w = np.flatnonzero(self.wide)
            span = (hi - lo)[step_ok][:, w]
            room = (self.upper - self.lower)[w]
            joint = int(w[np.argmax((span / room).min(axis=0))]) if len(w) else 0
            return Blocked(k, "joint_limit", joint, reached=reached)
        if len(delta) == 0:
            return Blocked(k, "jump", 0, reached=reached)
        ratio = np.abs(delta) / self.caps[k - 1]
        worst = ratio.max(axis=1)
        best = int(np.argmin(worst))
        joint = int(np.argmax(ratio[best]))
        jump = np.abs(delta[best, joint]) > self.jump_caps[joint]
        speed_cap = self.caps[k - 1, joint] < self.jump_caps[joint]
        kind = "velocity_limit" if speed_cap and not jump else "jump"
        return Blocked(k, kind, joint, float(worst[best]), reached)
