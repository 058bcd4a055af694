"""Point commands: record the current configuration (``r [name]``; p1, p2, ... by default, never a
name a recorded path uses), forget a point or path (``del``), list what was recorded (``list``)."""

from __future__ import annotations

import numpy as np

from kinplan.apps.teach.parsing import NAME
from kinplan.apps.teach.state import MoveSpec, PendantState, Reply


class PointCommands(PendantState):
    """The pendant's commands on recorded points (and the list of points and paths)."""

    def _record(self, arguments: list[str]) -> Reply:
        if arguments and arguments[0].lower() in ("ptp", "lin", "circ"):
            arguments = [self._next_name(), *arguments]
        if len(arguments) > 1 and arguments[1].lower() not in ("ptp", "lin", "circ"):
            raise ValueError(
                "usage: r [name] [ptp | lin [speed] | circ <via> [speed]], rec start [hz] or "
                "rec stop [tol_deg]"
            )
        name = arguments[0] if arguments else self._next_name()
        spec = self._move_spec(arguments[1:])
        if not NAME.match(name):
            raise ValueError(
                f"point name {name!r}: use letters, digits, _ and -, not first a digit"
            )
        if name in self.points:
            return Reply(f"refused: a point {name!r} exists; give another name or del {name}")
        taken = self._path_point_owner(name)
        if taken:
            return Reply(f"refused: {name!r} is taken by the path {taken}; give another name")
        self.points[name] = self.q.copy()
        self._order.append(("point", name))
        self.move_specs[name] = spec
        xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(self.q).translation)
        how = "" if spec == MoveSpec() else f", reached by {spec.yaml(name)}"
        return Reply(f"recorded {name} (tool at ({xyz}) m{how}); {len(self.points)} points")

    def _move_spec(self, arguments: list[str]) -> MoveSpec:
        """How the program reaches a point recorded with ``arguments`` after its name
        (:class:`kinplan.apps.teach.process.ProcessCommands` reads them; a plain ptp here)."""
        if arguments:
            raise ValueError("usage: r [name]")
        return MoveSpec()

    def _path_point_owner(self, name: str) -> str | None:
        """The recorded path whose name or program point names include ``name``, if any."""
        for path in self.paths.values():
            if name == path.name or name in path.point_names():
                return path.name
        return None

    def _next_name(self) -> str:
        k = len(self.points) + 1
        while f"p{k}" in self.points or self._path_point_owner(f"p{k}"):
            k += 1
        return f"p{k}"

    # -- the list ------------------------------------------------------------------------------
    def _delete(self, arguments: list[str]) -> Reply:
        if len(arguments) != 1:
            raise ValueError("usage: del <name>")
        name = arguments[0]
        if name in self.points:
            del self.points[name]
            self.move_specs.pop(name, None)
            self._order.remove(("point", name))
        elif name in self.paths:
            del self.paths[name]
            self._order.remove(("path", name))
        else:
            known = ", ".join(name for _, name in self._order) or "none"
            return Reply(f"no point {name!r}; recorded: {known}")
        return Reply(f"deleted {name}")

    def _list(self) -> Reply:
        if not self._order:
            return Reply("nothing recorded yet (r [name] records a point, rec start a path)")
        lines = []
        for kind, name in self._order:
            if kind == "point":
                q = self.points[name]
                xyz = ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation)
                degrees = ", ".join(f"{v:.2f}" for v in np.degrees(q))
                lines.append(f"{name}: joints [{degrees}] deg, tool ({xyz}) m")
            else:
                path = self.paths[name]
                lines.append(
                    f"{name}: path of {len(path.samples)} samples over {path.duration:.2f} s, "
                    f"spline through {len(path.knot_indices)} knots, max deviation "
                    f"{path.max_deviation:.2e} rad ({1000 * path.tool_deviation:.3f} mm at the "
                    "tool)"
                )
        return Reply("\n".join(lines))
