"""The live viewer: :class:`Viewer` drives a MeshCat server from a script or a notebook.

A :class:`Viewer` starts a local MeshCat server (``python -m meshcat.servers.zmqserver``) or
connects to a running one, and sends it the scene's commands (:mod:`kinplan.viewer.scene`) over
ZeroMQ as MeshCat's own Python client does: :meth:`Viewer.display` a configuration,
:meth:`Viewer.play` a motion (loaded into MeshCat's animation, or stepped through from Python).
"""

from __future__ import annotations

import logging
import queue
import subprocess
import sys
import threading
import time
import weakref
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from kinplan.errors import ViewerError
from kinplan.trajectory.motion import MotionLike
from kinplan.viewer import commands as ms
from kinplan.viewer.meshes import TRIANGLE_BUDGET
from kinplan.viewer.playback import DEFAULT_FPS, Markers, marker_points, playback, positive
from kinplan.viewer.scene import (
    LAYERS,
    animation_command,
    bounding_points,
    environment_commands,
    frame_view,
    overlay_commands,
    pose_commands,
    robot_commands,
    triad_commands,
)
from kinplan.viewer.visuals import visuals_for

if TYPE_CHECKING:
    import zmq

    from kinplan.model.robot import Robot

__all__ = ["Viewer"]

logger = logging.getLogger(__name__)


