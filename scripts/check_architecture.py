#!/usr/bin/env python3
"""Architecture checks of the beamfx package, from the source alone (``ast``; nothing is imported).

1. The import graph of the beamfx modules: module-level *and* function-level imports, relative
   imports resolved; its cycles (strongly connected components of two or more modules) are
   printed with one closed path through each.
2. Every function or method longer than ``--max-lines`` (80) lines, with file:line and length
   (from the ``def`` line to the last line of the body; a nested function counts in its parent
   too and is also listed on its own).
3. The length of ``run_scene`` in beamfx/runner.py (for information).

Exit status 1 when there is a cycle or a long function, else 0.

Usage: ``python scripts/check_architecture.py [--root DIR] [--max-lines N]``.
"""

import argparse
import ast
import sys
from pathlib import Path
from typing import NamedTuple

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "beamfx"
MAX_LINES = 80


class LongFunction(NamedTuple):
    file: str  # relative to the root, with forward slashes
    line: int
    name: str  # qualified: Class.method, outer.inner
    length: int

    @property
    def id(self):
        """``file::qualified name``: stable while lines move."""
        return f"{self.file}::{self.name}"


def module_files(root=ROOT, package=PACKAGE):
    """{dotted module name: path} of every .py file of the package."""
    out = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _base(module, is_package, node):
    """The absolute module an ``ImportFrom`` names (``from <base> import ...``)."""
    if node.level == 0:
        return node.module
    parts = module.split(".") if is_package else module.split(".")[:-1]
    parts = parts[: len(parts) - (node.level - 1)]
    return ".".join(parts + ([node.module] if node.module else []))


def imports_of(module, path, modules):
    """The beamfx modules that ``module`` imports anywhere in its file (sorted, no self)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name in modules)
        elif isinstance(node, ast.ImportFrom):
            base = _base(module, is_package, node)
            if node.module and base in modules:
                found.add(base)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                if sub in modules:
                    found.add(sub)
                elif node.module is None and base in modules:
                    found.add(base)
    found.discard(module)
    return sorted(found)


def import_graph(root=ROOT, package=PACKAGE):
    """{module: [imported beamfx modules]} over the whole package."""
    modules = module_files(root, package)
    return {m: imports_of(m, p, modules) for m, p in modules.items()}


def strongly_connected(graph):
    """Strongly connected components of ``graph`` (Tarjan), each a sorted list."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def cycles(graph):
    """The import cycles: components of two or more modules, sorted."""
    return sorted(c for c in strongly_connected(graph) if len(c) > 1)


def cycle_path(graph, component):
    """One closed import path through a component, e.g. ``[a, b, a]``: the shortest from its
    first module back to itself (breadth first inside the component)."""
    start, members = component[0], set(component)
    parent, queue = {start: None}, [start]
    while queue:
        v = queue.pop(0)
        for w in graph[v]:
            if w == start:
                path = [v]
                while parent[path[-1]] is not None:
                    path.append(parent[path[-1]])
                return [*reversed(path), start]
            if w in members and w not in parent:
                parent[w] = v
                queue.append(w)
    return component


def _functions(node, prefix=""):
    """(qualified name, def node) of every function and method under ``node``, nested ones
    too, in source order."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            name = f"{prefix}{child.name}"
            if not isinstance(child, ast.ClassDef):
                yield name, child
            yield from _functions(child, name + ".")
        else:
            yield from _functions(child, prefix)


def long_functions(root=ROOT, package=PACKAGE, max_lines=MAX_LINES):
    """Every function or method of the package longer than ``max_lines`` lines."""
    out = []
    for path in module_files(root, package).values():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        rel = path.relative_to(root).as_posix()
        for name, node in _functions(tree):
            length = node.end_lineno - node.lineno + 1
            if length > max_lines:
                out.append(LongFunction(rel, node.lineno, name, length))
    return sorted(out)


def function_length(path, name):
    """Lines of the top-level function ``name`` in ``path`` (None if there is none)."""
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == name:
            return node.end_lineno - node.lineno + 1
    return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--root", type=Path, default=ROOT, help="repository root")
    parser.add_argument("--max-lines", type=int, default=MAX_LINES)
    args = parser.parse_args(argv)

    graph = import_graph(args.root)
    edges = sum(len(v) for v in graph.values())
    found = cycles(graph)
    print(f"import graph: {len(graph)} modules, {edges} imports between them")
    for component in found:
        print(f"  cycle: {' -> '.join(cycle_path(graph, component))}")
        if len(component) > 2:
            print(f"         (all of {', '.join(component)})")
    print(f"  {len(found)} cycle(s)")

    long = long_functions(args.root, max_lines=args.max_lines)
    print(f"functions over {args.max_lines} lines:")
    for f in long:
        print(f"  {f.file}:{f.line}: {f.name} ({f.length} lines)")
    print(f"  {len(long)} long function(s)")

    n = function_length(args.root / PACKAGE / "runner.py", "run_scene")
    print(f"run_scene in {PACKAGE}/runner.py: {'not found' if n is None else f'{n} lines'}")
    return 1 if found or long else 0


if __name__ == "__main__":
    sys.exit(main())
