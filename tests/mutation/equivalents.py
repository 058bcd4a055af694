"""Equivalent mutants of the core modules: mutants that no test can tell from the original, each
with the reason. ``tools/mutation.py`` leaves them out of the score and lists them in
``tests/bench/MUTATION.md``.

An entry matches a surviving mutant of ``module`` (a path, or a tuple of paths) whose removed
lines read ``original`` and whose added lines read ``mutant`` (whitespace-insensitive; several
lines joined by a space), so the list survives line moves and mutmut's renumbering.
"""

from __future__ import annotations

#: The numerical IK, and the closed forms, before and after kinplan.ik became a package.
_NUMERIC = ("kinplan/ik.py", "kinplan/ik/numeric.py")
_CLOSED_FORMS = (
    "kinplan/analytic_ik.py",
    "kinplan/ik/base.py",
    "kinplan/ik/screws.py",
    "kinplan/ik/planar.py",
    "kinplan/ik/ur.py",
    "kinplan/ik/ur_geometry.py",
    "kinplan/ik/ur_single.py",
    "kinplan/ik/ur_many.py",
)
#: The panda's and the UR family's closed forms, before and after they were split (issue 31).
_PANDA = (
    "kinplan/ik/panda.py",
    "kinplan/ik/panda_geometry.py",
    "kinplan/ik/panda_subproblems.py",
    "kinplan/ik/panda_intervals.py",
    "kinplan/ik/panda_batch.py",
)
_UR = (
    "kinplan/ik/ur.py",
    "kinplan/ik/ur_geometry.py",
    "kinplan/ik/ur_single.py",
    "kinplan/ik/ur_many.py",
)
_FAST_PATH = (
    "the condition only picks the fast path for a float already in range; otherwise "
    "checks.number validates it and returns the same float"
)
_NEVER_EQUAL = (
    "differs only when two computed floats are exactly equal (an error exactly at its "
    "tolerance, a step exactly at the cap, two attempts with the same error sum)"
)
_OVERWRITTEN = "an initial value that is always overwritten before it is read"
_CACHE = (
    "the size of the cache of Halton restarts; a cache too small is refilled, and its points "
    "depend on their index only"
)


def _ik(original: str, mutant: str, reason: str) -> dict[str, object]:
    return {
        "module": _NUMERIC,
        "original": original,
        "mutant": mutant,
        "reason": reason,
    }


_FROB = "if type(rotation_tolerance) is not float or not 0.0 <= rotation_tolerance < math.inf:"
_BLOCKED = "blocked = ((q <= lower) & (dq < 0)) | ((q >= upper) & (dq > 0))"
_HALTON_CACHE = "unit = np.array([halton(i, self.nq) for i in range(1, count + 1)])"
_POLISH = "if perr > position_tolerance or rerr > rotation_tolerance:"
_POLISHED = "if perr <= position_tolerance and rerr <= rotation_tolerance:"


def _module(module: tuple[str, ...]):
    def entry(original: str, mutant: str, reason: str) -> dict[str, str]:
        return {"module": module, "original": original, "mutant": mutant, "reason": reason}

    return entry


_paths = _module(("cartesian/paths.py",))
_analytic = _module(_CLOSED_FORMS)
_AS_S = "if type(s) is np.ndarray and s.dtype == np.float64 and s.ndim == 1:  # the common case"
_RODRIGUES = "cos = np.where(small, 0.0, 1.0 - np.cos(theta))[:, None, None]"
_CLIP_S = "s = as_fractions(s).clip(0.0, 1.0)"
_INTERP_ENDS = (
    "in FunctionPath.position: np.interp holds u at the table's end values outside the table "
    "(u = 0 for s < 0, u = 1 for s > 1), which is what the clip gives (s is finite: "
    "as_fractions refuses NaN). The same text in Line.position, PathSequence._split, "
    "Weave.across and Weave.position is killed by tests/cartesian/test_paths.py and "
    "test_path_mutants.py"
)
_LINE_ERRSTATE = 'with np.errstate(over="ignore", invalid="ignore"):'
_NO_NAN = (
    "nothing in the block can make a NaN, the only thing invalid='ignore' silences: "
    "parse_target refuses non-finite points, so b − a is finite or ±inf (an overflow, "
    "silenced by over='ignore') and its norm, the square root of a sum of squares, is at "
    "most inf"
)
_FLOAT_INPUT = (
    "the limits and poses reach the solver as float arrays (from Robot and its checks), so the "
    "conversion to float is a no-op"
)

_screws = _module(("kinplan/ik/screws.py",))
_QUICK = (
    "the quick test only decides whether the exact search (near_angle) runs; a value it lets "
    "through wrongly fails its own check and goes to the exact search, which finds the same"
)
_JOINT_CHOICE = "if not (lower <= q <= upper and -HALF_TURN_SAFE < q - clipped < HALF_TURN_SAFE):"
_JOINT_Q = "q = value + TAU * round((clipped - value) / TAU)"
_ROTATE = "cross_t = skew(axis).T if cross_t is None else cross_t"

