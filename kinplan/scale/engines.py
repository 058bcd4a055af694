"""Where batch work runs: in this process, on a Dask ``LocalCluster``, or on a Dask scheduler.

Every batch job of kinplan (:func:`kinplan.scale.reach.capability_map`,
:func:`kinplan.scale.placement.place`,
:func:`kinplan.scale.batch.plan_many`) is a list of **work items**: a module-level function called
as
``function(chunk, payload=payload)``, pure in its arguments (the payload holds the URDF or
program *text* and the options, never an object of this process), so the same items give
bit-identical results wherever they run. :func:`open_engine` gives the engine that runs them:

* ``"local"`` (default): in this process, one item after the other; needs nothing;
* ``"dask"`` with ``jobs=N``: a ``LocalCluster`` of N single-threaded worker processes started
  for the job and closed after it;
* ``"dask"`` with ``scheduler="tcp://HOST:8786"``: an existing Dask scheduler, whose workers
  must have the same kinplan installed (and see the same files for URDF paths, meshes and
  programs given by path);
* a ``distributed.Client`` the caller already has.

Dask is an optional dependency (``pip install "kinplan[dask]"``). The Dask engine submits the
items with retries; a worker that dies mid-job has its items rerun elsewhere by the scheduler.
A bad scheduler address fails within :data:`CONNECT_TIMEOUT` seconds with one
:class:`~kinplan.errors.KinplanError`. Ctrl-C cancels the submitted items.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, cast

import numpy as np

from kinplan import checks
from kinplan.errors import InputError, KinplanError

if TYPE_CHECKING:  # type-only: Dask and the robot are imported where they are used
    from distributed import Client

    from kinplan.model.robot import Robot

logger = logging.getLogger(__name__)

#: Seconds to wait for a Dask scheduler before failing.
CONNECT_TIMEOUT = 3.0
#: Times the Dask engine reruns a work item that raised (a worker that dies is handled by the
#: scheduler itself: its items move to another worker).
RETRIES = 2
ENGINES = ("local", "dask")
#: Most worker processes of a LocalCluster started by kinplan.
MAX_JOBS = 256

Progress = Callable[[int, int], None]


class EngineError(KinplanError):
    """An engine could not start (Dask missing, scheduler unreachable) or a work item failed."""


class LocalEngine:
    """Runs work items in this process, in order."""

    name = "local"
    workers = 1

    def map(
        self,
        function: Callable,
        chunks: Sequence[Any],
        payload: Any,
        progress: Progress | None = None,
    ) -> list[Any]:
        """``[function(chunk, payload=payload) for chunk in chunks]``, reporting progress."""
        results = []
        for done, chunk in enumerate(chunks):
            results.append(function(chunk, payload=payload))
            if progress is not None:
                progress(done + 1, len(chunks))
        return results

    def describe(self) -> str:
        return "in-process"


class DaskEngine:
    """Runs work items on a Dask cluster through ``client``.

    Args:
        client: A ``distributed.Client``.
        description: How the cluster is named in messages.
    """

    name = "dask"

    def __init__(self, client: Client, description: str) -> None:
        self.client = client
        self._description = description

    @property
    def workers(self) -> int:
        try:
            return max(1, len(self.client.scheduler_info(n_workers=-1)["workers"]))
        except Exception:  # only for messages
            return 1

    def describe(self) -> str:
        return self._description

    def map(
        self,
        function: Callable,
        chunks: Sequence[Any],
        payload: Any,
        progress: Progress | None = None,
    ) -> list[Any]:
        """The results of ``function(chunk, payload=payload)`` for every chunk, in order.

        The payload is sent to the workers once; items are retried :data:`RETRIES` times.
        Ctrl-C (or any error) cancels what is still queued.
        """
        from distributed import as_completed

        client = self.client
        if not chunks:
            return []
        # a list of one: scatter would send a dict's values as separate keys
        [shared] = client.scatter([payload], broadcast=True, hash=False)
        futures = client.map(function, list(chunks), payload=shared, retries=RETRIES, pure=False)
        try:
            done = 0
            for future in as_completed(futures):
                if future.status == "error":
                    future.result()  # raises the item's exception
                done += 1
                if progress is not None:
                    progress(done, len(futures))
            return client.gather(futures)
        except BaseException:
            client.cancel(futures)
            raise


def _dask_missing() -> EngineError:
    return EngineError(
        "the Dask engine needs dask.distributed: pip install 'kinplan[dask]' "
        "(or run with engine='local' / without --jobs and --scheduler)"
    )


@contextmanager
def open_engine(
    engine: object = "local",
    scheduler: str | None = None,
    jobs: int | None = None,
    timeout: float = CONNECT_TIMEOUT,
) -> Iterator[LocalEngine | DaskEngine]:
    """The engine to run work items on, closed (a cluster it started shut down) on exit.

    Args:
        engine: ``"local"``, ``"dask"``, or a ``distributed.Client``.
        scheduler: Address of a Dask scheduler (``tcp://HOST:8786``); implies ``"dask"``.
        jobs: Worker processes of a ``LocalCluster`` started for the job (``"dask"`` without a
            scheduler; default: the machine's cores). ``jobs=1`` without a scheduler runs
            locally.
        timeout: Seconds to wait for the scheduler [s].

    Raises:
        InputError: an unknown engine, ``jobs`` not an integer from 1 to :data:`MAX_JOBS`,
            both ``jobs`` and ``scheduler``.
        EngineError: Dask is not installed, the scheduler cannot be reached in ``timeout``,
            the cluster cannot start.
    """
    if jobs is not None:
        jobs = _jobs(jobs)
    if scheduler is not None:
        scheduler = checks.text(scheduler, "scheduler (a Dask scheduler address)")
        if jobs is not None:
            raise InputError(
                "give either jobs (a LocalCluster of worker processes started here) or "
                "scheduler (the address of a running Dask scheduler), not both"
            )
        if engine == "local":
            engine = "dask"
    if not isinstance(engine, str):
        if type(engine).__name__ != "Client" or not hasattr(engine, "map"):
            raise InputError(
                f"engine must be one of {', '.join(ENGINES)} or a distributed.Client, got "
                f"{checks.describe(engine)}"
            )
        address = getattr(getattr(engine, "scheduler", None), "address", "?")
        # a distributed.Client, recognised above without importing distributed
        yield DaskEngine(cast("Client", engine), f"Dask cluster of {address}")
        return
    engine = checks.choice(engine, "engine", ENGINES)
    if engine == "local" and (jobs is None or jobs == 1):
        yield LocalEngine()
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise _dask_missing() from None
    if scheduler is not None:
        client = _connect(Client, scheduler, timeout)
        try:
            yield DaskEngine(client, f"Dask scheduler {scheduler}")
        finally:
            client.close()
        return
    workers = jobs or os.cpu_count() or 1
    # Ctrl-C in a terminal interrupts the whole process group: the workers start with SIGINT
    # ignored (inherited through the spawn), so only this process stops them, quietly
    previous = _ignore_interrupts()
    try:
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.ERROR,
        )
    except Exception as exc:  # a cluster that cannot start: one line
        raise EngineError(f"cannot start a Dask LocalCluster of {workers} workers: {exc}") from exc
    finally:
        _restore_interrupts(previous)
    client = Client(cluster)
    try:
        yield DaskEngine(client, f"Dask LocalCluster of {workers} workers")
    finally:
        client.close()
        cluster.close()


def _jobs(jobs: object) -> int:
    """``jobs`` as a number of worker processes, 1 to :data:`MAX_JOBS`."""
    count = checks.count(jobs, "jobs (worker processes)", minimum=1)
    if count > MAX_JOBS:
        raise InputError(
            f"jobs (worker processes) must be at most {MAX_JOBS}, got {count}; this machine has "
            f"{os.cpu_count() or 1} cores (more workers than cores only wait for each other)"
        )
    return count


def batch_options(
    engine: object, jobs: object, progress: object
) -> tuple[object, int | None, Progress | None]:
    """The checked engine arguments of a batch job (:func:`kinplan.scale.reach.capability_map`,
    :func:`kinplan.scale.placement.place`, :func:`kinplan.scale.batch.plan_many`): ``(engine, jobs
    for
    open_engine, progress)``. ``jobs > 1`` with the ``"local"`` engine means ``"dask"``; the
    local engine takes no jobs.

    Raises:
        InputError: ``jobs`` not an integer from 1 to :data:`MAX_JOBS`, ``progress`` neither
            None nor callable.
    """
    count = None if jobs is None else _jobs(jobs)
    if progress is not None and not callable(progress):
        raise InputError(
            f"progress must be None or a function called as progress(done, total), got "
            f"{checks.describe(progress)}"
        )
    local = isinstance(engine, str) and engine == "local"
    if local and count is not None and count > 1:
        engine, local = "dask", False
    return engine, (None if local else count), cast("Progress | None", progress)


def _ignore_interrupts():
    """Ignore SIGINT (main thread only); return what to restore (None: nothing changed)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGINT, signal.SIG_IGN)


def _restore_interrupts(previous) -> None:
    import signal

    if previous is not None:
        signal.signal(signal.SIGINT, previous)


def _connect(client_class, address: str, timeout: float):
    try:
        return client_class(address, timeout=timeout)
    except (OSError, ValueError, TypeError) as exc:  # unreachable, refused, malformed
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise EngineError(
            f"cannot reach the Dask scheduler at {address} within {timeout:g} s ({reason}); "
            "start one with `dask scheduler` and workers with `dask worker ADDRESS`, check the "
            "address, or run locally with --jobs N"
        ) from None


# ---------------------------------------------------------------------------- robots as text
def robot_payload(robot: Robot) -> dict[str, Any]:
    """What a worker needs to rebuild ``robot``: its URDF text and load options (plain data).

    The joint limits are passed as overrides, so a robot loaded with ``limits=`` (or with a
    tool, :meth:`kinplan.Robot.with_tool`) is rebuilt the same.
    """
    text = Path(robot.urdf_path).read_text(encoding="utf-8")
    limits = robot.limit_overrides()
    base = robot.base_pose
    return {
        "urdf": text,
        "urdf_folder": str(Path(robot.urdf_path).parent),
        "name": robot.name,
        "tip": robot.tip_frame,
        "locked_joints": {k: float(v) for k, v in robot.locked_joints.items()},
        "base_pose": None if base.isIdentity() else base.homogeneous.tolist(),
        "limits": limits,
        "package_dirs": [str(p) for p in robot.package_dirs],
        # a robot with a tool (Robot.with_tool): which links are tool bodies, where its SRDF is
        "tool_links": list(getattr(robot, "tool_links", ())),
        "source_urdf_path": str(getattr(robot, "source_urdf_path", None) or robot.urdf_path),
    }


def payload_digest(payload: dict[str, Any]) -> str:
    """A hash of a robot payload (the key of the worker's robot cache)."""
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


_ROBOTS: dict[str, Any] = {}


def robot_from_payload(payload: dict[str, Any]) -> Robot:
    """The robot of :func:`robot_payload`, built once per process and thread (cached by
    content: a robot's kinematics data are its own, so threads of a worker do not share one)."""
    import threading

    key = f"{payload_digest(payload)}-{threading.get_ident()}"
    robot = _ROBOTS.get(key)
    if robot is not None:
        return robot
    import pinocchio as pin

    from kinplan.model.robot import Robot
    from kinplan.model.sources import RobotSpec

    text = payload["urdf"]
    folder = Path(tempfile.gettempdir()) / "kinplan-urdf"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"work_{hashlib.sha256(text.encode()).hexdigest()[:20]}.urdf"
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        handle, temporary = tempfile.mkstemp(dir=folder, suffix=".urdf.tmp")
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
        os.replace(temporary, path)
    dirs = tuple(Path(p) for p in payload["package_dirs"]) + (Path(payload["urdf_folder"]),)
    spec = RobotSpec(name=payload["name"], urdf_path=path, package_dirs=dirs)
    base = payload["base_pose"]
    robot = Robot(
        spec,
        payload["tip"],
        locked_joints=payload["locked_joints"] or None,
        base_pose=None if base is None else pin.SE3(np.array(base)),
        limits=payload["limits"] or None,
    )
    robot.tool_links = tuple(payload["tool_links"])
    robot.source_urdf_path = Path(payload["source_urdf_path"])
    if len(_ROBOTS) > 16:
        _ROBOTS.clear()
    _ROBOTS[key] = robot
    return robot


def write_atomically(
    path: str | os.PathLike[str], write: Callable[[Any], None], binary: bool
) -> Path:
    """Write a file through ``write(stream)`` into a temporary file beside it, then rename it
    into place: an interrupted write (Ctrl-C, a crash) leaves no half-written file.

    Returns:
        The path written.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(
        dir=target.parent, prefix=f".{target.name}.", suffix=".tmp"
    )
    try:
        stream: IO[Any]
        with (
            os.fdopen(handle, "wb") if binary else os.fdopen(handle, "w", encoding="utf-8")
        ) as stream:
            write(stream)
        os.chmod(temporary, 0o666 & ~_umask())  # mkstemp makes it private: as open() would
        os.replace(temporary, target)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise
    return target


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_ALLOCATOR_TUNED = False
#: glibc's mallopt parameters.
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3


def tune_allocator() -> None:
    """Undo, in a Dask worker, the cost of ``MALLOC_TRIM_THRESHOLD_=65536``.

    Dask's nanny starts workers with that variable (to hand freed memory back to the system).
    Setting it also freezes glibc's mmap threshold at 128 kB, so every numpy temporary of a work
    item (many of 0.1–5 MB) is mapped and unmapped afresh: measured 1.7× slower map chunks. In
    a process that has the variable (a worker), the thresholds are raised to 32 MB (mmap) and
    64 MB (trim) once; elsewhere nothing changes. Results do not depend on it.
    """
    global _ALLOCATOR_TUNED
    if _ALLOCATOR_TUNED:
        return
    _ALLOCATOR_TUNED = True
    if "MALLOC_TRIM_THRESHOLD_" not in os.environ or not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(_M_MMAP_THRESHOLD, 32 * 2**20)
        libc.mallopt(_M_TRIM_THRESHOLD, 64 * 2**20)
    except (OSError, AttributeError):  # not glibc: nothing to undo
        pass
