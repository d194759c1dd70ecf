"""The package's layering, read from the source with :mod:`ast` (imports inside functions count):
``pulses`` imports neither ``rocking`` nor ``pipeline``, ``rocking`` does not import ``pipeline``,
and the modules of ``pipeline`` import each other without a cycle."""
from __future__ import annotations

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("pulses", "rocking", "pipeline")


def _modules(package: str) -> dict[str, pathlib.Path]:
    return {p.stem: p for p in sorted((ROOT / package).glob("*.py"))}


def imports(path: pathlib.Path, package: str) -> set[str]:
    """Absolute names of every module ``path`` imports (top level and inside functions);
    ``package.x`` for a module of a package, the top-level name otherwise."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package if node.level == 1 else ""
                mod = f"{base}.{node.module}" if node.module else base
            else:
                mod = node.module or ""
            out.add(mod)
            if mod in PACKAGES:  # ``from . import x``: the module x of the package
                out.update(f"{mod}.{a.name}" for a in node.names if (ROOT / mod / f"{a.name}.py").exists())
    return out


def _graph(package: str) -> dict[str, set[str]]:
    mods = _modules(package)
    graph = {}
    for name, path in mods.items():
        deps = set()
        for imp in imports(path, package):
            parts = imp.split(".")
            if parts[0] == package and len(parts) > 1 and parts[1] in mods and parts[1] != name:
                deps.add(parts[1])
        graph[name] = deps
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` (its modules in order, the first repeated at the end), or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_checker_finds_a_cycle():
    # the checker itself: a cycle through three modules is found, a chain is not
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


def test_checker_sees_imports_inside_functions(tmp_path):
    src = tmp_path / "m.py"
    src.write_text("def f():\n    from . import runner\n    from .batch import Task\n    import rocking.lanes\n")
    assert imports(src, "pipeline") >= {"pipeline.runner", "pipeline.batch", "rocking.lanes"}


def test_no_import_cycle_in_pipeline():
    graph = _graph("pipeline")
    assert len(graph) > 20  # the package's modules were found
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


def test_imports_go_one_way():
    for package, forbidden in (("pulses", ("rocking", "pipeline")), ("rocking", ("pipeline",))):
        for name, path in _modules(package).items():
            bad = {i for i in imports(path, package) if i.split(".")[0] in forbidden}
            assert not bad, f"{package}/{name}.py imports {sorted(bad)}"
