# SPDX-License-Identifier: Apache-2.0
"""The import graph of the harness package, from the source (AST only: nothing is imported, the
shared library is not needed). Every import counts, at module level or inside a function.

    python -m icoac.tools.imports          # prints "module -> imports" per module, then the checks

Exit status 1 if the graph has a cycle or a module imports icoac.cli (the command line only
parses and reports; nothing may depend on it).
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = "icoac"
ROOT = Path(__file__).resolve().parents[1]
FORBIDDEN = f"{PACKAGE}.cli"
ENTRY = f"{PACKAGE}.__main__"  # the one module allowed to import the command line

# The layers (folders of the package) and the layers each may import: the core imports no other
# layer; the integrations (Dask, Gymnasium) only the core; the studies the core, the Dask backend
# that runs their grids and the envs the trained baselines learn on; the command line and the
# maintainers' tools what they drive.
LAYERS = {"core": set(), "cluster": {"core"}, "gym": {"core"}, "studies": {"core", "cluster", "gym"},
          "cli": {"core", "cluster", "gym", "studies"}, "tools": {"core", "cluster", "studies"}}


def layer(module: str) -> str:
    """The layer of a module: its folder under the package (the command line: cli and __main__)."""
    name = module.split(".")[1]
    return name if name in LAYERS else "cli" if name == "__main__" else "core"


def module_name(path: Path, root: Path = ROOT) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _resolve(module: str, is_package: bool, level: int, name: str | None) -> str:
    base = module.split(".") if is_package else module.split(".")[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def imports_of(path: Path, modules: set[str], root: Path = ROOT) -> set[str]:
    """The harness modules a source file imports ("from . import x" counts as importing x)."""
    module = module_name(path, root)
    is_package = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            target = _resolve(module, is_package, node.level, node.module) if node.level else (node.module or "")
            names = [f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target for a in node.names]
        else:
            continue
        for name in names:
            while name and name not in modules:  # icoac.core.grid.run_grid -> icoac.core.grid
                name = name.rpartition(".")[0]
            if name and name != module and name != PACKAGE:
                out.add(name)
    return out


def graph(root: Path = ROOT) -> dict[str, set[str]]:
    """{module: harness modules it imports} of every module under root."""
    files = sorted(root.rglob("*.py"))
    modules = {module_name(f, root) for f in files}
    return {module_name(f, root): imports_of(f, modules, root) for f in files}


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """Every elementary cycle found by depth-first search (each reported once, from its first module)."""
    found: list[list[str]] = []
    seen: set[tuple[str, ...]] = set()

    def visit(node: str, path: list[str]) -> None:
        for nxt in sorted(g.get(node, ())):
            if nxt in path:
                cyc = path[path.index(nxt):]
                key = tuple(sorted(cyc))
                if key not in seen:
                    seen.add(key)
                    found.append(cyc + [nxt])
            elif len(path) < len(g):
                visit(nxt, path + [nxt])

    for start in sorted(g):
        visit(start, [start])
    return found


def problems(g: dict[str, set[str]]) -> list[str]:
    out = [f"cycle: {' -> '.join(c)}" for c in cycles(g)]
    out += [f"layer: {m} ({layer(m)}) imports {d} ({layer(d)})" for m, deps in sorted(g.items())
            for d in sorted(deps) if layer(d) != layer(m) and layer(d) not in LAYERS[layer(m)]]
    out += [f"{m} imports {FORBIDDEN}" for m, deps in sorted(g.items()) if FORBIDDEN in deps and m != ENTRY]
    return out


def main() -> int:
    g = graph()
    width = max(len(m) for m in g)
    for module in sorted(g):
        print(f"{module:<{width}} -> {', '.join(sorted(g[module])) or '-'}")
    bad = problems(g)
    for line in bad:
        print(f"ERROR: {line}")
    if not bad:
        print(f"no cycle; every layer imports only the layers it may; nothing but {ENTRY} imports {FORBIDDEN}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
