"""One engine, three scales: the same work items give bit-identical results in this process, on a
Dask LocalCluster started here and on a Dask scheduler + worker launched as separate processes
on 127.0.0.1; a worker that dies loses no work; a bad scheduler address fails in one line; Ctrl-C
leaves no half-written file.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import REPOSITORY, TESTS

import kinplan
from kinplan.scale.batch import plan_many
from kinplan.scale.engines import CONNECT_TIMEOUT, EngineError, open_engine
from kinplan.scale.placement import place
from kinplan.scale.reach import capability_map

distributed = pytest.importorskip("distributed", reason="the Dask engine needs kinplan[dask]")
# two clusters in one session: the second's HTTP server moves to another port, and says so
pytestmark = pytest.mark.filterwarnings("ignore:Port .* is already in use")

EXAMPLES = REPOSITORY / "examples" / "programs"
URDF = TESTS / "urdf"
KINPLAN = [sys.executable, "-m", "kinplan.apps.cli"]


@pytest.fixture(scope="module")
def local_cluster():
    """A LocalCluster of two single-threaded worker processes, and its client."""
    import logging

    cluster = distributed.LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


@pytest.fixture(scope="module")
def remote_scheduler(tmp_path_factory):
    """A Dask scheduler and one worker, each its own process, on 127.0.0.1: the address."""
    folder = tmp_path_factory.mktemp("dask")
    file = folder / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL, "cwd": folder}
    scheduler = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1"]
        + ["--port", "0", "--no-dashboard", "--scheduler-file", str(file)],
        **quiet,
    )
    processes = [scheduler]
    try:
        deadline = time.monotonic() + 30.0
        while not (file.is_file() and file.stat().st_size) and time.monotonic() < deadline:
            if scheduler.poll() is not None:
                pytest.skip(f"the Dask scheduler exited at start ({scheduler.returncode})")
            time.sleep(0.1)
        if not file.is_file():
            pytest.skip("the Dask scheduler did not start within 30 s")
        address = json.loads(file.read_text())["address"]
        worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1"]
            + ["--nworkers", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"],
            **quiet,
        )
        processes.append(worker)
        with distributed.Client(address, timeout=10) as client:
            client.wait_for_workers(1, timeout=30)
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()


def _same(a, b) -> None:
    for name in ("centers", "index", "manipulability", "branches"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes(), name


def test_three_engines_give_bit_identical_results(local_cluster, remote_scheduler):
    ur5 = kinplan.load_robot("ur5")
    skewed = kinplan.load_robot(URDF / "skewed_axes.urdf")
    maps = {}
    for label, options in (
        ("local", {}),
        ("cluster", {"engine": local_cluster}),
        ("remote", {"scheduler": remote_scheduler}),
    ):
        maps[label] = (
            capability_map(ur5, 0.25, 8, chunk_targets=512, **options),
            capability_map(skewed, 0.4, 2, chunk_targets=32, **options),
        )
    assert maps["local"][0].info["chunks"] >= 4 and maps["local"][1].info["chunks"] >= 4
    assert maps["cluster"][0].info["engine"].startswith("Dask cluster")
    assert maps["remote"][0].info["engine"] == f"Dask scheduler {remote_scheduler}"
    for label in ("cluster", "remote"):
        for here, there in zip(maps["local"], maps[label]):
            _same(here, there)
    programs = [EXAMPLES / "lecture_2r.yaml", EXAMPLES / "weld_unreachable.yaml"]
    runs = [
        plan_many(programs),
        plan_many(programs, engine=local_cluster),
        plan_many(programs, scheduler=remote_scheduler),
    ]
    for run in runs[1:]:
        for a, b in zip(runs[0], run):
            assert {**a.as_dict(), "seconds": 0} == {**b.as_dict(), "seconds": 0}
    assert [s.ok for s in runs[0]] == [True, False]


def test_placement_is_the_same_on_a_cluster(local_cluster):
    options = {"x": (-0.1, 0.1), "y": (0.0,), "step": 0.1}
    here = place(EXAMPLES / "lecture_2r.yaml", **options)
    there = place(EXAMPLES / "lecture_2r.yaml", engine=local_cluster, **options)
    assert [repr(p) for p in here.placements] == [repr(p) for p in there.placements]  # NaN too
    assert here.best.ok and not here.placements[-1].ok  # x = 0.1 m: a point out of reach
    assert here.placements[-1].xyz == (0.1, 0.0, 0.0)


def test_a_worker_that_dies_loses_no_chunk(local_cluster):
    robot = kinplan.load_robot("ur5")
    expected = capability_map(robot, 0.15, 8, chunk_targets=512)
    pids = local_cluster.run(os.getpid)  # worker address -> process id
    victim = sorted(pids)[0]
    killed = []

    def kill_one_worker(done, total):
        if not killed:  # after the first chunk: a worker process dies, its chunks are rerun
            killed.append(victim)
            os.kill(pids[victim], signal.SIGKILL)

    got = capability_map(
        robot, 0.15, 8, chunk_targets=512, engine=local_cluster, progress=kill_one_worker
    )
    _same(expected, got)
    assert killed and killed[0] not in local_cluster.scheduler_info(n_workers=-1)["workers"]
    local_cluster.wait_for_workers(2, timeout=30)  # the nanny restarted it


def test_items_that_fail_are_retried(local_cluster, tmp_path):
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    marker = tmp_path / "failed-once"
    with open_engine(local_cluster) as engine:
        results = engine.map(_fails_once, [1, 2, 3], str(marker))
    assert results == [2, 4, 6]
    assert marker.is_file()


def _fails_once(chunk: int, payload: str) -> int:
    marker = Path(payload)
    if chunk == 2 and not marker.exists():
        marker.write_text("x")
        raise OSError("a transient failure")
    return 2 * chunk


def test_jobs_start_and_stop_a_local_cluster():
    robot = kinplan.load_robot("planar_2r")
    reach_map = capability_map(robot, 0.2, jobs=2, chunk_targets=128)
    assert reach_map.info["engine"] == "Dask LocalCluster of 2 workers"
    _same(reach_map, capability_map(robot, 0.2, chunk_targets=128))


def test_bad_scheduler_address_fails_fast_in_one_line(tmp_path):
    with pytest.raises(EngineError, match="cannot reach the Dask scheduler at nonsense::"):
        plan_many([EXAMPLES / "lecture_2r.yaml"], scheduler="nonsense::")
    # The wait is bounded by the connect timeout (measured in process: a command's own start-up,
    # importing Dask, is not the wait and varies with the machine's load).
    started = time.monotonic()
    with pytest.raises(EngineError, match=f"within {CONNECT_TIMEOUT:g} s"):
        plan_many([EXAMPLES / "lecture_2r.yaml"], scheduler="tcp://127.0.0.1:1")
    assert time.monotonic() - started < 3 * CONNECT_TIMEOUT
    for address in ("tcp://127.0.0.1:1", "nonsense::"):
        result = subprocess.run(
            KINPLAN + ["reach", "planar_2r", "-o", str(tmp_path / "m.npz"), "--scheduler", address],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert result.returncode == 1
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("kinplan: error: cannot reach the Dask"), (
            lines
        )
    assert list(tmp_path.iterdir()) == []


def test_engine_arguments_are_checked():
    with pytest.raises(kinplan.InputError, match="not both"):
        with open_engine("dask", scheduler="tcp://127.0.0.1:8786", jobs=2):
            pass
    with pytest.raises(kinplan.InputError, match="jobs"):
        with open_engine("dask", jobs=0):
            pass


#: A plain progress line of `kinplan reach` off a terminal.
PROGRESS_LINE = re.compile(r"kinplan: reach map of \S+: \d+/\d+ chunks( \(\d+ %\))?, [0-9.]+ s")


def _interrupt_a_map(folder: Path, extra: list[str], wait: float) -> None:
    """Start `kinplan reach` in its own process group, press Ctrl-C (SIGINT to the whole group,
    as a terminal does) after ``wait`` seconds: exit 130, progress lines then one line saying
    so, no file."""
    out = folder / "out"
    out.mkdir()
    process = subprocess.Popen(
        KINPLAN + ["reach", "ur5", "-o", str(out / "map.npz"), "--resolution", "0.02", *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        # Ctrl-C's default action, even when this test runs in a background job (whose
        # children inherit SIGINT ignored, and Python then keeps it ignored)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    time.sleep(wait)  # past the imports, into the map (about 30 s of work at 2 cm)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    # off a terminal the map prints plain progress lines once it has worked 3 s (issue 30);
    # then the interruption is one line, no traceback
    *progress, last = stderr.strip().splitlines()
    assert last == "kinplan: interrupted", stderr
    assert all(PROGRESS_LINE.fullmatch(line) for line in progress), stderr
    assert list(out.iterdir()) == []


def test_ctrl_c_leaves_no_half_written_map(tmp_path):
    _interrupt_a_map(tmp_path, [], 3.5)


@pytest.mark.slow
def test_ctrl_c_stops_a_local_cluster_quietly(tmp_path):
    _interrupt_a_map(tmp_path, ["--jobs", "2"], 8.0)