class _Connection:
    """A ZeroMQ request socket to a MeshCat server (MeshCat's Python client protocol)."""

    def __init__(self, zmq_url: str, timeout: float):
        import zmq

        self._zmq = zmq
        self.zmq_url = zmq_url
        self._timeout_ms = int(1000 * timeout)
        self._socket: zmq.Socket | None = None
        self._connect()

    def _connect(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
        socket: zmq.Socket = self._zmq.Context.instance().socket(self._zmq.REQ)
        socket.setsockopt(self._zmq.RCVTIMEO, self._timeout_ms)
        socket.setsockopt(self._zmq.SNDTIMEO, self._timeout_ms)
        socket.setsockopt(self._zmq.LINGER, 0)
        socket.connect(self.zmq_url)
        self._socket = socket

    def request(self, frames: list[bytes]) -> bytes:
        if self._socket is None:
            raise ViewerError("the viewer is closed")
        try:
            self._socket.send_multipart(frames)
            return self._socket.recv()
        except self._zmq.Again as exc:
            self._connect()  # a REQ socket without its reply is unusable
            raise ViewerError(
                f"the MeshCat server at {self.zmq_url} did not answer within "
                f"{self._timeout_ms / 1000:g} s; is it running?"
            ) from exc

    def web_url(self) -> str:
        url = self.request([b"url"]).decode("utf-8")
        self._connect()  # as MeshCat's client: reconnect after asking for the URL
        return url

    def send(self, command: ms.Command) -> None:
        reply = self.request([command["type"].encode(), command["path"].encode(), ms.pack(command)])
        if reply != b"ok":
            raise ViewerError(f"the MeshCat server refused {command['type']}: {reply!r}")

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
            self._socket = None


def _start_server(timeout: float) -> tuple[subprocess.Popen, str]:
    """Start ``python -m meshcat.servers.zmqserver``; return the process and its ZeroMQ URL."""
    process = subprocess.Popen(
        [sys.executable, "-u", "-m", "meshcat.servers.zmqserver"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,  # a notebook's interrupt does not kill the server
    )
    lines: queue.Queue[str | None] = queue.Queue()

    def drain() -> None:  # read every line, so the server never blocks on a full pipe
        for line in process.stdout or ():
            lines.put(line.strip())
        lines.put(None)

    threading.Thread(target=drain, daemon=True, name="meshcat-server-output").start()
    deadline = time.monotonic() + timeout
    while True:
        try:
            line = lines.get(timeout=max(deadline - time.monotonic(), 0.01))
        except queue.Empty:
            line = None
        if line is None:
            _stop_server(process)
            raise ViewerError(
                f"the MeshCat server did not start within {timeout:g} s "
                f"(exit code {process.poll()}); check that meshcat is installed"
            )
        if line.startswith("zmq_url="):
            return process, line.split("=", 1)[1]


def _stop_server(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class Viewer:
    """A live MeshCat viewer of a robot, for scripts and notebooks.

    Starts a local MeshCat server (or connects to one at ``zmq_url``); open :attr:`url` in a
    browser (or show the viewer as a notebook cell's last value). Close it with :meth:`close` or
    use it as a context manager; a server it started stops with it.

    Example:
        >>> with Viewer(robot) as viewer:  # doctest: +SKIP
        ...     viewer.play(trajectory)

    Attributes:
        robot: The robot shown.
        url: The viewer's web address.
        zmq_url: The server's ZeroMQ address.
    """

    def __init__(
        self,
        robot: Robot,
        open: bool = False,
        zmq_url: str | None = None,
        timeout: float = 10.0,
        max_triangles: int = TRIANGLE_BUDGET,
    ) -> None:
        """Start or connect to a server and show ``robot`` at its neutral configuration.

        Args:
            robot: The robot to show.
            open: Open the viewer in the default web browser.
            zmq_url: Address of a running MeshCat server (``tcp://127.0.0.1:6000``); default:
                start one (it stops with :meth:`close`).
            timeout: Seconds to wait for the server to start or answer [s].
            max_triangles: Triangles drawn for the whole robot (see
                :func:`kinplan.viewer.save_html`).

        Raises:
            ViewerError: the server did not start or does not answer.
        """
        self.robot = robot
        self._visuals = visuals_for(robot, max_triangles)
        self._process: subprocess.Popen | None = None
        self._finalizer: weakref.finalize | None = None
        self._radius = 1.0  # [m] scene size: sets the tube and marker sizes
        if zmq_url is None:
            self._process, zmq_url = _start_server(timeout)
            self._finalizer = weakref.finalize(self, _stop_server, self._process)
        self.zmq_url = zmq_url
        self._connection = _Connection(zmq_url, timeout)
        try:
            self.url = self._connection.web_url()
            self._send(self._initial_commands())
        except ViewerError:
            self.close()
            raise
        logger.info("MeshCat viewer at %s", self.url)
        if open:
            import webbrowser

            webbrowser.open(self.url, new=2)

    def _initial_commands(self) -> list[ms.Command]:
        rng = np.random.default_rng(0)
        qs = np.vstack(
            [
                self.robot.neutral(),
                rng.uniform(self.robot.lower, self.robot.upper, (24, self.robot.nq)),
            ]
        )
        parts, _ = self._visuals.placements_over(qs)
        view = frame_view(bounding_points(self._visuals, parts), orbit_origin=True)
        commands = environment_commands(view, page_background=False)
        commands += robot_commands(self._visuals, self.robot.neutral())
        commands += triad_commands(LAYERS["tool"], 0.08 * view.radius)
        self._radius = view.radius
        return commands

    def _send(self, commands: Iterable[ms.Command]) -> None:
        for command in commands:
            self._connection.send(command)

    def display(self, q: Sequence[float] | np.ndarray) -> None:
        """Show the robot at joint configuration ``q``, shape (nq,) [rad or m]."""
        self._send(pose_commands(self._visuals, self.robot.check_q(q)))

    def play(
        self,
        motion: MotionLike,
        speed: float = 1.0,
        markers: Markers = None,
        fps: float = DEFAULT_FPS,
        loop: bool = False,
        step: bool = False,
    ) -> None:
        """Play a joint ``Trajectory`` or a ``CartesianPlan`` with its paths and markers.

        By default the motion is loaded into MeshCat's animation (timeline in the viewer's
        controls) and this returns at once. With ``step=True`` this sends each key frame in
        real time instead and returns when the motion has been shown.

        Args:
            motion: The motion (see :func:`kinplan.viewer.save_html`).
            speed: Playback speed factor (2.0: twice as fast).
            markers: Points to mark [m] (see :func:`kinplan.viewer.save_html`).
            fps: Key frames per second [1/s].
            loop: Repeat the animation.
            step: Step through the key frames from Python, blocking, instead of animating.

        Raises:
            InputError: a motion of another robot, a non-positive speed, a bad marker.
        """
        speed = positive("speed", speed, 1000.0)
        sampled = playback(self.robot, motion, fps)
        overlay, _ = overlay_commands(self._visuals, sampled, marker_points(markers), self._radius)
        self._send([ms.delete(LAYERS["path"]), ms.delete(LAYERS["markers"]), *overlay])
        if not step:
            if len(sampled.t) > 1:
                self._send([animation_command(self._visuals, sampled, speed, loop, play=True)])
            self.display(sampled.q[0])
            return
        self._send([ms.set_animation([], play=False)])  # stop an earlier animation
        start = time.monotonic()
        for t, q in zip(sampled.t, sampled.q):
            delay = start + t / speed - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            self.display(q)

    def close(self) -> None:
        """Disconnect and stop the server this viewer started (safe to call twice)."""
        connection = getattr(self, "_connection", None)
        if connection is not None:
            connection.close()
        if self._finalizer is not None:
            self._finalizer()  # stops the server, once

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _repr_html_(self) -> str:
        return (
            f'<div style="height: 420px; width: 100%; resize: both; overflow: hidden">'
            f'<iframe src="{self.url}" style="width: 100%; height: 100%; border: none">'
            "</iframe></div>"
        )

    def __repr__(self) -> str:
        return f"Viewer({self.robot.name!r}, url={getattr(self, 'url', None)!r})"
