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
_CONVERGED = "self.converged_position: tuple[float, float, float] = (math.nan,) * 3"
_DIFFERENCES = "self.differences: tuple[float, float, float, float] = (math.nan,) * 4"
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
    _paths(
        'with np.errstate(over="ignore", invalid="ignore"):',
        'with np.errstate(over="ignore", invalid=None):',
        "numpy's error state only decides "
        "whether a warning is printed; the checks that follow refuse the value either way",
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
    _ik(_CONVERGED, _CONVERGED.replace("(math.nan,) * 3", "None"), _OVERWRITTEN),
    _ik(_CONVERGED, _CONVERGED.replace("* 3", "* 4"), _OVERWRITTEN),
    _ik(_DIFFERENCES, _DIFFERENCES.replace("(math.nan,) * 4", "None"), _OVERWRITTEN),
    _ik(_DIFFERENCES, _DIFFERENCES.replace("* 4", "* 5"), _OVERWRITTEN),
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
        "converged = (it > 0 or not evaluated) and self.accepts(",
        "converged = (it >= 0 or not evaluated) and self.accepts(",
        "the caller's accepts() is repeated at the same q: the same answer, one more "
        "kinematics pass",
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
