"""Robot.ik_batch on several threads: the same answers as on one (the same successes, q to the
last bits of rounding: numpy's BLAS rounds a column of a product by where it lies in the block,
as the batch's chunks already do); who decides how many threads; the compiled kernels release
the GIL (else the threads would take turns)."""

from __future__ import annotations

import importlib
import os
import signal
import threading

import numpy as np
import pytest
from conftest import TESTS, cached_robot
from parallel_arms import parallel_arm_urdf

import kinplan
from kinplan.errors import InputError
from kinplan.ik import batch_threads
from kinplan.ik.batch_threads import THREADED_FROM, WARM_UP, split_run, thread_count

URDF = TESTS / "urdf"


def _poses(robot: kinplan.Robot, rng: np.random.Generator, count: int) -> np.ndarray:
    """(count, 4, 4): FK of random configurations, one in five moved 0.5–1.5 m away (mostly
    unreachable: failures must split the same way too)."""
    kinematics = robot.batch_solver.kinematics
    q = np.array([robot.random_configuration(rng) for _ in range(count)])
    positions, rotations = kinematics.fk(q)
    positions[::5] += rng.uniform(0.5, 1.5, (len(positions[::5]), 3))
    poses = np.zeros((count, 4, 4))
    poses[:, :3, :3], poses[:, :3, 3], poses[:, 3, 3] = rotations, positions, 1.0
    return poses


@pytest.mark.parametrize(
    ("source", "count"),
    [
        ("ur5", 3000),
        ("panda", 1500),
        ("planar_2r", 3000),
        (URDF / "skewed_axes.urdf", 300),  # numerical (compiled LM)
        (URDF / "prismatic_gantry.urdf", 300),  # numerical (numpy LM)
        ("three parallel", 1500),  # ThreeParallelIK (a synthetic arm)
    ],
)
def test_threads_give_the_answers_of_one_thread(source, count, tmp_path):
    if source == "three parallel":
        source = tmp_path / "parallel.urdf"
        source.write_text(parallel_arm_urdf(1))
        assert "three parallel" in kinplan.load_robot(source).ik_solver.description
    robot = cached_robot(source) if isinstance(source, str) else kinplan.load_robot(source)
    rng = np.random.default_rng([5, count])
    poses = _poses(robot, rng, count)
    if robot.nq == 2:  # the planar arm: positions only
        targets, options = poses[:, :3, 3], {"position_only": True}
    else:
        targets, options = poses, {}
    seeds = np.array([robot.random_configuration(rng) for _ in range(count)])
    q1, ok1 = robot.ik_batch(targets, q_seed=seeds, threads=1, **options)
    assert 0 < ok1.sum() < count  # reachable and unreachable targets both
    for threads in (2, 3):
        q, ok = robot.ik_batch(targets, q_seed=seeds, threads=threads, **options)
        np.testing.assert_array_equal(ok, ok1)
        # failures' best attempts included; 1e-12 rad is ~4,000 times the rounding of angles
        np.testing.assert_allclose(q, q1, rtol=0.0, atol=1e-12)


def test_split_run_joins_the_parts_in_order():
    calls: list[tuple[int, int, str]] = []

    def solve(part: slice) -> tuple[np.ndarray, ...]:
        calls.append((part.start, part.stop, threading.current_thread().name))
        index = np.arange(part.start, part.stop)
        return index * 2.0, index % 3 == 0

    here = threading.current_thread().name
    for warm_up in (True, False):
        calls.clear()
        doubled, thirds = split_run(solve, 1000, 3, warm_up)
        np.testing.assert_array_equal(doubled, 2.0 * np.arange(1000))
        np.testing.assert_array_equal(thirds, np.arange(1000) % 3 == 0)
        first = WARM_UP if warm_up else 0
        if warm_up:  # alone in the calling thread, before the others
            assert calls.pop(0) == (0, WARM_UP, here)
        parts = sorted(calls)
        assert len(parts) == 3 and parts[0][0] == first and parts[-1][1] == 1000
        assert all(a[1] == b[0] for a, b in zip(parts, parts[1:]))  # contiguous, no overlap
        assert parts[0][2] == here  # the first part in the calling thread, the others pooled
        assert all(name.startswith("kinplan-ik") for _, _, name in parts[1:])
    assert split_run(solve, WARM_UP + 2, 3)[0].shape == (WARM_UP + 2,)  # too few: one call


def test_a_failing_part_raises_after_the_others_end():
    ended: list[int] = []

    def solve(part: slice) -> tuple[np.ndarray, ...]:
        if part.start == 0:
            raise ValueError("part 0 failed")
        ended.append(part.start)
        return (np.arange(part.start, part.stop),)

    with pytest.raises(ValueError, match="part 0 failed"):
        split_run(solve, 900, 3, warm_up=False)
    assert sorted(ended) == [300, 600]