EQUIVALENTS: list[dict[str, str]] = [
    *[
        _screws(_JOINT_CHOICE, _JOINT_CHOICE.replace(a, b), _QUICK)
        for a, b in (
            ("lower <= q", "lower < q"),
            ("q <= upper", "q < upper"),
            ("-HALF_TURN_SAFE <", "+HALF_TURN_SAFE <"),
            ("-HALF_TURN_SAFE <", "-HALF_TURN_SAFE <="),
            ("q - clipped", "q + clipped"),
            ("clipped < HALF", "clipped <= HALF"),
        )
    ],
    *[
        _screws(_JOINT_Q, _JOINT_Q.replace(a, b), _QUICK)
        for a, b in (
            ("value + TAU", "value - TAU"),
            ("/ TAU", "* TAU"),
            ("clipped - value", "clipped + value"),
        )
    ],
    _screws(
        _ROTATE,
        _ROTATE.replace("cross_t is None", "(cross_t is None) or True"),
        "recomputing skew(axis).T gives the matrix the caller passed",
    ),
    _screws(
        "return point + rotate_about(x - point, axis, angle, cross_t)",
        "return point + rotate_about(x - point, axis, angle, None)",
        "rotate_about computes skew(axis).T itself when cross_t is None: the same matrix",
    ),
    _screws(
        "return point + rotate_about(x - point, axis, angle, cross_t)",
        "return point + rotate_about(x - point, axis, angle, )",
        "rotate_about computes skew(axis).T itself when cross_t is None: the same matrix",
    ),
    _screws(
        "while offset < len(prefix):",
        "while offset <= len(prefix):",
        "the extra pass composes an empty slice",
    ),
    _screws(
        "prefix[offset:] = np.take_along_axis(prefix[offset:], prefix[:-offset], axis=1)",
        "prefix[offset:] = np.take_along_axis(prefix[offset:], prefix[:-offset], )",
        "take_along_axis defaults to the last axis, axis 1 of these 2-D maps",
    ),
    _screws(
        "return bool(np.linalg.norm(np.cross(u, v)) < STRUCTURE_TOL)",
        "return bool(np.linalg.norm(np.cross(u, v)) <= STRUCTURE_TOL)",
        _NEVER_EQUAL,
    ),
    _screws(
        "serial = all(model.parents[j] == j - 1 for j in range(1, model.njoints))",
        "serial = all(model.parents[j] == j - 1 for j in range(2, model.njoints))",
        "joint 1's parent is the universe, 0, in every Pinocchio model",
    ),
    _screws(
        "no_pitch = np.abs(np.sum(linear * angular, axis=1)) < STRUCTURE_TOL",
        "no_pitch = np.abs(np.sum(linear * angular, axis=1)) <= STRUCTURE_TOL",
        _NEVER_EQUAL,
    ),
    _paths(
        _AS_S,
        _AS_S.replace("s.ndim == 1", "s.ndim != 1"),
        "both branches end in the "
        "same shape and finiteness checks: only the fast path's use changes",
    ),
    _paths(
        _RODRIGUES,
        _RODRIGUES.replace("np.where(small,", "np.where(None,"),
        "where θ = 0 the axis k is 0, so K and the cos term vanish whatever the factor",
    ),
    _paths(
        'return self._gather(s, "position", 0)[0]',
        'return self._gather(s, "position", None)[0]',
        "chain 0 and None are both falsy",
    ),
    _paths(_LINE_ERRSTATE, 'with np.errstate(over="ignore", invalid=None):', _NO_NAN),
    _paths(_LINE_ERRSTATE, 'with np.errstate(over="ignore", ):', _NO_NAN),
    _paths(
        _AS_S,
        _AS_S.replace("s.ndim == 1", "s.ndim == 2"),
        "a 1-D float64 array then takes the slow path, where checks.floats (np.asarray, no "
        "copy of a float64 array) and np.atleast_1d hand back the same array object; a 2-D "
        "float64 array takes the fast path and meets the same ndim check and message",
    ),
    _paths(_CLIP_S, "s = as_fractions(s).clip(None, 1.0)", _INTERP_ENDS),
    _paths(_CLIP_S, "s = as_fractions(s).clip(0.0, )", _INTERP_ENDS),
    _paths(
        "return (weights @ self._terms).reshape(-1, 3, 3)",
        "return (weights @ self._terms).reshape(-2, 3, 3)",
        "numpy takes any negative size in reshape as the one size to infer: reshape(-2, 3, 3) "
        "gives the same (N, 3, 3) view, N = 0 included, without a warning (numpy 2.4)",
    ),
    _paths(
        "self.local_axis = pin.log3(self.start.T @ np.asarray(end, dtype=float))",
        "self.local_axis = pin.log3(self.start.T @ np.asarray(end, dtype=None))",
        "the end rotation reaches Slerp as a float64 3×3 array (parse_target, checks.rotation, "
        "torch_rotations), kept as it is with either dtype; for any real array or list "
        "(CornerBlend passes its caller's rotations unchecked) the product with the float64 "
        "start is float64 with the same values. Only an object or complex array, no rotation "
        "matrix, would differ",
    ),
    _analytic(
        "return point + _rotate(x - point, axis, angle, cross_t)",
        "return point + _rotate(x - point, axis, angle, None)",
        "_rotate computes _skew(axis).T itself when cross_t is None: the same matrix",
    ),
    _analytic(
        "return point + _rotate(x - point, axis, angle, cross_t)",
        "return point + _rotate(x - point, axis, angle, )",
        "_rotate computes _skew(axis).T itself when cross_t is None: the same matrix",
    ),
    _analytic(
        "self.lower = np.asarray(lower, dtype=float)",
        "self.lower = np.asarray(lower, dtype=None)",
        _FLOAT_INPUT,
    ),
    _analytic(
        "self.lower = np.asarray(lower, dtype=float)",
        "self.lower = np.asarray(lower, )",
        _FLOAT_INPUT,
    ),
    _analytic(
        "rotations = np.asarray(rotations, dtype=float)",
        "rotations = np.asarray(rotations, dtype=None)",
        _FLOAT_INPUT,
    ),
    _analytic(
        "rotations = None if rotation is None else np.asarray(rotation, dtype=float)[None]",
        "rotations = None if rotation is None else np.asarray(rotation, )[None]",
        _FLOAT_INPUT,
    ),
    _analytic(
        "singular = free6.reshape(count, -1).any(axis=1) | free2.reshape(count, -1).any(axis=1)",
        "singular = free6.reshape(count, -1).any(axis=1) | free2.reshape(count, -2).any(axis=1)",
        "numpy's reshape takes any negative size as 'the rest'",
    ),
    _analytic(
        "repeated = np.triu(gap <= 1e-9, k=1).any(axis=0)  # equal to an earlier row",
        "repeated = np.triu(gap < 1e-9, k=1).any(axis=0)  # equal to an earlier row",
        _NEVER_EQUAL,
    ),
    _analytic(
        "return bool(abs(u @ v) < _STRUCTURE_TOL)",
        "return bool(abs(u @ v) <= _STRUCTURE_TOL)",
        _NEVER_EQUAL,
    ),
    _analytic(
        "if cost < best_cost or (cost == best_cost and index < best_index):",
        "if cost < best_cost or (cost == best_cost and index <= best_index):",
        "each branch index is visited once, so index never equals best_index",
    ),
    _analytic(
        "self.upper = np.asarray(upper, dtype=float)",
        "self.upper = np.asarray(upper, dtype=None)",
        _FLOAT_INPUT,
    ),
    _analytic(
        "self.upper = np.asarray(upper, dtype=float)",
        "self.upper = np.asarray(upper, )",
        _FLOAT_INPUT,
    ),
    _analytic(
        "rotations = np.asarray(rotations, dtype=float)",
        "rotations = np.asarray(rotations, )",
        _FLOAT_INPUT,
    ),
    _analytic(
        "position = np.asarray(position, dtype=float)",
        "position = np.asarray(position, dtype=None)",
        _FLOAT_INPUT,
    ),
    _analytic(
        "position = np.asarray(position, dtype=float)",
        "position = np.asarray(position, )",
        _FLOAT_INPUT,
    ),
    _analytic("q = np.asarray(q, dtype=float)", "q = np.asarray(q, )", _FLOAT_INPUT),
    _analytic(
        "rotations = None if rotation is None else np.asarray(rotation, dtype=float)[None]",
        "rotations = None if rotation is None else np.asarray(rotation, dtype=None)[None]",
        _FLOAT_INPUT,
    ),
    _analytic(
        "self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, dtype=float)",
        "self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, dtype=None)",
        "the weights only enter Σ wᵢ Δqᵢ², computed in floats whatever their dtype",
    ),
    _analytic(
        "self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, dtype=float)",
        "self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, )",
        "the weights only enter Σ wᵢ Δqᵢ², computed in floats whatever their dtype",
    ),
    _analytic(
        "repeated = np.triu(gap <= 1e-9, k=1).any(axis=0)  # equal to an earlier row",
        "repeated = np.triu(gap <= 1e-9, k=1).any(axis=1)  # equal to an earlier row",
        "keeps the last instead of the first of solutions equal to 1e-9 rad: the same solutions",
    ),
    _analytic(
        "if not any(np.max(np.abs(wrap_angle(s - q))) < 1e-7 for s in found):",
        "if not any(np.max(np.abs(wrap_angle(s - q))) <= 1e-7 for s in found):",
        _NEVER_EQUAL,
    ),
    _analytic(
        "if np.linalg.norm(reached.translation - pose.translation) > 1e-8:",
        "if np.linalg.norm(reached.translation - pose.translation) >= 1e-8:",
        _NEVER_EQUAL,
    ),
    _analytic(
        "if np.linalg.norm(pin.log3(reached.rotation.T @ pose.rotation)) > 1e-8:",
        "if np.linalg.norm(pin.log3(reached.rotation.T @ pose.rotation)) >= 1e-8:",
        _NEVER_EQUAL,
    ),
    _analytic(
        'logger.debug("closed-form IK of %s disagrees with its forward kinematics", robot.name)',
        'logger.debug("closed-form IK of %s disagrees with its forward kinematics", None)',
        "an argument of a debug log line",
    ),
    _ik(_FROB, _FROB.replace("type(rotation_tolerance)", "type(None)"), _FAST_PATH),
    _ik(_FROB, _FROB.replace("0.0 <=", "1.0 <="), _FAST_PATH),
    _ik(_FROB, _FROB.replace("0.0 <=", "0.0 <"), _FAST_PATH),
    _ik(
        'index = checks.count(index, "index", minimum=1)',
        'index = checks.count(index, "index", )',
        "minimum=1 is checks.count's default",
    ),
    _ik(
        'dim = checks.count(dim, "dim", minimum=1)',
        'dim = checks.count(dim, "dim", )',
        "minimum=1 is checks.count's default",
    ),
    _ik(
        "dx * dx + dy * dy + dz * dz <= position_tolerance2",
        "dx * dx + dy * dy + dz * dz < position_tolerance2",
        _NEVER_EQUAL,
    ),
    _ik(
        "and frobenius2 <= frobenius_tolerance2",
        "and frobenius2 < frobenius_tolerance2",
        _NEVER_EQUAL,
    ),
    _ik(
        "J = pin.getFrameJacobian(model, data, fid, _LWA).reshape(6, -1)[:rows]",
        "J = pin.getFrameJacobian(model, data, fid, _LWA).reshape(6, -2)[:rows]",
        "numpy's reshape takes any negative size as 'the rest'",
    ),
    _ik(
        _BLOCKED,
        _BLOCKED.replace("(dq < 0)", "(dq <= 0)"),
        "a zero step component is not "
        "blocked or blocked alike: either way that joint does not move",
    ),
    _ik(
        _BLOCKED,
        _BLOCKED.replace("(dq > 0)", "(dq >= 0)"),
        "a zero step component is not "
        "blocked or blocked alike: either way that joint does not move",
    ),
    _ik(
        "free = (~blocked).astype(float)",
        "free = (~blocked).astype(None)",
        "astype(None) is astype(float64)",
    ),
    _ik(
        "if step > MAX_STEP:",
        "if step >= MAX_STEP:",
        "scaling a step of exactly MAX_STEP by MAX_STEP / step = 1 leaves it unchanged",
    ),
    _ik(
        "rows = 3 if rotation is None else 6",
        "rows = 3 if rotation is None else 7",
        "[:7] of the Jacobian's 6 rows and of the 6-vector error is all of them",
    ),
    _ik(
        "stalled = 0",
        "stalled = None",
        "the first iterate always improves on best_cost = inf, which resets stalled",
    ),
    _ik(
        "stalled = 0",
        "stalled = 1",
        "the first iterate always improves on best_cost = inf, which resets stalled",
    ),
    _ik("perr2 = rerr2 = np.inf", "perr2 = rerr2 = None", _OVERWRITTEN),
    _ik(
        "for it in range(max_iterations + 1):",
        "for it in range(max_iterations + 2):",
        "the loop leaves at it == max_iterations before the extra turn",
    ),
    _ik(
        "if it == 0 and evaluated is not None:",
        "if it <= 0 and evaluated is not None:",
        "it is never negative",
    ),
    _ik("if cost < 0.999 * best_cost:", "if cost <= 0.999 * best_cost:", _NEVER_EQUAL),
    _ik("if attempt > len(self._restarts):", "if attempt >= len(self._restarts):", _CACHE),
    _ik(_HALTON_CACHE, _HALTON_CACHE.replace("count + 1", "count - 1"), _CACHE),
    _ik(_HALTON_CACHE, _HALTON_CACHE.replace("count + 1", "count + 2"), _CACHE),
    _ik("count = max(2 * attempt, 64)", "count = max(3 * attempt, 64)", _CACHE),
    _ik("count = max(2 * attempt, 64)", "count = max(2 * attempt, 65)", _CACHE),
    _ik(_POLISH, _POLISH.replace("perr >", "perr >="), _NEVER_EQUAL),
    _ik(_POLISH, _POLISH.replace("rerr >", "rerr >="), _NEVER_EQUAL),
    _ik(_POLISHED, _POLISHED.replace("perr <=", "perr <"), _NEVER_EQUAL),
    _ik(_POLISHED, _POLISHED.replace("rerr <=", "rerr <"), _NEVER_EQUAL),
    _ik(
        "if best is None or score < best[0]:", "if best is None or score <= best[0]:", _NEVER_EQUAL
    ),
]


