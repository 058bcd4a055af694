"""IK iteration counts are bounded (issue 26): ``robot.ik(..., max_iterations=10**9)`` on an arm
without a closed form ran past 30 s. Counts beyond the bounds of
:func:`kinplan.ik.numeric.check_effort` are refused at once with a message saying what fits;
counts within them keep working."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest
from conftest import TESTS

import kinplan
from kinplan.errors import InputError
from kinplan.ik import numeric

UNREACHABLE = np.array([5.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def arm():
    """A 6-joint arm without a closed form: the numerical solver (tests/urdf/skewed_axes: no
    two of its axes meet or are parallel; the kinova, used before, has a spherical wrist since
    issue 29, and the z1 after it three parallel axes)."""
    robot = kinplan.load_robot(TESTS / "urdf" / "skewed_axes.urdf")
    assert robot.closed_form_ik is None
    return robot


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"max_iterations": 10**9}, "max_iterations must be at most 10,000"),
        ({"max_restarts": 10**9}, "max_restarts must be at most 10,000"),
        ({"max_iterations": 10**400}, "max_iterations must be at most 10,000"),
        ({"max_iterations": 2000, "max_restarts": 100}, "would allow 212,000 iterations"),
    ],
)
@pytest.mark.parametrize("batch", [False, True])
def test_absurd_counts_are_refused_at_once(arm, options, fragment, batch):
    started = time.perf_counter()
    with pytest.raises(InputError, match=fragment):
        if batch:
            arm.ik_batch(UNREACHABLE[None, :], **options)
        else:
            arm.ik(UNREACHABLE, **options)
    assert time.perf_counter() - started < 1.0


def test_the_printed_remedy_fits(arm):
    with pytest.raises(InputError) as info:
        arm.ik(UNREACHABLE, max_iterations=2000, max_restarts=100)
    found = re.search(r"max_iterations ≤ ([\d,]+) or max_restarts ≤ ([\d,]+)", str(info.value))
    iterations, restarts = (int(text.replace(",", "")) for text in found.groups())
    for options in ({"max_iterations": iterations, "max_restarts": 100},
                    {"max_iterations": 2000, "max_restarts": restarts}):  # fmt: skip
        numeric.check_effort(options["max_iterations"], options["max_restarts"])
    with pytest.raises(InputError):
        numeric.check_effort(iterations + 1, 100)
    with pytest.raises(InputError):
        numeric.check_effort(2000, restarts + 1)


def test_counts_within_the_bounds_work_and_finish(arm):
    started = time.perf_counter()
    result = arm.ik(UNREACHABLE, max_iterations=1000, max_restarts=40)
    assert not result.success
    low, high = numeric.finite_bounds(arm.lower, arm.upper)
    middle = np.where(np.isfinite(arm.lower), 0.5 * (low + high), 0.3)
    target, seed = arm.fk(middle), middle + 0.05
    assert arm.ik(target, seed, max_iterations=numeric.MAX_ITERATIONS, max_restarts=0).success
    q, ok = arm.ik_batch(UNREACHABLE[None, :], max_iterations=1000, max_restarts=40)
    assert not ok[0]
    assert time.perf_counter() - started < 20.0


def test_the_worst_allowed_solve_is_bounded():
    """The bound itself: the most iterations any allowed pair of counts permits."""
    worst = max(
        (restarts + 2 + 2 * numeric.POLISH_ITERATIONS if restarts else 1) * iterations
        for iterations in (1, 40, 1000, numeric.MAX_ITERATIONS)
        for restarts in range(0, numeric.MAX_RESTARTS + 1, 250)
        if _allowed(iterations, restarts)
    )
    assert worst <= numeric.MAX_SOLVE_ITERATIONS


def _allowed(iterations: int, restarts: int) -> bool:
    try:
        numeric.check_effort(iterations, restarts)
    except InputError:
        return False
    return True