def test_pools_are_started_again_in_a_forked_child():
    """The kept pool's threads do not survive ``fork``: a child must not wait on them."""

    def solve(part: slice) -> tuple[np.ndarray, ...]:
        return (np.arange(part.start, part.stop),)

    split_run(solve, 1000, 2)  # the pool exists in this process
    pid = os.fork()
    if pid == 0:  # the child: answers within 20 s or is killed by the alarm
        signal.alarm(20)
        ok = np.array_equal(split_run(solve, 1000, 2)[0], np.arange(1000))
        os._exit(0 if ok else 1)
    _, status = os.waitpid(pid, 0)
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, status


def test_thread_count_choice(monkeypatch):
    monkeypatch.delenv("KINPLAN_THREADS", raising=False)
    monkeypatch.setattr(batch_threads, "available_cores", lambda: 4)
    assert thread_count(THREADED_FROM - 1) == 1  # a small batch: one thread
    assert thread_count(THREADED_FROM) == 4  # one per core
    assert thread_count(10, 3) == 3  # the caller's choice wins
    assert thread_count(2, 8) == 2  # never more threads than targets
    monkeypatch.setenv("KINPLAN_THREADS", "2")
    assert thread_count(THREADED_FROM) == 2
    monkeypatch.setenv("KINPLAN_JIT", "0")  # the pure-Python loops: one thread, unless asked
    assert thread_count(THREADED_FROM) == 1 and thread_count(THREADED_FROM, 2) == 2
    monkeypatch.delenv("KINPLAN_JIT")
    answers: list[int] = []  # another thread (Dask's workers, a pool): one thread
    worker = threading.Thread(target=lambda: answers.append(thread_count(10**6)))
    worker.start()
    worker.join()
    assert answers == [1]


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_bad_thread_counts_are_refused(ur5, bad):
    with pytest.raises(InputError, match="threads must be a positive integer"):
        ur5.ik_batch(np.eye(4)[None], threads=bad)


@pytest.mark.parametrize("setting", ["0", "two", "-3"])
def test_bad_environment_setting_is_refused(monkeypatch, setting):
    monkeypatch.setenv("KINPLAN_THREADS", setting)
    with pytest.raises(InputError, match="KINPLAN_THREADS must be a positive integer"):
        thread_count(THREADED_FROM)


def test_large_batches_use_the_cores_from_the_main_thread_only(monkeypatch):
    used: list[tuple[int, bool]] = []
    original = split_run

    def recording(solve, count, threads, warm_up=True):
        used.append((threads, warm_up))
        return original(solve, count, threads, warm_up)

    monkeypatch.setattr("kinplan.ik.batch.split_run", recording)
    monkeypatch.setattr(batch_threads, "available_cores", lambda: 2)
    monkeypatch.delenv("KINPLAN_THREADS", raising=False)
    ur5 = kinplan.load_robot("ur5")  # a solver of its own: its first threaded batch warms up
    poses = np.tile(ur5.fk(ur5.neutral()).homogeneous, (THREADED_FROM, 1, 1))
    ur5.ik_batch(poses)
    worker = threading.Thread(target=lambda: ur5.ik_batch(poses))
    worker.start()
    worker.join()
    ur5.ik_batch(poses[:100])
    ur5.ik_batch(poses)
    assert [threads for threads, _ in used] == [2, 1, 1, 2]
    assert used[0][1] and not used[3][1]  # only the first threaded batch warms up


KERNELS = [
    "kinplan.ik.ur_kernel",
    "kinplan.ik.panda_kernel",
    "kinplan.ik.spherical_wrist_kernel",
    "kinplan.ik.wrist_offset_kernel",
    "kinplan.ik.numeric_kernel",
    "kinplan.ik.batch_kinematics_kernel",
]


@pytest.mark.parametrize("name", KERNELS)
def test_compiled_kernels_release_the_gil(name):
    numba = pytest.importorskip("numba")
    module = importlib.import_module(name)
    dispatcher = numba.core.registry.CPUDispatcher
    dispatchers = [value for value in vars(module).values() if isinstance(value, dispatcher)]
    assert dispatchers, f"{name} has no compiled functions"
    assert all(d.targetoptions.get("nogil") for d in dispatchers), [
        d.__name__ for d in dispatchers if not d.targetoptions.get("nogil")
    ]


def test_numpy_steps_and_python_loops_keep_to_one_thread(monkeypatch):
    """A numerical arm without the compiled solve (a prismatic joint: numpy's small steps hold
    the GIL) runs on one thread even when asked for more; a compiled one on those asked for."""
    used: list[int] = []
    original = split_run

    def recording(solve, count, threads, *rest):
        used.append(threads)
        return original(solve, count, threads, *rest)

    monkeypatch.setattr("kinplan.ik.batch.split_run", recording)
    gantry = kinplan.load_robot(URDF / "prismatic_gantry.urdf")
    skewed = kinplan.load_robot(URDF / "skewed_axes.urdf")
    assert not gantry.ik_solver.compiled and skewed.ik_solver.compiled
    for robot in (gantry, skewed):
        robot.ik_batch(np.tile(robot.fk(robot.neutral()).homogeneous, (4, 1, 1)), threads=2)
    assert used == [1, 2]