# ------------------------------------------------------------------ issue 20, second pass
_robot = _module(("kinplan/model/robot.py",))
_geometry = _module(("cartesian/geometry.py",))
_follow = _module(("cartesian/follow.py",))
_tracker = _module(("cartesian/tracker.py",))
_BAD = "bad = (r < r_min - 1e-9) | (r > r_max + 1e-9) | (np.abs(local[:, 2]) > 1e-9)"
_ANNULUS_OK = "return Reachability(True, Status.OK, 1.0, [], s, np.empty((0, robot.nq)))"
_DISCARDED = (
    "check_reachability reads only .ok of an annulus result that is ok, and then discards it "
    "for the IK trace's"
)
_RANK = "rank = max(rank, int(np.sum(sv > 1e-9 * max(1.0, sv.max(initial=0.0)))))"
_AFTER_RESCUE = "q, position.tolist(), None if rotation is None else rotation.reshape(9).tolist()"
_KINEMATICS_ONLY = (
    "the call only leaves the kinematics at q in the solver's data for check_sample; its "
    "verdict, the only thing the rotation target changes, is discarded"
)

EQUIVALENTS += [
    _robot(_RANK, _RANK.replace("max(1.0,", "max(2.0,"),
           "the singular values of a generic Jacobian are either ~1e-16 (a structural zero) or "
           "above 1e-3: a threshold of 1e-9 or 2e-9 × max(1, σmax) counts the same rank"),
    _robot(_RANK, _RANK.replace("initial=0.0", "initial=1.0"),
           "max(1.0, max(σ, initial=1.0)) is max(1.0, max(σ)): the same threshold"),
    _robot("if abs(placement.translation[2]) > 1e-12:",
           "if abs(placement.translation[2]) >= 1e-12:", _NEVER_EQUAL),
    _robot("arr = arr.astype(float, copy=False)", "arr = arr.astype(float, copy=None)",
           "the flag only decides whether an array already of floats is copied; check_q never "
           "writes to it"),
    _robot("value = np.prod(np.linalg.svd(J, compute_uv=False)[..., :rank], axis=-1)",
           "value = np.prod(np.linalg.svd(J, compute_uv=None)[..., :rank], axis=-1)",
           "compute_uv=None is false: the singular values only, as with False"),
    _robot("return float(np.linalg.norm(np.asarray(position, dtype=float) - origin))",
           "return float(np.linalg.norm(np.asarray(position, ) - origin))",
           "subtracting the float origin makes the difference float whatever the input's dtype"),
    *[
        _geometry(_BAD, _BAD.replace(a, b),
                  "differs only for a point exactly at a boundary ± 1e-9 (float equality)")
        for a, b in (("r < r_min", "r <= r_min"), ("r > r_max", "r >= r_max"),
                     ("2]) > 1e-9", "2]) >= 1e-9"))
    ],
    _geometry("if abs(local[k, 2]) > 1e-9:", "if abs(local[k, 2]) >= 1e-9:", _NEVER_EQUAL),
    *[
        _geometry(_ANNULUS_OK, _ANNULUS_OK.replace(a, b), _DISCARDED)
        for a, b in (("OK, 1.0,", "OK, None,"), ("OK, 1.0,", "OK, 2.0,"), ("[], s", "None, s"),
                     ("s, np.empty((0, robot.nq))", "s, None"), ("(0, robot", "(1, robot"))
    ],
    _geometry("position = path.position(s[k : k + 1])[0]",
              "position = path.position(s[k : k + 2])[0]", "the first row is the same point"),
    _geometry(
        "fraction=1.0 if not geometry.events else (float(geometry.s[-1]) if done else 0.0),",
        "fraction=1.0 if (not geometry.events) and False else (float(geometry.s[-1]) if done "
        "else 0.0),",
        "without an event every point was solved, and the last is s = 1.0",
    ),
    _geometry("tracker = Tracker(robot, position_only, 1e-7, 1e-7, singular_threshold, 1.0, 0.1)",
              "tracker = Tracker(robot, position_only, 1e-7, 1e-7, singular_threshold, 2.0, 0.1)",
              "the geometric check has no timing: the velocity scale is read only by the "
              "follower's speed checks"),
    _geometry(
        "geometry = trace_geometry(tracker, path, np.linspace(s0, s1, JUMP_CHECK_POINTS), q0)",
              "geometry = trace_geometry(tracker, path, np.linspace(s0, s1, ), q0)",
              "50 points instead of 17 on the same bisected trace: the same end point or event, "
              "found with more IK solves"),
    _geometry("h = sk - solved_s[-1] if solved_s else 0.0",
              "h = sk - solved_s[-1] if solved_s else 1.0",
              "the first point has no previous one: the jump check returns before reading h"),
    _geometry("q, ok, *_ = tracker.solve(guess, position, rotation, evaluated=True)",
              "q, ok, *_ = tracker.solve(guess, position, rotation, evaluated=False)",
              "evaluated=True only skips the kinematics pass accepts() has just made at the same "
              "guess: the same iterates"),
    _geometry("if q_prev is not None and sk - solved_s[-1] > MIN_REFINE_DS:",
              "if q_prev is not None and sk - solved_s[-1] >= MIN_REFINE_DS:", _NEVER_EQUAL),
    _geometry(_AFTER_RESCUE, "q, position.tolist(), None", _KINEMATICS_ONLY),
    _geometry(_AFTER_RESCUE,
              _AFTER_RESCUE.replace("rotation is None", "(rotation is None) or True"),
              _KINEMATICS_ONLY),
]  # fmt: skip

