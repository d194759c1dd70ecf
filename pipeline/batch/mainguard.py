"""Worker processes started from a script: the ``if __name__ == "__main__":`` guard.

The worker processes of ``jobs > 1`` (and of ``--dask local``) are started clean, not forked from
the caller (a forked process with threads running is unsafe), and :mod:`multiprocessing` then
imports the caller's script again in each of them, to find what it defines.  A script that calls
:func:`pipeline.design` at its top level without the guard calls it again in every worker: each
re-ran the script's top level (59 s in one case) and failed to start processes of its own, and
every record failed with "A process in the process pool was terminated abruptly".
:func:`check` finds that case before any process starts and says what to write instead.
"""
from __future__ import annotations

import ast
import sys


def _is_guard(test) -> bool:
    """``__name__ == "__main__"`` (either way round)."""
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1 and isinstance(test.ops[0], ast.Eq)):
        return False
    sides = [test.left, test.comparators[0]]
    names = [s for s in sides if isinstance(s, ast.Name) and s.id == "__name__"]
    consts = [s for s in sides if isinstance(s, ast.Constant) and s.value == "__main__"]
    return len(names) == 1 and len(consts) == 1


def guarded_lines(source: str) -> list[tuple[int, int]]:
    """The line ranges of ``source`` inside an ``if __name__ == "__main__":`` block."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.If) and _is_guard(node.test) and node.body:
            out.append((node.body[0].lineno, node.body[-1].end_lineno or node.body[-1].lineno))
    return out


def unguarded_call() -> tuple[str, int] | None:
    """``(script, line)`` where the caller's ``__main__`` script, a file that worker processes
    import again, is running at its top level outside the guard (the line of the top-level
    statement now running); None otherwise (the guard is there, an interactive session or a
    notebook, ``python -c``, a source that cannot be read)."""
    import inspect

    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if name is not None and (name == "__main__" or name.endswith(".__main__")):
        return None  # a package's __main__ (python -m pipeline): multiprocessing leaves it out
    if not path or not str(path).endswith(".py"):
        return None
    frame, top = inspect.currentframe(), None
    while frame is not None:
        if frame.f_code.co_name == "<module>" and frame.f_globals is vars(main):
            top = frame  # the outermost is the script's own top level
        frame = frame.f_back
    if top is None:
        return None
    line = top.f_lineno
    try:
        with open(path, encoding="utf-8") as fh:
            spans = guarded_lines(fh.read())
    except (OSError, SyntaxError, ValueError):
        return None
    if any(lo <= line <= hi for lo, hi in spans):
        return None
    return str(path), line


def check(what: str) -> None:
    """Raise :class:`RuntimeError` naming the guard where :func:`unguarded_call` finds the call;
    ``what``: what starts the processes (``"jobs=2"``)."""
    found = unguarded_call()
    if found is None:
        return
    path, line = found
    raise RuntimeError(
        f"{what} starts worker processes, and each imports your script {path} again: the call at "
        f"its line {line} would run again in every one of them. Put the script's work under "
        f'`if __name__ == "__main__":` (docs/notebook.md shows how), or use jobs=1')
