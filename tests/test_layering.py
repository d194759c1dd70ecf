"""The package's layering, read from the source with :mod:`ast` (imports inside functions count,
and a name taken from a package's lazy table counts as an import of the module it loads):
``pulses`` imports neither ``rocking`` nor ``pipeline``, ``rocking`` does not import ``pipeline``,
the modules of ``pulses`` and of ``pipeline`` import each other without a cycle, and the rooms of
``pulses`` stand one on another (the formats under the record type, the readers on both)."""
from __future__ import annotations

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGES = ("pulses", "rocking", "pipeline")


def _modules(package: str) -> dict[str, pathlib.Path]:
    """``{"sub.module": path}`` of every module of ``package`` and its subpackages (``__init__`` by
    its package's dotted name relative to ``package``, ``""`` for the package itself)."""
    out = {}
    for p in sorted((ROOT / package).rglob("*.py")):
        parts = p.relative_to(ROOT / package).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def lazy_table(package: str) -> dict[str, str]:
    """The ``_WHERE`` table of a package's ``__init__`` (public name -> its module), read with
    :mod:`ast`; empty where there is none."""
    init = ROOT.joinpath(*package.split("."), "__init__.py")
    if not init.exists():
        return {}
    for node in ast.parse(init.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "_WHERE" for t in node.targets):
            return ast.literal_eval(node.value)
    return {}


def imports(path: pathlib.Path, package: str) -> set[str]:
    """Absolute names of every module ``path`` imports (top level and inside functions);
    ``package.x`` for a module of a package, the top-level name otherwise; a name imported from a
    package with a lazy table (``from pulses import read_record``) counts as its module
    (``pulses.io``).  ``path`` is a module of ``package`` (a dotted name, a subpackage's
    ``package.sub``); relative imports resolve from it."""
    out = set()
    here = package.split(".")
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(here[:len(here) - node.level + 1])
                mod = f"{base}.{node.module}" if node.module else base
            else:
                mod = node.module or ""
            out.add(mod)
            folder = ROOT.joinpath(*mod.split("."))
            if mod.split(".")[0] in PACKAGES and folder.is_dir():  # ``from . import x``: the module x
                out.update(f"{mod}.{a.name}" for a in node.names
                           if (folder / f"{a.name}.py").exists() or (folder / a.name).is_dir())
                lazy = lazy_table(mod)
                out.update(f"{mod}.{lazy[a.name]}" for a in node.names if a.name in lazy)
    return out


def _package_of(package: str, name: str) -> str:
    """The dotted package a module ``name`` of ``package`` (from :func:`_modules`) sits in."""
    path = _modules(package)[name]
    return ".".join((package, *path.relative_to(ROOT / package).parent.parts))


def _graph(package: str) -> dict[str, set[str]]:
    mods = _modules(package)
    graph = {}
    for name, path in mods.items():
        deps = set()
        for imp in imports(path, _package_of(package, name)):
            parts = imp.split(".")
            rest = ".".join(parts[1:])
            if parts[0] == package and rest in mods and rest != name and rest != "":
                deps.add(rest)
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
    src.write_text("def f():\n    from . import runner\n    from .record import Task\n    from ..reports import figures\n"
                   "    import rocking.lanes\n")
    assert imports(src, "pipeline.batch") >= {"pipeline.batch.runner", "pipeline.batch.record",
                                              "pipeline.reports.figures", "rocking.lanes"}


def test_checker_sees_names_of_a_lazy_table(tmp_path):
    src = tmp_path / "m.py"
    src.write_text("def f():\n    from pulses import read_record, fit_pulse\n    from . import Record\n")
    assert imports(src, "pulses") >= {"pulses.io", "pulses.fit", "pulses.record"}


def test_no_import_cycle_in_pulses():
    graph = _graph("pulses")
    assert {"record", "formats", "formats.at2", "io", "io.read"} <= set(graph)  # the rooms were read
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


#: the rooms of ``pulses`` from the ground up: a module imports modules of lower layers and of its
#: own room only (``formats.at2`` may import ``formats.registry``; ``record`` no module of
#: ``io``).  The formats say what a file or a trace states, below the record type; ``io`` builds
#: records from files; fitting and classification use records.  A module not listed here sits at
#: the top: nothing of ``pulses`` may import it until it is placed.
PULSES_LAYERS = [
    ("lazy", "errors", "bytecache", "export"),
    ("units", "orientation"),
    ("formats",),
    ("record",),
    ("shapes", "pairs"),
    ("triplets", "scenario", "db4"),
    ("io", "fit", "velocity"),
]


def _layer(name: str) -> int:
    room = name.split(".")[0]
    return next((i for i, rooms in enumerate(PULSES_LAYERS) if room in rooms), len(PULSES_LAYERS))


def test_pulses_rooms_stand_one_on_another():
    graph = _graph("pulses")
    for name, deps in graph.items():
        if name == "":
            continue
        for dep in deps:
            ok = _layer(dep) < _layer(name) or dep.split(".")[0] == name.split(".")[0]
            assert ok, f"pulses.{name} imports pulses.{dep}, which stands above it (PULSES_LAYERS)"
    # the record type reaches the formats (Record.from_trace), never the readers that build records
    assert not {d for d in graph["record"] if d.split(".")[0] == "io"}


def test_no_import_cycle_in_pipeline():
    graph = _graph("pipeline")
    assert len(graph) > 20  # the package's modules were found
    assert find_cycle(graph) is None, " -> ".join(find_cycle(graph))


def test_imports_go_one_way():
    for package, forbidden in (("pulses", ("rocking", "pipeline")), ("rocking", ("pipeline",))):
        for name, path in _modules(package).items():
            bad = {i for i in imports(path, _package_of(package, name)) if i.split(".")[0] in forbidden}
            assert not bad, f"{package}/{name}.py imports {sorted(bad)}"


#: the groups of ``pipeline`` and those each must not import: the commands use the batch engine and
#: the reports; the batch engine writes through the reports; the reports use neither.  The top-level
#: modules are shared: ``cli``, ``api`` and ``plan`` (the run checked, as the batch's values) stand
#: above the groups; ``args``, ``values`` and ``interrupts`` are leaves every group may use.
PIPELINE_ROLES = {"batch": ("commands",), "reports": ("commands", "batch")}


def test_pipeline_groups_import_one_way():
    graph = _graph("pipeline")
    assert {n.split(".")[0] for n in graph} >= {"commands", "batch", "reports"}  # the groups were read
    for name, deps in graph.items():
        group = name.split(".")[0]
        for dep in deps:
            bad = dep.split(".")[0] in PIPELINE_ROLES.get(group, ())
            assert not bad, f"pipeline.{name} imports pipeline.{dep}"
    top = {n for n in graph if "." not in n and n not in ("commands", "batch", "reports")}
    for name in top - {"cli", "api", "plan", "__main__", ""}:  # the shared leaves use no group but reports
        assert not {d for d in graph[name] if d.split(".")[0] in ("commands", "batch")}, name


def test_the_batch_takes_values_not_the_command_line():
    """The batch engine imports neither argparse nor the command line's parsers (pipeline.args):
    the commands read their options into values (pipeline.values' rules), the batch takes them."""
    mods = _modules("pipeline")
    batch = {n: p for n, p in mods.items() if n == "batch" or n.startswith("batch.")}
    assert len(batch) > 20  # the batch's modules were read
    for name, path in batch.items():
        bad = {i for i in imports(path, _package_of("pipeline", name)) if i in ("argparse", "pipeline.args")}
        assert not bad, f"pipeline/{name.replace('.', '/')}.py imports {sorted(bad)}"