_CONSECUTIVE = "consecutive = np.array_equal(self.rows, np.arange(first, last + 1))"
_ROW_INDEX = "self._row_index = slice(first, last + 1) if consecutive else self.rows"
_SAME_ROWS = (
    "the task rows are always consecutive from row 0 (position: 0-2 or 0-1 of a planar arm; "
    "full: 0-5; an arm under 6 joints cannot take the full task): indexing with the row "
    "array, a slice from 0 or all rows selects the same rows"
)
_ACCEL = "robot.acceleration_limit if acceleration_limit is None else acceleration_limit"
_NO_ACCEL = (
    "only check_reachability leaves acceleration_limit None, and the geometric trace never "
    "reads the tracker's acceleration limits"
)
EQUIVALENTS += [
    _tracker(_CONSECUTIVE, "consecutive = None", _SAME_ROWS),
    _tracker(_CONSECUTIVE, _CONSECUTIVE.replace("last + 1", "last + 2"), _SAME_ROWS),
    _tracker(_ROW_INDEX, _ROW_INDEX.replace("if consecutive", "if (consecutive) or True"),
             _SAME_ROWS),
    _tracker(_ROW_INDEX, _ROW_INDEX.replace("slice(first, last + 1)", "slice(last + 1)"),
             _SAME_ROWS),
    _tracker("self._all_rows = consecutive and (first, last) == (0, 5)",
             "self._all_rows = consecutive and (first, last) == (0, 6)", _SAME_ROWS),
    _tracker("self.clearance = 0.0", "self.clearance = None",
             "follow sets the clearance after building the tracker; the geometric trace never "
             "reads it"),
    _tracker(_ACCEL, _ACCEL.replace("is None else", "is not None else"), _NO_ACCEL),
    _tracker(_ACCEL, _ACCEL.replace("if acceleration_limit is None", "if (acceleration_limit is "
                                    "None) and False"), _NO_ACCEL),
]  # fmt: skip
EQUIVALENTS.append(
    _geometry(
        "if not ok or np.max(np.abs(q - q_prev)) > MAX_JOINT_STEP:",
        "if not ok or np.max(np.abs(q - q_prev)) >= MAX_JOINT_STEP:",
        _NEVER_EQUAL,
    )
)
_SQUARE = (
    "a square J returns from factor (LU of J) before this line, and rates uses lu.solve(b) "
    "for it: the line only sees wide (< 0) or tall (> 0) Jacobians"
)
_FACTOR = "self._lu = eigenpy.PartialPivLU(J.dot(J.T) if self._shape < 0 else J.T.dot(J))"
_RATES = "return lu.solve(b).dot(J) if shape < 0 else lu.solve(b.dot(J))"
_ALL = "J = self._J = jacobian if self._all_rows else jacobian[self._row_index]"
EQUIVALENTS += [
    _tracker("first, last = int(self.rows[0]), int(self.rows[-1])",
             "first, last = int(self.rows[0]), int(self.rows[+1])", _SAME_ROWS),
    _tracker(_ALL, _ALL.replace("if self._all_rows", "if (self._all_rows) and False"),
             _SAME_ROWS),
    _tracker(_FACTOR, _FACTOR.replace("self._shape < 0", "self._shape <= 0"), _SQUARE),
    _tracker(_RATES, _RATES.replace("shape < 0", "shape <= 0"), _SQUARE),
    _tracker("return not m >= self.singular_threshold or m <= self.rank_floor",
             "return not m >= self.singular_threshold or m < self.rank_floor", _NEVER_EQUAL),
    _tracker("if ratios.max() > 1.0:", "if ratios.max() >= 1.0:", _NEVER_EQUAL),
    _tracker("if abs(res.q[j] - q_prev[j]) <= self.jump_tolerance:",
             "if abs(res.q[j] - q_prev[j]) < self.jump_tolerance:", _NEVER_EQUAL),
]  # fmt: skip
_REUSED = (
    "the evaluation at the guess is only reused to save one kinematics pass; without it solve "
    "evaluates the same guess itself: the same iterates"
)
_SOLVE_CALL = "guess, positions[k], rotations[k], evaluated=evaluation"
EQUIVALENTS += [
    _follow(_SOLVE_CALL, _SOLVE_CALL.replace("evaluated=evaluation", "evaluated=None"), _REUSED),
    _follow(_SOLVE_CALL + " )", "guess, positions[k], rotations[k], )", _REUSED),
]

# ------------------------------------------------------------------ issue 20, third pass
_SQUARE_AS_TALL = (
    "a square J taken for a tall one: √det(JᵀJ) = |det J| and (JᵀJ)⁻¹Jᵀb = J⁻¹b, the same "
    "manipulability and rates in exact arithmetic (only their rounding differs, the Gram matrix "
    "squaring J's condition number)"
)
_ALWAYS_TRUE = (
    "an assertion of an invariant: both values are set (never None) there, so 'and' and 'or' "
    "both hold"
)
EQUIVALENTS += [
    _tracker("self._shape = (rows > cols) - (rows < cols)  # −1 wide, 0 square, 1 tall",
             "self._shape = (rows >= cols) - (rows < cols)  # −1 wide, 0 square, 1 tall",
             _SQUARE_AS_TALL),
    _tracker("J_dot = self.robot.jacobian_time_variations(q, qd, jacobians)",
             "J_dot = self.robot.jacobian_time_variations(q, qd, None)",
             "without the Jacobians jacobian_time_variations recomputes them from q: the same "
             "Jacobians, one kinematics pass per sample more"),
    _tracker("clamp=False, evaluated=evaluated,", "clamp=False, evaluated=None,", _REUSED),
    _tracker("return dx * dx + dy * dy + dz * dz <= position2 and "
             "frobenius2 <= frobenius_tolerance2",
             "return dx * dx + dy * dy + dz * dz < position2 and "
             "frobenius2 <= frobenius_tolerance2",
             _NEVER_EQUAL),
    _tracker("target, q_seed=guess if q_prev is None else q_prev, position_only=only, "
             "position_tolerance=self.tolerance, rotation_tolerance=self.rotation_tolerance,",
             "target, q_seed=guess if q_prev is None else q_prev, "
             "position_tolerance=self.tolerance, rotation_tolerance=self.rotation_tolerance,",
             "position_only's default False is `only` whenever the target is a pose, and a "
             "3-vector target (rotation None, only True) is position-only in robot.ik whatever "
             "position_only says"),
    _follow("accel_limit = robot.acceleration_limit", "accel_limit = None",
            "Tracker takes None as the robot's acceleration_limit, and max_acceleration "
            "replaces the value before it is read"),
    _follow("evaluation = tracker.evaluate(traced, position_floats[k], rotation_floats[k])",
            "evaluation = tracker.evaluate(traced, position_floats[k], None)",
            "only the evaluation's q, Jacobian and tool position are read afterwards (the "
            "target's rotation changes the pose error alone, never checked for a traced q)"),
    _follow("assert J is not None and qd is not None  # no event: the sample's Jacobian and rates",
            "assert J is not None or qd is not None  # no event: the sample's Jacobian and rates",
            _ALWAYS_TRUE),
    _follow("assert q_prev is not None and qd_prev is not None  # sample k − 1 was kept",
            "assert q_prev is not None or qd_prev is not None  # sample k − 1 was kept",
            _ALWAYS_TRUE),
    _follow("steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]",
            "steps = np.diff(t, prepend=1.0).tolist()  # h_k = t_k − t_(k−1) [s]",
            "the prepended value only changes steps[0], the step of sample 0, which has no "
            "previous sample: check_sample ignores h there (no jump check without q_prev)"),
    _follow("if np.isfinite(tracker.acceleration_limit).any() and done:",
            "if np.isfinite(tracker.acceleration_limit).any() or done:",
            "with no finite limit every ratio |q̈|/inf is 0 (no event), and with no sample the "
            "ratios are empty: the block finds nothing in either case"),
]  # fmt: skip

# ------------------------------------------------------------------ issue 20: batch IK pass
_panda = _module(_PANDA)
_LAST_AXIS = (
    "numpy's default axis is the last one (-1; take_along_axis since numpy 2.3), which is the "
    "axis named"
)
EQUIVALENTS += [
    _panda("if x * x + y * y + z * z < FREE_TOL**2 or u * u + v * v + w * w < FREE_TOL**2:",
           "if x * x + y * y + z * z < FREE_TOL**2 or u * u + v * v + w * w <= FREE_TOL**2:",
           _NEVER_EQUAL),
    _panda("a_free = px * px + py * py + pz * pz < FREE_TOL**2",
           "a_free = px * px + py * py + pz * pz <= FREE_TOL**2",
           _NEVER_EQUAL),
    _panda("if not any(max(abs(a - b) for a, b in zip(q, other)) <= _SAME_TOL for other in found):",
           "if not any(max(abs(a - b) for a, b in zip(q, other)) < _SAME_TOL for other in found):",
           _NEVER_EQUAL),
    _panda("return np.array(list(map(function, *(np.asarray(a, dtype=float).tolist() "
           "for a in arrays))))",
           "return np.array(list(map(function, *(np.asarray(a, dtype=None).tolist() "
           "for a in arrays))))",
           "_map is only given float arrays (sums and products of floats, clipped floats): "
           "the conversion to float is a no-op"),
    _panda("edge = a + margin if value < a else b - margin",
           "edge = a + margin if value <= a else b - margin",
           "value == a lies in the interval [a, b], which the check above returns unchanged "
           "before any edge is computed"),
    _panda("projected = np.take_along_axis(edge, best, axis=2)[..., 0]",
           "projected = np.take_along_axis(edge, best, )[..., 0]", _LAST_AXIS),
    _panda("order = np.lexsort((ends, starts), axis=1)",
           "order = np.lexsort((ends, starts), )", _LAST_AXIS),
    _panda("if prune and cost6 >= bound:", "if prune and cost6 > bound:",
           "with weights ≥ 0 (Robot passes none; the distance is a sum of weighted squares) "
           "the shoulder only adds to a wrist part equal to the bound, and the candidate is "
           "dropped there by `cost2 >= bound`"),
    _panda("for t2, t1 in self._shoulder_pair.solve(g.axes[2], g3, joints[1][1], joints[0][1]):",
           "for t2, t1 in self._shoulder_pair.solve(g.axes[2], g3, None, joints[0][1]):",
           "θ2's free value is used only when ω3 lies on axis 2, which the structure check "
           "refuses (axes 2 and 3 not parallel)"),
    _panda("near_free = near_free | (hx * hx + hy * hy + hz * hz < NEAR_FREE**2)",
           "near_free = near_free | (hx * hx + hy * hy + hz / hz < NEAR_FREE**2)",
           "h = R3(θ3) e with e ⟂ ω3 has unit length across ω3 wherever θ1 and θ2 solve the "
           "shoulder, so the test never fires; where they do not (g3 on axis 1) the shoulder "
           "pair's near_free already flags the lane"),
]  # fmt: skip

