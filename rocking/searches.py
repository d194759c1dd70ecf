"""Record searches kept for a later call with the same inputs (off unless :func:`keep` is called).

A batch computes a pair's direction in passes (``pipeline.batch.passes``): a direction searched in
a first pass is computed again, with its check above the design width, in a later one.  The
search (:func:`rocking.widths._record_search`) is a deterministic function of the record, the
column and the search's settings (the check's settings play no part in it), so a process that
keeps its searches answers the second call with the first's result, the same to the last bit.
The key is a hash of every input, samples included: a different record never shares a search.
"""
from __future__ import annotations

import collections
import copy
import dataclasses
import hashlib

import numpy as np

_kept: collections.OrderedDict = collections.OrderedDict()
_size = 0


def keep(n: int) -> None:
    """Keep the last ``n`` record searches of this process (0: none, the default; the kept ones
    are dropped)."""
    global _size
    _size = max(0, int(n))
    while len(_kept) > _size:
        _kept.popitem(last=False)


def _digest(samples) -> str:
    return hashlib.sha256(np.ascontiguousarray(samples, dtype="<f8").tobytes()).hexdigest()


def key(excitation, vertical, settings, *column) -> tuple:
    """The inputs of one record search: samples (hashed), time step, vertical (hashed), the
    search's settings (without the check's ``check_*``) and the column's (height, criterion, ...)."""
    search = tuple((f.name, getattr(settings, f.name)) for f in dataclasses.fields(settings)
                   if not f.name.startswith("check_"))
    up = None if vertical is None else (_digest(vertical.acc), float(vertical.dt))
    return (_digest(excitation.acc), float(excitation.dt), up, search, column)


def remembered(k, search):
    """``search()``'s result ``(RequiredWidth, widths run)``, or a copy of the one kept for ``k``."""
    if _size:
        hit = _kept.get(k)
        if hit is not None:
            _kept.move_to_end(k)
            return copy.deepcopy(hit)
    res = search()
    if _size:
        _kept[k] = copy.deepcopy(res)
        while len(_kept) > _size:
            _kept.popitem(last=False)
    return res
