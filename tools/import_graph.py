"""Import cycles and old module paths in kinplan/ and cartesian/ (issue 31).

Reads every ``import`` / ``from ... import`` statement (inside functions and ``TYPE_CHECKING``
blocks too) and builds the module graph; an import of an old flat path (``kinplan.robot``,
``kinplan.reach``, ...: shims that alias the moved module) counts as an import of the module it
names now. Prints the strongly connected components of more than one module (cycles) and, with
``--old-paths``, every import that still goes through an old path, as ``file:line``.

    python tools/import_graph.py [--old-paths]

Exit status 1 when there is a cycle.
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path

from kinplan._moved import MOVED as MOVED_MODULES

ROOT = Path(__file__).resolve().parents[1]

#: Old flat module → where it lives now, relative to ``kinplan`` (the old path is a shim).
MOVED = {old: new.removeprefix("kinplan.") for old, new in MOVED_MODULES.items()}
SHIMS = {f"kinplan.{old}" for old in MOVED} | {"kinplan._moved"}


def current(name: str) -> str:
    """The module path ``name`` stands for now (an old path's new one)."""
    for old, new in MOVED.items():
        if name == f"kinplan.{old}" or name.startswith(f"kinplan.{old}."):
            return f"kinplan.{new}" + name[len(f"kinplan.{old}") :]
    return name


def modules() -> dict[str, Path]:
    found = {}
    for package in ("kinplan", "cartesian"):
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            name = ".".join(parts)
            if not any(name == s or name.startswith(s + ".") for s in SHIMS):
                found[name] = path
    return found


def graph(found: dict[str, Path]) -> tuple[dict[str, set[str]], list[tuple[Path, int, str]]]:
    def resolve(name: str) -> str | None:
        name = current(name)
        while name and name not in found:
            name = name.rpartition(".")[0]
        return name or None

    edges: dict[str, set[str]] = {}
    old_paths = []
    for name, path in found.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                imported = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(parts + ([base] if base else []))
                imported = []
                for alias in node.names:  # a submodule, or a name of the module
                    full = f"{base}.{alias.name}"
                    imported.append(full if resolve(full) == current(full) else base)
            else:
                continue
            for target in imported:
                if not target.startswith(("kinplan", "cartesian")):
                    continue
                if current(target) != target:
                    old_paths.append((path, node.lineno, target))
                resolved = resolve(target)
                if resolved and resolved != name:
                    targets.add(resolved)
        edges[name] = targets
    return edges, sorted(set(old_paths))


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in edges:
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--old-paths", action="store_true", help="list imports of old paths")
    args = parser.parse_args()
    found = modules()
    edges, old_paths = graph(found)
    components = cycles(edges)
    print(f"{len(edges)} modules, {sum(map(len, edges.values()))} imports between them")
    for component in components:
        print("cycle:", " ⇄ ".join(component))
    if not components:
        print("no import cycle")
    if args.old_paths:
        for path, line, target in old_paths:
            print(f"{path.relative_to(ROOT)}:{line}: {target} → {current(target)}")
    print(f"{len(old_paths)} imports through old paths")
    return 1 if components else 0


if __name__ == "__main__":
    sys.exit(main())