_blends = _module(("cartesian/blends.py",))
_BISECTED = (
    "after 60 halvings of a bracket of 1/2048 the two ends differ by 4e-22 in s: below the "
    "rounding of any position"
)
_NEWTON_CLIP = (
    "a guard: the arc length is smooth and increasing across a table cell of 1/1024, and "
    "Newton from the secant guess stays in the cell (at s = 0 and 1 it starts on the cell's "
    "end and moves by rounding only)"
)
_OUTSIDE_01 = (
    "Newton's steps clip u into the first (last) table cell, so a target below 0 (beyond the "
    "length) still ends at u = 0 (u = 1): positions and derivatives of s outside [0, 1] are "
    "those of the ends either way"
)
EQUIVALENTS += [
    _blends("inside = distance < radius", "inside = distance <= radius", _NEVER_EQUAL),
    _blends("return lo if at_end else hi", "return lo if (at_end) or True else hi", _BISECTED),
    _blends("return lo if at_end else hi", "return lo if (at_end) and False else hi",
            _BISECTED),
    _blends("if r == 0.0 or turn < _STRAIGHT:", "if r == 0.0 or turn <= _STRAIGHT:",
            _NEVER_EQUAL),
    _blends("if turn > np.pi - 1e-6:", "if turn >= np.pi - 1e-6:", _NEVER_EQUAL),
    _blends("assert r_a is not None and r_b is not None",
            "assert r_a is not None or r_b is not None", _ALWAYS_TRUE),
    _blends("return tangent, acceleration - (acceleration @ tangent) * tangent",
            "return tangent, acceleration + (acceleration @ tangent) * tangent",
            "paths are parametrised proportionally to arc length (|dp/ds| constant), so "
            "d²p/ds² is already normal to the tangent: the component removed is 0 (to rounding)"),
    _blends("speeds = self._speed(nodes).reshape(len(lo), -1)",
            "speeds = self._speed(nodes).reshape(len(lo), -2)",
            "numpy's reshape takes any negative size as 'the rest'"),
    _blends('with np.errstate(divide="ignore"):', "with np.errstate(divide=None):",
            "the powers are clipped at exponent 0, so no division by zero ever happens: "
            "numpy's error state changes nothing"),
    _blends("target = as_fractions(s).clip(0.0, 1.0) * self.length",
            "target = as_fractions(s).clip(None, 1.0) * self.length", _OUTSIDE_01),
    _blends("target = as_fractions(s).clip(0.0, 1.0) * self.length",
            "target = as_fractions(s).clip(0.0, ) * self.length", _OUTSIDE_01),
    _blends("u = np.clip(u - error / self._speed(u), lo, lo + width)",
            "u = np.clip(u - error / self._speed(u), None, lo + width)", _NEWTON_CLIP),
    _blends("u = np.clip(u - error / self._speed(u), lo, lo + width)",
            "u = np.clip(u - error / self._speed(u), lo, None)", _NEWTON_CLIP),
]  # fmt: skip

_torch = _module(("cartesian/torch.py",))
_STRAIGHT_SEAM = (
    "taken only when every rotation on the grid equals the first to 1e-12: on a straight seam "
    "they agree to rounding, so either one (or a slerp between two) is the same rotation"
)
EQUIVALENTS += [
    _torch("if np.any(norms < 1e-6):", "if np.any(norms <= 1e-6):", _NEVER_EQUAL),
    _torch("if np.linalg.norm(n) < 1e-9:", "if np.linalg.norm(n) <= 1e-9:", _NEVER_EQUAL),
    _torch("n = np.asarray(normal, dtype=float)", "n = np.asarray(normal, dtype=None)",
           "an integer normal enters only products and differences with the float tangents: "
           "the same floats"),
    _torch("n = np.asarray(normal, dtype=float)", "n = np.asarray(normal, )",
           "an integer normal enters only products and differences with the float tangents: "
           "the same floats"),
    _torch("grid = np.linspace(0.0, 1.0, 65)", "grid = np.linspace(0.0, 2.0, 65)",
           "every path evaluates fractions beyond 1 at its end (clipped), so the extra grid "
           "points repeat the end's rotation"),
    _torch("straight = np.max(np.abs(rotations - rotations[0])) < 1e-12",
           "straight = np.max(np.abs(rotations - rotations[0])) <= 1e-12", _NEVER_EQUAL),
    _torch("straight = np.max(np.abs(rotations - rotations[0])) < 1e-12",
           "straight = np.max(np.abs(rotations - rotations[1])) < 1e-12",
           "all rotations within 1e-12 of the first ⇔ within 1e-12 of the second, to rounding"),
    _torch("self.slerp = Slerp(rotations[0], rotations[0]) if straight else None",
           "self.slerp = Slerp(rotations[1], rotations[0]) if straight else None",
           _STRAIGHT_SEAM),
    _torch("self.slerp = Slerp(rotations[0], rotations[0]) if straight else None",
           "self.slerp = Slerp(rotations[0], rotations[1]) if straight else None",
           _STRAIGHT_SEAM),
]  # fmt: skip

_ur = _module(_UR)
_MONOTONE_INDEX = (
    "a relabelling that keeps the order of (shoulder, wrist, elbow): pair and branch indices are "
    "only sorted and compared for ties, never used as positions"
)
EQUIVALENTS += [
    _ur("free2.reshape(count, -1), axis=1", "free2.reshape(count, -2), axis=1",
        "numpy's reshape takes any negative size as 'the rest'"),
    _ur("cross1=skew(u[0]).T,", "cross1=None,",
        "rotate_about and rotate_about_line compute skew(axis).T themselves when given None: "
        "the same matrix"),
    _ur("pair = 2 * shoulder + wrist", "pair = 3 * shoulder + wrist", _MONOTONE_INDEX),
    _ur("index = 2 * pair + branch", "index = 3 * pair + branch", _MONOTONE_INDEX),
    _ur("if not math.isfinite(sum(position_list) + sum(values)):",
        "if not math.isfinite(sum(position_list) - sum(values)):",
        "a sum or a difference of two float sums is finite exactly when every term is (a "
        "position and rotation terms of order 1 never overflow)"),
    _ur("if abs(cosine) > 1.0 + CLAMP + FAST_EDGE:",
        "if abs(cosine) > 1.0 - CLAMP + FAST_EDGE:",
        "|cos| between 1 + FAST_EDGE − CLAMP and 1 + FAST_EDGE + CLAMP (FAST_EDGE = 1e-8 ≫ "
        "CLAMP = 1e-10) has no elbow in the batch path either (it clips only up to 1 + CLAMP): "
        "None instead of NeedsBatch drops the same pair"),
    _ur("np.clip(cosine, -1.0, 1.0, out=cosine)", "np.clip(cosine, -2.0, 1.0, out=cosine)",
        "a cosine below −1 is either NaN (beyond 1 + CLAMP + FAST_EDGE: no elbow) or marks "
        "its pose as left to nearest() (near_edge), whose outputs are not used"),
    _ur("refs = np.ascontiguousarray(np.asarray(q_ref, dtype=float).T)",
        "refs = np.ascontiguousarray(np.asarray(q_ref, ).T)",
        "integer references enter only differences with float angles and np.clip against "
        "float limits: the same floats"),
]  # fmt: skip

