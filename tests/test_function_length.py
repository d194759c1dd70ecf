"""No hand-written function in pulses/, rocking/ or pipeline/ longer than MAX_LINES (read with ast,
decorators to last line), none in a package of PACKAGE_LIMITS longer than its limit, and no module
of those packages longer than their module limit: long functions hide their parts from tests,
long modules hold several ideas.  The generated step code of
the compiled core (rocking/_taylor_*.pxi, written by rocking/_make_*.py) is not Python source here."""
from __future__ import annotations

import ast
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
MAX_LINES = 100
#: functions allowed over the limit for a while, each with its length then (none may grow); none now
KNOWN_LONG: dict[str, int] = {}
#: packages already held to the house's limits: (lines a function, lines a module)
PACKAGE_LIMITS = {"pulses": (80, 600), "pipeline": (80, 600)}


def function_lengths():
    """``{"package/module.py:qualified name": lines}`` of every function and method."""
    out = {}
    for package in ("pulses", "rocking", "pipeline"):
        for path in sorted((ROOT / package).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"))

            def visit(node, prefix):
                for child in ast.iter_child_nodes(node):
                    if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                        name = f"{prefix}{child.name}"
                        if not isinstance(child, ast.ClassDef):
                            first = min([child.lineno] + [d.lineno for d in child.decorator_list])
                            out[f"{path.relative_to(ROOT).as_posix()}:{name}"] = child.end_lineno - first + 1
                        visit(child, name + ".")

            visit(tree, "")
    return out


def test_the_lengths_are_read():
    lengths = function_lengths()
    assert len(lengths) > 300  # every module was read
    assert lengths["pipeline/batch/tasks.py:record_ids"] > 10


def test_no_function_over_the_limit():
    long = {name: n for name, n in function_lengths().items() if n > MAX_LINES}
    new = {name: n for name, n in long.items() if name not in KNOWN_LONG}
    assert not new, f"functions over {MAX_LINES} lines: {new}"
    grown = {name: n for name, n in long.items() if n > KNOWN_LONG[name]}
    assert not grown, f"functions that grew: {grown}"
    split = set(KNOWN_LONG) - set(long)
    assert not split, f"now short, remove from KNOWN_LONG: {sorted(split)}"


def test_the_packages_held_to_the_house_limits():
    lengths = function_lengths()
    for package, (function_limit, module_limit) in PACKAGE_LIMITS.items():
        long = {name: n for name, n in lengths.items() if name.startswith(f"{package}/") and n > function_limit}
        assert not long, f"functions of {package} over {function_limit} lines: {long}"
        modules = {p.relative_to(ROOT).as_posix(): len(p.read_text(encoding="utf-8").splitlines())
                   for p in sorted((ROOT / package).rglob("*.py"))}
        assert len(modules) > 10  # the package's modules were read
        big = {name: n for name, n in modules.items() if n > module_limit}
        assert not big, f"modules of {package} over {module_limit} lines: {big}"
