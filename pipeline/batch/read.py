"""A task's ground motion, read: :func:`read_task` gives ``(horizontal, vertical, note)`` for every
kind of task of ``pipeline run``.

- a single component: the file, scaled;
- a direction of a pair: the component ``pulses.component(a1, a2, theta)`` of the two files
  (read once a process, :mod:`pipeline.batch.memo`), scaled;
- a pair with a vertical (``--triplet``, ``--pairs auto``; with ``--vertical auto``): the three
  read on one time axis (:func:`pulses.check_triplet`: cut to the shortest, the vertical made
  upward by its stated polarity), the horizontal in the task's direction and the vertical, both
  scaled;
- a record of a PEER download (:mod:`pipeline.batch.peer_inputs`): its two horizontals (and its
  vertical, where listed and read) from the download, as a pair.

A vertical that cannot be used (unreadable, its polarity not stated, on another time axis) is left
out and ``note`` says why (``vertical not used: ...``); the horizontals are then read as a pair.
The risk at a site measures the horizontal motion alone: it reads a task whose options say
``vertical="none"`` (:func:`horizontal_only`).
"""
from __future__ import annotations

import dataclasses

from . import memo, peer_inputs


def read_task(task):
    """``(horizontal record, upward vertical or None, note or None)`` of ``task``: the component in
    the task's direction, and the vertical on its time axis, both scaled by ``task.scale``."""
    import pulses

    want = task.options.vertical != "none"
    if task.peer is not None:
        first, second, name = peer_inputs.read_components(task)
        vertical, note = peer_inputs.read_vertical(task) if want else (None, "")
        return _with_vertical(task, first, second, vertical, name, note or None)
    kw = task.options.read.kwargs()
    if task.path2 is None:
        return _scaled(task, pulses.read_record(task.path, **kw)), None, None
    if not (want and task.vertical):
        first, second = _pair(task, kw)
        return _scaled(task, pulses.component(first, second, task.direction)), None, None
    first, second = (pulses.read_record(p, **kw) for p in (task.path, task.path2))
    try:
        vertical = pulses.read_record(task.vertical, **kw)
    except pulses.RecordError as exc:
        return _with_vertical(task, first, second, None, None, f"vertical not used: {exc}")
    return _with_vertical(task, first, second, vertical, task.vertical, None)


def horizontal_only(task):
    """``task`` as one whose vertical is not used: :func:`read_task` of it reads the horizontal
    motion as a lone pair does (a triplet's are otherwise cut to the shortest of the three)."""
    return dataclasses.replace(task, options=dataclasses.replace(task.options, vertical="none"))


def _pair(task, kw):
    """The two components of a pair (:func:`pulses.read_pair`), read once a process while the
    files stay the same."""
    import pulses

    read = lambda: pulses.read_pair(task.path, task.path2, **kw)  # noqa: E731
    try:
        key = (memo.file_key(task.path), memo.file_key(task.path2), repr(sorted(kw.items())))
    except OSError:  # read_pair says what is wrong
        return read()
    return memo.remembered("pair", key, read)


def _with_vertical(task, first, second, vertical, name, note):
    """The horizontal in the task's direction and the upward vertical (None where there is none
    or it cannot be used: ``note`` then says why), from the components as read."""
    import pulses

    up = None
    if vertical is not None:
        try:
            first, second, up = pulses.check_triplet(first, second, vertical, name)
        except pulses.RecordError as exc:
            note = f"vertical not used: {exc}"
    if up is None:
        first, second = pulses.check_pair(first, second)
    horizontal = pulses.component(first, second, task.direction or 0.0)
    return _scaled(task, horizontal), (None if up is None else _scaled(task, up)), note


def _scaled(task, record):
    return record.scaled(task.scale) if task.scale != 1.0 else record