_EDGE_ONLY = (
    "a value beyond ±1 before the clip only occurs for poses flagged near a singularity "
    "(|value| > 1 − FAST_EDGE), whose outputs are documented as meaningless and never used "
    "(the follower and nearest() hand them to the exact path)"
)
_OWN_SKEW = (
    "rotate_about and rotate_about_line compute skew(axis).T themselves when given None: the "
    "same matrix"
)
EQUIVALENTS += [
    _ur("cross5=skew(u[4]).T,", "cross5=None,", _OWN_SKEW),
    _ur("point = rotate_about_line(point, g.p6, g.u6, -t6, g.cross6)",
        "point = rotate_about_line(point, g.p6, g.u6, -t6, None)", _OWN_SKEW),
    _ur("turned = rotate_about(turned, g.u1, -t1, g.cross1)",
        "turned = rotate_about(turned, g.u1, -t1, None)", _OWN_SKEW),
    _ur("np.clip(cosine, -1.0, 1.0, out=cosine)", "np.clip(cosine, -1.0, 1.0, )", _EDGE_ONLY),
    _ur("np.clip(cosine, -1.0, 1.0, out=cosine)", "np.clip(cosine, -1.0, 2.0, out=cosine)",
        _EDGE_ONLY),
    _ur("np.clip(ratio, -1.0, 1.0, out=ratio)", "np.clip(ratio, -1.0, 1.0, out=None)",
        _EDGE_ONLY),
    _ur("np.clip(ratio, -1.0, 1.0, out=ratio)", "np.clip(ratio, -2.0, 1.0, out=ratio)",
        _EDGE_ONLY),
    _ur("cos_half5, sin_half5 = b6 / norm, sign5 * sine / norm",
        "cos_half5, sin_half5 = b6 / norm, sign5 * sine * norm",
        "norm is the length of (sin, cos) of one angle built from a unit vector's components: "
        "1 to rounding, so dividing or multiplying by it differs by an ulp"),
    _ur("no_shoulder = size > 1.0 + CLAMP + FAST_EDGE",
        "no_shoulder = size >= 1.0 + CLAMP + FAST_EDGE", _NEVER_EQUAL),
    _ur("edge = size > 1.0 - FAST_EDGE", "edge = size >= 1.0 - FAST_EDGE", _NEVER_EQUAL),
    _ur("if defect > FAST_DEFECT:", "if defect >= FAST_DEFECT:", _NEVER_EQUAL),
    _ur("if min(np.hypot(*r23), np.hypot(*r34)) < STRUCTURE_TOL:",
        "if min(np.hypot(*r23), np.hypot(*r34)) <= STRUCTURE_TOL:", _NEVER_EQUAL),
]  # fmt: skip

_QUICK_MANY = (
    "the first q only decides which entries are ties: a wrong number of turns puts q more than "
    "half a turn from the reference, so the entry goes to the exact search (near_angle), which "
    "finds the same; q is recomputed from the corrected turns afterwards"
)
_CALLERS_PASS_CROSS = (
    "every caller passes the axis' precomputed skew(axis).T (URGeometry.cross1/5/6): the branch "
    "for None is never taken, and recomputing gives the same matrix"
)
_CHOICE_MANY_Q = "q = values + TAU * turns"
_VALID = "valid = (q >= lower - LIMIT_TOL) & (q <= upper + LIMIT_TOL)"
_NEAR_QUICK = "if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL and ("
_NEAR_LOOP = "if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:"
_PITCH = "no_pitch = np.abs(np.sum(linear * angular, axis=1)) < STRUCTURE_TOL"
_NO_PITCH = (
    "URDF joints have no pitch: a revolute joint's linear part p × u is orthogonal to u (0 to "
    "rounding), and a prismatic one fails the unit-axis test; the sum over joints is as small"
)
EQUIVALENTS += [
    _screws('with np.errstate(invalid="ignore"):', "with np.errstate(invalid=None):",
            "numpy's error state only decides whether a warning is printed for NaN values "
            "(no solution), which come out as NaN and inf cost either way"),
    _screws("turns = np.round((clipped - values) / TAU)",
            "turns = np.round((clipped + values) / TAU)", _QUICK_MANY),
    _screws(_CHOICE_MANY_Q, _CHOICE_MANY_Q.replace("+ TAU *", "- TAU *"), _QUICK_MANY),
    _screws(_CHOICE_MANY_Q, _CHOICE_MANY_Q.replace("TAU * turns", "TAU / turns"), _QUICK_MANY),
    _screws("tie = np.abs(q - clipped) >= HALF_TURN_SAFE",
            "tie = np.abs(q - clipped) > HALF_TURN_SAFE", _NEVER_EQUAL),
    _screws("turns -= q > upper + LIMIT_TOL  # value + 2π·turns as near_angle: the same last bit",
            "turns -= q >= upper + LIMIT_TOL  # value + 2π·turns as near_angle: the same last bit",
            _NEVER_EQUAL),
    _screws("turns += q < lower - LIMIT_TOL", "turns += q <= lower - LIMIT_TOL", _NEVER_EQUAL),
    _screws(_VALID, _VALID.replace("q >= lower", "q > lower"), _NEVER_EQUAL),
    _screws(_VALID, _VALID.replace("q <= upper", "q < upper"), _NEVER_EQUAL),
    _screws("np.minimum(np.maximum(q, lower, out=q), upper, out=q)",
            "np.minimum(np.maximum(q, lower, ), upper, out=q)",
            "the inner out= only saves an allocation: the outer call writes the same values "
            "into q"),
    _screws(_NEAR_QUICK, _NEAR_QUICK.replace("candidate <= upper", "candidate < upper"),
            _NEVER_EQUAL),
    _screws(_NEAR_QUICK, _NEAR_QUICK.replace("upper + LIMIT_TOL", "upper - LIMIT_TOL"),
            "the quick test only decides whether the loop over k − 1, k, k + 1 runs; a "
            "candidate it refuses within LIMIT_TOL of the upper limit is found by the loop"),
    _screws(_NEAR_LOOP, _NEAR_LOOP.replace("LIMIT_TOL <= candidate", "LIMIT_TOL < candidate"),
            _NEVER_EQUAL),
    _screws(_NEAR_LOOP, _NEAR_LOOP.replace("candidate <= upper", "candidate < upper"),
            _NEVER_EQUAL),
    _screws("inside = (candidates >= lower[:, None] - LIMIT_TOL) & (candidates <= upper[:, None] "
            "+ LIMIT_TOL)",
            "inside = (candidates >= lower[:, None] - LIMIT_TOL) & (candidates < upper[:, None] "
            "+ LIMIT_TOL)", _NEVER_EQUAL),
    _screws("chosen = np.take_along_axis(candidates, best, axis=-1)[..., 0]",
            "chosen = np.take_along_axis(candidates, best, )[..., 0]", _LAST_AXIS),
    _screws("found = np.isfinite(np.take_along_axis(distance, best, axis=-1)[..., 0])",
            "found = np.isfinite(np.take_along_axis(distance, best, )[..., 0])", _LAST_AXIS),
    _screws("unit = np.abs(np.linalg.norm(angular, axis=1) - 1.0) < STRUCTURE_TOL",
            "unit = np.abs(np.linalg.norm(angular, axis=1) - 1.0) <= STRUCTURE_TOL",
            _NEVER_EQUAL),
    _screws(_PITCH, _PITCH.replace("axis=1", "axis=None"), _NO_PITCH),
    _screws(_PITCH, _PITCH.replace(", axis=1)", ", )"), _NO_PITCH),
    _screws(_ROTATE, _ROTATE.replace("cross_t is None", "(cross_t is None) and False"),
            _CALLERS_PASS_CROSS),
    _screws(_ROTATE, _ROTATE.replace("skew(axis)", "skew(None)"), _CALLERS_PASS_CROSS),
    _screws(_ROTATE, _ROTATE.replace("cross_t is None", "cross_t is not None"),
            _CALLERS_PASS_CROSS),
]  # fmt: skip

