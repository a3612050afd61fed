"""The layout of the Python package: no import cycle among its modules (function-level imports
included), the analysis layers import only downwards, and no Python file is over 800 lines."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "hexadyn"
#: The analysis layers, bottom first: each may import only those before it.
LAYERS = ("hexadyn.results", "hexadyn.energy", "hexadyn.plots", "hexadyn.report")
#: Compiled modules of the package: nodes without imports.
EXTENSIONS = {"hexadyn._core"}
MAX_LINES = 800


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path, modules: set[str]) -> set[str]:
    """The package modules `path` imports anywhere in it (module level, in functions, under
    TYPE_CHECKING): ``from a import b`` counts as importing ``a.b`` if that is a module, else
    ``a``."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base)
    return found & modules - {name}


def import_graph() -> dict[str, set[str]]:
    files = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(p) for p in files} | EXTENSIONS
    return {module_name(p): imported_modules(p, modules) for p in files} | {name: set() for name in EXTENSIONS}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the graph as a list of modules (the first repeated at the end), or None."""
    state: dict[str, str] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_no_import_cycle():
    graph = import_graph()
    assert {"hexadyn", "hexadyn.results", "hexadyn.montecarlo.campaign"} <= set(graph)
    assert "hexadyn.energy" in graph["hexadyn.plots"], "the import graph misses imports"
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_the_cycle_finder_finds_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b", "c"}, "b": {"c"}, "c": set()}) is None


def test_analysis_layers_import_downwards():
    graph = import_graph()
    for k, module in enumerate(LAYERS):
        upper = set(LAYERS[k + 1 :])
        assert not graph[module] & upper, f"{module} imports {sorted(graph[module] & upper)}"


def test_no_python_file_over_the_limit():
    files = [p for folder in ("python", "tests", "benches") for p in (ROOT / folder).rglob("*.py")]
    assert len(files) > 20
    long = {str(p.relative_to(ROOT)): n for p in files if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"Python files over {MAX_LINES} lines: {long}"
