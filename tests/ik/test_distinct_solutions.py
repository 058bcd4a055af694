"""The compiled list of a pose's distinct solutions (``spherical_wrist_kernel.distinct``, what
every closed form's ``solutions`` returns) against numpy's form
(:meth:`kinplan.ik.base.ClosedFormIK._distinct` without numba): the same rows to the bit over
thousands of seeded random cases: NaN rows, rows 2π apart, chains of near-equal rows, rows
equal across ±π, values at the limits' tolerance, bounded and continuous joints."""

from __future__ import annotations

import numpy as np
import pytest

from kinplan.ik import spherical_wrist_kernel
from kinplan.ik.base import ClosedFormIK
from kinplan.ik.screws import DISTINCT_TOL, LIMIT_TOL, TAU

pytestmark = pytest.mark.skipif(
    not spherical_wrist_kernel.available(), reason="numba missing or KINPLAN_JIT=0"
)


def _limits(rng: np.random.Generator, nq: int) -> tuple[np.ndarray, np.ndarray]:
    kind = rng.integers(4, size=nq)
    lower = np.where(kind == 0, -np.inf, -rng.uniform(0.1, 2.5 * np.pi, nq))
    upper = np.where(kind == 0, np.inf, rng.uniform(0.1, 2.5 * np.pi, nq))
    narrow = kind == 1
    lower[narrow], upper[narrow] = -0.3, 0.2
    return lower, upper


def _raw(rng: np.random.Generator, nq: int, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    rows = int(rng.integers(1, 17))
    raw = rng.uniform(-3 * np.pi, 3 * np.pi, (rows, nq))
    for r in range(rows):
        pick = rng.integers(7)
        if pick == 0:
            raw[r] = np.nan
        elif pick == 1 and r > 0:  # another row, some joints a whole turn away
            raw[r] = raw[rng.integers(r)] + TAU * rng.integers(-1, 2, nq)
        elif pick == 2 and r > 0:  # another row within or just past the tolerance
            step = rng.choice([0.3, 0.6, 0.99, 1.01, 1.5]) * DISTINCT_TOL
            raw[r] = raw[r - 1] + step * rng.choice([-1.0, 1.0], nq)
        elif pick == 4 and r > 0:  # another row, a joint at −π where that one is at π
            j = rng.integers(nq)
            raw[r] = raw[r - 1]
            raw[r - 1, j] = np.pi - rng.uniform(0.0, 0.4) * DISTINCT_TOL
            raw[r, j] = -np.pi + rng.uniform(0.0, 0.4) * DISTINCT_TOL
        elif pick == 3:  # at a limit, within or past its tolerance
            j = rng.integers(nq)
            edge = lower[j] if rng.random() < 0.5 else upper[j]
            if np.isfinite(edge):
                raw[r, j] = edge + rng.choice([-2.0, -0.5, 0.5, 2.0]) * LIMIT_TOL
    return raw


def _numpy_distinct(solver: ClosedFormIK, raw: np.ndarray, monkeypatch) -> np.ndarray:
    with monkeypatch.context() as patch:
        patch.setattr(spherical_wrist_kernel, "available", lambda: False)
        return solver._distinct(raw)


def test_compiled_distinct_rows_equal_numpys_to_the_bit(monkeypatch):
    rng = np.random.default_rng(29)
    kept_counts = set()
    for _ in range(3_000):
        nq = int(rng.choice([2, 6, 7]))
        lower, upper = _limits(rng, nq)
        solver = ClosedFormIK(lower, upper)
        raw = _raw(rng, nq, lower, upper)
        compiled = solver._distinct(raw)
        expected = _numpy_distinct(solver, raw, monkeypatch)
        assert compiled.shape == expected.shape
        assert np.array_equal(compiled, expected), (raw, lower, upper)
        kept_counts.add(len(compiled))
    assert {0, 1} <= kept_counts and max(kept_counts) >= 8  # the cases reach every outcome


def test_a_chain_of_near_equal_rows_drops_each_after_the_first(monkeypatch):
    """B within the tolerance of A, C of B but not of A: B and C are both dropped (each is
    equal to an earlier row, repeated or not), as numpy's form decides."""
    solver = ClosedFormIK(np.full(6, -np.pi), np.full(6, np.pi))
    a = np.linspace(-1.0, 1.0, 6)
    raw = np.array([a, a + 0.6 * DISTINCT_TOL, a + 1.2 * DISTINCT_TOL, a + 0.5])
    compiled = solver._distinct(raw)
    assert np.array_equal(compiled, raw[[0, 3]])
    assert np.array_equal(compiled, _numpy_distinct(solver, raw, monkeypatch))