# ---------------------------------------------------------------------------- issue 20: fast paths
# cartesian/batch_track.py (vectorised closed-form follower) and cartesian/lean_track.py (lean loop)
_batch = _module(("cartesian/batch_track.py",))
_lean = _module(("cartesian/lean_track.py",))
_RECHECKED = (
    "the first sample's rotation is checked again by _on_path (q[0] is q0) against both "
    "tolerances, and a q0 off the target is no closed-form branch (_branch_of): None either way"
)
_EMPTY_SUM = "for i = n − 1 the row slice lu[i, i + 1:] is empty: the einsum subtracts 0"
_BT_CONTINUOUS = "if not np.abs(guess - q[1]).max() <= bound:"
EQUIVALENTS += [
    _batch("if not distance[order[0]] <= SAME_BRANCH or distance[order[1]] <= OTHER_BRANCH:",
           "if not distance[order[0]] < SAME_BRANCH or distance[order[1]] <= OTHER_BRANCH:",
           _NEVER_EQUAL),
    _batch(_BT_CONTINUOUS, _BT_CONTINUOUS.replace("<=", "<"), _NEVER_EQUAL),
    _batch("return bool(frobenius2.max() <= frobenius_tolerance(tracker.rotation_tolerance))",
           "return bool(frobenius2.max() < frobenius_tolerance(tracker.rotation_tolerance))",
           _NEVER_EQUAL),
    _batch("if not peak < 1.0 - RELATIVE_MARGIN:", "if not peak <= 1.0 - RELATIVE_MARGIN:",
           _NEVER_EQUAL),
    _batch("v_qd = jacobians[:3] * qd  # (3, nq, N)", "v_qd = jacobians[:4] * qd  # (3, nq, N)",
           "the extra (angular) row of v_qd and σ is never read: _summed_cross reads rows 0–2"),
    _batch("if not np.abs(multipliers).max(initial=0.0) <= MAX_MULTIPLIER:",
           "if not np.abs(multipliers).max(initial=1.0) <= MAX_MULTIPLIER:",
           "max(|m|, 1) ≤ 8 exactly when |m| ≤ 8 (and 1 ≤ 8 when there is no multiplier)"),
    _batch("if i < n - 1:", "if i <= n - 1:", _EMPTY_SUM),
    _batch("if i < n - 1:", "if i < n + 1:", _EMPTY_SUM),
    _batch("floats = None if rotation is None else rotation.reshape(9).tolist()",
           "floats = None if (rotation is None) or True else rotation.reshape(9).tolist()",
           _RECHECKED),
    _batch("evaluation = tracker.evaluate(q0, position.tolist(), floats)",
           "evaluation = tracker.evaluate(q0, position.tolist(), None)", _RECHECKED),
    _batch("task = jacobians if len(tracker.rows) == 6 else jacobians[tracker.rows]  # (nq, nq, N)",
           "task = jacobians if (len(tracker.rows) == 6) and False else jacobians[tracker.rows]  "
           "# (nq, nq, N)",
           "the rows of a 6-row task are 0…5: indexing them copies the same matrices"),
    _batch("if solver is None or kinematics is None:",
           "if solver is None and kinematics is None:",
           "kinematics is None whenever the solver is (the line before), and every arm with a "
           "vectorised closed form (UR family, planar 2R: serial chains of 1-dof joints) has "
           "batch kinematics"),
]  # fmt: skip
# ------------------------------------------------------------------- issue 18: planar fast path
_planar = _module(("kinplan/ik/planar.py",))
_PLANAR_SUM = (
    "a non-finite input makes the mutated sum non-finite too (NaN and ±inf propagate through "
    "+ and −); finite inputs whose sum overflows only in one form are far out of reach, where "
    "both paths find no solution (position) or the same nearest equivalents (reference)"
)
_PLANAR_REACH = "if not (abs(off_plane) <= PLANAR_TOL and abs(cosine) <= 1.0 + CLAMP):"
_PLANAR_JOINTS = (
    "self._joint_floats = tuple(zip(*limits, strict=True))  # per joint: lower, upper, weight"
)
EQUIVALENTS += [
    _planar("(np.abs(cosine) <= 1.0 + CLAMP)[..., None], cosine.shape + (len(signs),)",
            "(np.abs(cosine) < 1.0 + CLAMP)[..., None], cosine.shape + (len(signs),)",
            _NEVER_EQUAL),
    _planar("free = d2 < FREE_TOL**2", "free = d2 <= FREE_TOL**2", _NEVER_EQUAL),
    _planar(_PLANAR_REACH, _PLANAR_REACH.replace("off_plane) <=", "off_plane) <"), _NEVER_EQUAL),
    _planar(_PLANAR_REACH, _PLANAR_REACH.replace("cosine) <=", "cosine) <"), _NEVER_EQUAL),
    _planar("if d2 < FREE_TOL**2:", "if d2 <= FREE_TOL**2:", _NEVER_EQUAL),
    _planar("if not math.isfinite(px + py + pz):", "if not math.isfinite(px + py - pz):",
            _PLANAR_SUM),
    _planar("if not math.isfinite(px + py + pz):", "if not math.isfinite(px - py + pz):",
            _PLANAR_SUM),
    _planar("if not math.isfinite(ref1 + ref2):", "if not math.isfinite(ref1 - ref2):",
            _PLANAR_SUM),
    _planar("ref = np.asarray(q_ref, dtype=float)", "ref = np.asarray(q_ref, dtype=None)",
            "the reference's values are read as Python numbers (tolist) and only meet floats: "
            "an integer or float array gives the same arithmetic"),
    _planar("position = np.asarray(position, dtype=float)",
            "position = np.asarray(position, dtype=None)",
            "the position's values are read as Python numbers (tolist) and only meet floats"),
    _planar(_PLANAR_JOINTS, _PLANAR_JOINTS.replace("strict=True", "strict=None"),
            "the three lists have nq entries each: zip's strictness never fires"),
    _planar(_PLANAR_JOINTS, _PLANAR_JOINTS.replace(", strict=True", ", "),
            "the three lists have nq entries each: zip's strictness never fires"),
    _planar(_PLANAR_JOINTS, _PLANAR_JOINTS.replace("strict=True", "strict=False"),
            "the three lists have nq entries each: zip's strictness never fires"),
    _planar("if min(solver.link_lengths) < STRUCTURE_TOL:",
            "if min(solver.link_lengths) <= STRUCTURE_TOL:", _NEVER_EQUAL),
    _planar("if d2 < FREE_TOL**2:", "if d2 < FREE_TOL * 2:",
            "a target within 1.4e-6 m of the first axis leaves the plain-float path for the "
            "vectorised one, which gives the same answer (tested to 1e-9 rad)"),
    _planar("psi1 = np.where(free[:, None], wrap_angle(angle[:, None] - psi2), psi1)",
            "psi1 = np.where(free[:, None], wrap_angle(angle[:, None] + psi2), psi1)",
            "θ1 is free only for a target on the first axis, which only an arm with l1 = l2 "
            "reaches, folded (ψ2 = ±π): angle ± ψ2 differ by 2π, which wrap_angle removes"),
    _planar("ok &= untilted[:, None] & (turn_error <= PLANAR_TOL)",
            "ok &= untilted[:, None] & (turn_error < PLANAR_TOL)", _NEVER_EQUAL),
    _planar("untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=-1) <= PLANAR_TOL",
            "untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=+1) <= PLANAR_TOL",
            "the vectors are the rows of an (N, 3) array: axis 1 is the last axis"),
    _planar("untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=-1) <= PLANAR_TOL",
            "untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=-1) < PLANAR_TOL",
            _NEVER_EQUAL),
    _planar("fill = np.zeros((len(positions), 2))", "fill = np.zeros((len(positions), 3))",
            "only the first column of fill is read (θ1 where it is free)"),
]  # fmt: skip
EQUIVALENTS += [
    _batch("distance[np.isnan(distance)] = np.inf  # rows without a solution",
           "distance[np.isnan(distance)] = None  # rows without a solution",
           "None stored into a float array is NaN, which argsort puts last and every <= "
           "comparison rejects, exactly as inf"),
    _batch("floats = None if rotation is None else rotation.reshape(9).tolist()",
           "floats = None", _RECHECKED),
    _batch("rows = np.asarray(matrix, dtype=float).tolist()",
           "rows = np.asarray(matrix, dtype=None).tolist()",
           "the Jacobians are float arrays: the conversion is a no-op"),
    _batch("for i in range(k + 1, n):", "for i in range(n):",
           "rows above the pivot are never read again, and the pivot row is replaced by a new "
           "list while the elimination keeps the old one (pivot_row): the order is the same"),
    _batch("angular = bool(tracker.rows.max() >= 3)  # a position task needs the linear rows alone",
           "angular = bool(tracker.rows.max() >= 4)  # a position task needs the linear rows alone",
           "task rows end at 2 (position), 1 (planar position) or 5 (pose, planar pose): never "
           "at 3"),
]  # fmt: skip
_NEGATIVE_RESHAPE = "numpy's reshape takes any negative size as 'the rest'"
_LEAN_STACKS = "q_out, dq_out = np.array(qs).reshape(-1, nq), np.array(dqs).reshape(-1, nq)"
EQUIVALENTS += [
    _lean("if not ok or abs(q - q_prev).max() > max_step:",
          "if not ok or abs(q - q_prev).max() >= max_step:", _NEVER_EQUAL),
    _lean("if not unexplained.max(initial=0.0) <= JUMP_SHARE * tracker.jump_tolerance:",
          "if not unexplained.max(initial=0.0) < JUMP_SHARE * tracker.jump_tolerance:",
          _NEVER_EQUAL),
    _lean(_LEAN_STACKS, _LEAN_STACKS.replace("array(qs).reshape(-1", "array(qs).reshape(-2"),
          _NEGATIVE_RESHAPE),
    _lean(_LEAN_STACKS, _LEAN_STACKS.replace("array(dqs).reshape(-1", "array(dqs).reshape(-2"),
          _NEGATIVE_RESHAPE),
    _lean("stack = np.array(jacobians).reshape(-1, 6, nq)",
          "stack = np.array(jacobians).reshape(-2, 6, nq)", _NEGATIVE_RESHAPE),
]  # fmt: skip
EQUIVALENTS += [
    _follow("guess = q_prev + qd_prev * steps[k] + (0.5 * steps[k] ** 2) * qdd_first",
            "guess = q_prev + qd_prev / steps[k] + (0.5 * steps[k] ** 2) * qdd_first",
            "qd_prev is the first sample's q̇, zero: every time law follow samples (the "
            "profiles, the retimed law) starts at rest"),
    _follow("corrections = 1", "corrections = 2",
            "corrections is only tested for truth (check_sample's `if corrections:`)"),
]  # fmt: skip
EQUIVALENTS += [
    _lean("task = jacobians if len(tracker.rows) == 6 else jacobians[:, tracker.rows]",
          "task = jacobians if len(tracker.rows) == 7 else jacobians[:, tracker.rows]",
          "the rows of a 6-row task are 0…5: indexing them copies the same matrices"),
    _lean("if rows < cols:", "if rows <= cols:",
          "_stacked_rates returns for square task Jacobians (rows == cols) before this test"),
]  # fmt: skip
_STEPS = "steps = np.diff(t, prepend=0.0).tolist()  # h_k = t_k − t_(k−1) [s]"
EQUIVALENTS += [
    _lean("if not unexplained.max() <= JUMP_SHARE * tracker.jump_tolerance:",
          "if not unexplained.max() < JUMP_SHARE * tracker.jump_tolerance:", _NEVER_EQUAL),
    _lean(_STEPS, _STEPS.replace("prepend=0.0", "prepend=1.0"),
          "steps[0] is never read: the first sample is the start's IK, not a prediction"),
    _lean("scales = np.zeros((n, 2))", "scales = np.zeros((n, 3))",
          "the third column of the scales is zero and its rates are never read"),
]  # fmt: skip
_LEAN_SOLVE = "guess, positions[k], rotations[k], evaluated=evaluation )"
EQUIVALENTS += [
    _lean(_LEAN_SOLVE, "guess, positions[k], rotations[k], )", _REUSED),
    _lean("guess = q_prev + qd_first * steps[1] + (0.5 * steps[1] ** 2) * qdd_first",
          "guess = q_prev - qd_first * steps[1] + (0.5 * steps[1] ** 2) * qdd_first",
          "qd_first is the first sample's q̇, zero: every time law follow samples (the "
          "profiles, the retimed law) starts at rest"),
    _lean("every = len(rows) == 6", "every = None",
          "the rows of a 6-row task are 0…5: indexing them gives the same matrix"),
    _lean("wide = len(rows) < tracker.robot.nq", "wide = len(rows) <= tracker.robot.nq",
          "for a square J of full rank the minimum-norm solution Jᵀ(JJᵀ)⁻¹B is J⁻¹B"),
]  # fmt: skip
EQUIVALENTS.append(
    _lean("square = len(rows) == tracker.robot.nq", "square = None",
          "for a square J of full rank the least-squares solution (JᵀJ)⁻¹JᵀB is J⁻¹B"),
)  # fmt: skip

