"""The ``pipeline`` command: one sub-command per job, each in its own module.

Every sub-command module defines ``add_parser(subparsers)`` (which registers the sub-command and
sets ``func`` to the function that runs it with the parsed arguments and returns an exit code).
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys

from .values import ArgumentError

#: sub-command modules, in the order ``pipeline --help`` lists them
COMMANDS = ["simulate", "fit", "convert", "design", "spectrum", "chart", "run", "demo", "classify"]


class _Parser(argparse.ArgumentParser):
    #: every option string of the command and its sub-commands, for the suggestions of :func:`suggestion`
    known_options: set = set()
    #: the options that take one value (``--limit R``), for :func:`numbers_as_values`
    one_value: set = set()

    def add_argument(self, *names, **kwargs):
        _Parser.known_options.update(n for n in names if isinstance(n, str) and n.startswith("--"))
        action = super().add_argument(*names, **kwargs)
        if action.option_strings and action.nargs is None:
            _Parser.one_value.update(action.option_strings)
        return action

    def error(self, message):  # one line and exit status 2, as argparse does, without usage noise
        self.exit(2, f"{self.prog}: error: {message}{suggestion(message, _Parser.known_options)}\n")


def suggestion(message: str, options) -> str:
    """``; did you mean 'run'?`` for a mistyped sub-command, or ``--block`` for a mistyped option
    (among ``options``); blank when nothing is close."""
    import difflib
    import re

    m = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
    if m:
        choices = re.findall(r"'([^']*)'", m.group(2))
        close = difflib.get_close_matches(m.group(1), choices, n=1, cutoff=0.6)
        return f"; did you mean {close[0]!r}?" if close else ""
    m = re.search(r"unrecognized arguments: (.*)", message)
    if not m:
        return ""
    out = []
    for word in m.group(1).split():
        if word.startswith("--"):
            close = difflib.get_close_matches(word.split("=", 1)[0], sorted(options), n=1, cutoff=0.7)
            if close:
                out.append(f"{close[0]} for {word}")
    return f"; did you mean {', '.join(out)}?" if out else ""


def numbers_as_values(argv, options) -> list:
    """``argv`` with ``--limit -inf`` written ``--limit=-inf``: argparse takes a value that starts
    with ``-`` for an option unless it looks like a plain negative number (``-1``, ``-0.5``), so
    ``-inf``, ``-1e5`` or ``-0.5g`` after an option that takes a value got "expected one argument"
    instead of the option's own rule."""
    def number_like(word):
        if word[1:2].isdigit() or word[1:2] == ".":
            return True
        try:
            float(word)
        except ValueError:
            return False
        return True

    out = list(argv)
    k = 0
    while k < len(out) - 1:
        if out[k] in options and out[k + 1].startswith("-") and number_like(out[k + 1]):
            out[k:k + 2] = [f"{out[k]}={out[k + 1]}"]
        k += 1
    return out


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="pipeline", description="Size free-standing rocking columns against "
                     "near-fault pulses: read records, fit pulses, solve, design and verify.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"pipeline.commands.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"pipeline.commands.{name}":
                continue  # sub-command not built in this version
            raise
        module.add_parser(sub)
    return parser


#: the BLAS libraries' thread counts, set to 1 for the command unless the user set them
BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _one_blas_thread() -> None:
    """One BLAS thread in this process and the worker processes it starts, unless the environment
    says otherwise.  The package's matrices are small (the pulse fit's), so more threads never
    speed them up, while OpenBLAS starts one per core as numpy is imported (0.06 s of CPU a
    process here) and keeps them spinning after each call: the main process of a batch of nine
    pairs with ``--jobs 2`` spent 1.29 s of CPU with them, 1.11 s without
    (benchmarks/bench_directions.py).  Only before numpy is imported (as the command starts)
    does it take effect in this process."""
    if "numpy" not in sys.modules:
        for name in BLAS_THREADS:
            os.environ.setdefault(name, "1")


def main(argv=None) -> int:
    """Run the ``pipeline`` command with ``argv``, as the shell does, and return its exit status.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``pipeline`` (default: ``sys.argv[1:]``); ``pipeline --help`` lists
        the sub-commands (docs/commands.md).

    Returns
    -------
    int
        0 on success, 1 when a record or the file system failed, 2 for an argument error (its
        one-line reason printed on standard error), 130 when interrupted.

    See Also
    --------
    rocking.simulate : the solver ``pipeline simulate`` calls.

    Examples
    --------
    >>> from pipeline import main
    >>> main(["simulate", "--block", "7.5x1.8", "--pulse", "sine", "--ap", "0.5g", "--tp", "1.0"])
    7.5 x 1.8 m column (tan(alpha) = 0.24, p = 1.381 rad/s) under sine pulse ap=0.5g tp=1 s:
      survives; max|theta|/alpha = 0.7906 (max|theta| = 0.1862 rad)
      impacts: 1; model: fast (verdict by energy rule); body: rectangular, eta = 0.9183
      friction needed: up to 0.2997 at t = 0.237 s (at uplift 0.24), impulse ratio at impacts 0.1774; smallest normal force 0.8624 of the weight
    0
    """
    from . import interrupts

    _one_blas_thread()
    interrupts.reset()
    # from the start: an interrupt while the sub-commands are imported is not lost either
    with interrupts.handling(to_exit=argv is None):  # argv None: the program itself, about to exit
        try:
            parser = build_parser()
            args = parser.parse_args(numbers_as_values(sys.argv[1:] if argv is None else argv, _Parser.one_value))
            if not getattr(args, "func", None):
                parser.print_help()
                return 2
            try:
                code = int(args.func(args) or 0)
            except ArgumentError as exc:
                print(f"pipeline {args.command}: error: {exc}", file=sys.stderr)
                return 2
            except OSError as exc:  # the file system refused (a full disk, a folder gone ...)
                print(f"pipeline {args.command}: error: {exc}", file=sys.stderr)
                return 1
        except KeyboardInterrupt as exc:
            print("interrupted", file=sys.stderr)
            return exc.exit_status if isinstance(exc, interrupts.Interrupted) else 130
        signum = interrupts.pending()
        if signum is not None:  # an interrupt whose exception something swallowed
            print("interrupted", file=sys.stderr)
            return interrupts.EXIT_STATUS[signum]
        return code


if __name__ == "__main__":
    sys.exit(main())
