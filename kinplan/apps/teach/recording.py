"""Continuous-path commands: ``rec start [hz]`` begins a recording, ``rec stop [tol_deg]`` fits
its spline (timed as recorded, within the tolerance) and stores it as a :class:`RecordedPath
<kinplan.apps.teach.paths.RecordedPath>`, with its report."""

from __future__ import annotations

import math

import numpy as np

from kinplan.apps.teach.capture import Recording
from kinplan.apps.teach.parsing import number
from kinplan.apps.teach.paths import RecordedPath, fit_spline, program_spline
from kinplan.apps.teach.settings import DEFAULT_RATE_HZ, MAX_PATH_TOLERANCE_DEG, MAX_RATE_HZ
from kinplan.apps.teach.state import PendantState, Reply

_FIT_ATTEMPTS = 4
"""Fits ``rec stop`` tries, each aiming tighter by what the last missed: the program reads the
knots rounded to 1e-6° and the times to 1e-6 s, which moves the spline by ~1e-8 rad."""


class RecordingCommands(PendantState):
    """The pendant's continuous-path commands."""

    def _start_recording(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: rec start [hz]")
        if self._recording is not None:
            recording = self._recording
            return Reply(
                f"refused: already recording ({len(recording.times)} samples, "
                f"{recording.elapsed:.2f} s); rec stop first"
            )
        rate = DEFAULT_RATE_HZ
        if arguments:
            rate = number(
                arguments[0], "the sampling rate", "Hz", positive=True, maximum=MAX_RATE_HZ
            )
        self._recording = Recording(rate, [0.0], [self.q.copy()])
        return Reply(
            f"recording at {rate:g} Hz from here: jog the arm along the path (each jog as a "
            f"motion at {100 * self.jog_speed:g} % of the joint speed limits), then "
            "rec stop [tol_deg]"
        )

    def _stop_recording(self, arguments: list[str]) -> Reply:
        if len(arguments) > 1:
            raise ValueError("usage: rec stop [tol_deg]")
        recording = self._recording
        if recording is None:
            return Reply("refused: not recording; rec start [hz] starts a path")
        tolerance = self.path_tolerance
        if arguments:
            tolerance = math.radians(
                number(
                    arguments[0],
                    "the tolerance",
                    "degrees",
                    positive=True,
                    maximum=MAX_PATH_TOLERANCE_DEG,
                )
            )
        self._recording = None
        if recording.jogs == 0:
            return Reply("recording stopped: the arm did not move, so no path was stored")
        times, samples = np.array(recording.times), np.array(recording.q)
        if recording.elapsed - times[-1] > 0.01 / recording.rate_hz:
            times, samples = np.append(times, recording.elapsed), np.vstack([samples, self.q])
        else:  # the last sample is at the end (at rest there): the exact end time and position
            times[-1], samples[-1] = recording.elapsed, self.q
        robot = self.robot
        aim = tolerance
        for _ in range(_FIT_ATTEMPTS):
            knots, _, _ = fit_spline(samples, times, aim, robot.lower, robot.upper)
            spline, ratio, joint = program_spline(robot, times[knots], samples[knots])
            played = np.interp(times, times[knots], spline.waypoints.times)
            fitted = spline.sample(played)[0]
            deviation = np.abs(fitted - samples).max(axis=1)
            excess = float(deviation.max()) - tolerance
            if excess <= 0.0:
                break
            aim = max(aim - 2.0 * excess, 0.5 * aim)  # the rounding moved it past: aim tighter
        tool = max(
            float(np.linalg.norm(robot.fk(a).translation - robot.fk(b).translation))
            for a, b in zip(fitted, samples, strict=True)
        )
        name = self._next_path_name()
        path = RecordedPath(
            name,
            recording.rate_hz,
            times,
            samples,
            knots,
            spline,
            played,
            deviation,
            tool,
            tolerance,
            ratio,
        )
        self.paths[name] = path
        self._order.append(("path", name))
        slower = ""
        if path.slowed:
            slower = (
                f"; timed as recorded the spline would need {100 * ratio:.1f} % of the velocity "
                f"limit of joint {joint} ({robot.joint_names[joint]}), so the program plays it "
                f"in {spline.duration:.3f} s, not the recorded {path.duration:.3f} s"
            )
        return Reply(
            f"stored {name}: {len(times)} samples over {path.duration:.2f} s at "
            f"{recording.rate_hz:g} Hz -> spline through {len(knots)} knots at their recorded "
            f"times; max deviation {path.max_deviation:.2e} rad "
            f"({math.degrees(path.max_deviation):.4f}°) in joint space, {1000 * tool:.3f} mm at "
            f"the tool (tolerance {tolerance:.2e} rad){slower}"
        )

    def _next_path_name(self) -> str:
        k = len(self.paths) + 1
        while f"path{k}" in self.paths or any(
            name == f"path{k}" or name.startswith(f"path{k}_") for name in self.points
        ):
            k += 1
        return f"path{k}"