# ---------------------------------------------------------------------------- issue 20: polynomials
_polynomials = _module(("kinplan/trajectory/polynomials.py",))
_SPLINE_TOO_SHORT = "if requested is not None and requested < minimum * (1.0 - 1e-12):"
EQUIVALENTS += [
    _polynomials("points = points[np.concatenate(([True], steps > 1e-12))]",
                 "points = points[np.concatenate(([True], steps >= 1e-12))]",
                 "differs only for two consecutive points exactly 1e-12 rad apart (the norm of "
                 "their difference equal to the threshold bit for bit)"),
    _polynomials(_SPLINE_TOO_SHORT, _SPLINE_TOO_SHORT.replace(" < ", " <= "),
                 "differs only for a requested duration equal bit for bit to the computed "
                 "minimum · (1 − 1e-12)"),
    _polynomials('what = "velocity" if by_speed[j] >= by_acceleration[j] else "acceleration"',
                 'what = "velocity" if by_speed[j] > by_acceleration[j] else "acceleration"',
                 "differs only when the joint's velocity and acceleration limits give the same "
                 "minimum time bit for bit; the joint then would exceed both limits, so the "
                 "message is true with either name"),
]  # fmt: skip

# ---------------------------------------------------------------------------- the compiled loop
_lk = _module(("cartesian/lean_kernel.py",))
_DTYPE = (
    "the callers pass float64 arrays (and int64 rows); without the conversion numba compiles "
    "the same loop for the given dtype, which computes in float64 alike: the same results"
)
_COMPILED_OR_NOT = (
    "compiled or interpreted, cached or not, the functions compute the same values; only the "
    "speed and the start-up differ"
)
_CHECK_POINTS = (
    "the screw check needs some configurations, not these: a geometry that disagrees with "
    "Pinocchio does so at any generic configuration (the three drawn, four, other seeds, or "
    "ranges of ±π for every joint), and a right one agrees at all"
)
EQUIVALENTS += [
    *(
        _lk(f"{target} = np.ascontiguousarray(screws.{source}, dtype=float)",
            f"{target} = np.ascontiguousarray(screws.{source}, {mutant})", _DTYPE)
        for target, source in (("directions", "directions"), ("points", "points"),
                               ("tool", "tool.homogeneous"))
        for mutant in ("dtype=None", "")
    ),
    *(
        _lk(f"np.ascontiguousarray({name}, dtype=float),",
            f"np.ascontiguousarray({name}, {mutant}),", _DTYPE)
        for name in ("grid", "velocities", "positions")
        for mutant in ("dtype=None", "")
    ),
    *(
        _lk("None if rotations is None else np.ascontiguousarray(rotations, dtype=float),",
            f"None if rotations is None else np.ascontiguousarray(rotations, {mutant}),", _DTYPE)
        for mutant in ("dtype=None", "")
    ),
    _lk("rows = np.asarray(rows, dtype=np.int64)", "rows = np.asarray(rows, dtype=None)", _DTYPE),
    _lk("rows = np.asarray(rows, dtype=np.int64)", "rows = np.asarray(rows, )", _DTYPE),
    *(
        _lk("return function if numba is None else numba.njit(cache=True)(function)", mutant,
            _COMPILED_OR_NOT)
        for mutant in (
            "return function if (numba is None) and False else numba.njit(cache=True)(function)",
            "return function if (numba is None) or True else numba.njit(cache=True)(function)",
            "return function if numba is None else numba.njit(cache=False)(function)",
            "return function if numba is None else numba.njit(cache=None)(function)",
            "return function if numba is not None else numba.njit(cache=True)(function)",
        )
    ),
    _lk("rng = np.random.default_rng(0)", "rng = np.random.default_rng(1)", _CHECK_POINTS),
    _lk("rng = np.random.default_rng(0)", "rng = np.random.default_rng(None)", _CHECK_POINTS),
    _lk("for q in rng.uniform(low, high, size=(3, robot.nq)):",
        "for q in rng.uniform(low, high, size=(4, robot.nq)):", _CHECK_POINTS),
    _lk("for q in rng.uniform(low, high, size=(3, robot.nq)):",
        "for q in rng.uniform(low, size=(3, robot.nq)):", _CHECK_POINTS),
    _lk("low = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)",
        "low = np.where(None, robot.lower, -np.pi)", _CHECK_POINTS),
    _lk("low = np.where(np.isfinite(robot.lower), robot.lower, -np.pi)",
        "low = np.where(np.isfinite(robot.lower), robot.lower, +np.pi)", _CHECK_POINTS),
    _lk("high = np.where(np.isfinite(robot.upper), robot.upper, np.pi)",
        "high = np.where(None, robot.upper, np.pi)", _CHECK_POINTS),
    _lk("np.abs(pose - robot.fk(q).homogeneous).max() <= AGREEMENT",
        "np.abs(pose - robot.fk(q).homogeneous).max() < AGREEMENT", _NEVER_EQUAL),
    _lk("and np.abs(jacobian - robot.jacobian(q)).max() <= AGREEMENT",
        "and np.abs(jacobian - robot.jacobian(q)).max() < AGREEMENT", _NEVER_EQUAL),
]  # fmt: skip
