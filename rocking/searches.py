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

class Kept:
    """The last ``size`` results by key, kept as deep copies and handed out as deep copies (a
    caller may change what it gets); ``size`` 0 keeps nothing."""

    def __init__(self, size: int = 0):
        self._items: collections.OrderedDict = collections.OrderedDict()
        self.size = 0
        self.resize(size)

    def __len__(self) -> int:
        return len(self._items)

    def resize(self, size: int) -> None:
        """Keep at most ``size`` results (the oldest dropped)."""
        self.size = max(0, int(size))
        while len(self._items) > self.size:
            self._items.popitem(last=False)

    def remembered(self, k, compute):
        """``compute()``, or a copy of the result kept for ``k``."""
        if self.size:
            hit = self._items.get(k)
            if hit is not None:
                self._items.move_to_end(k)
                return copy.deepcopy(hit)
        res = compute()
        if self.size:
            self._items[k] = copy.deepcopy(res)
            self.resize(self.size)
        return res


_kept = Kept()
_size = 0


def keep(n: int) -> None:
    """Keep the last ``n`` record searches of this process (0: none, the default; the kept ones
    are dropped)."""
    global _size
    _kept.resize(n)
    _size = _kept.size


def digest(samples) -> str:
    """A hash of the samples (as little-endian float64)."""
    return hashlib.sha256(np.ascontiguousarray(samples, dtype="<f8").tobytes()).hexdigest()


def key(excitation, vertical, settings, *column) -> tuple:
    """The inputs of one record search: samples (hashed), time step, vertical (hashed), the
    search's settings (without the check's ``check_*``) and the column's (height, criterion, ...)."""
    search = tuple((f.name, getattr(settings, f.name)) for f in dataclasses.fields(settings)
                   if not f.name.startswith("check_"))
    up = None if vertical is None else (digest(vertical.acc), float(vertical.dt))
    return (digest(excitation.acc), float(excitation.dt), up, search, column)


def remembered(k, search):
    """``search()``'s result ``(RequiredWidth, widths run)``, or a copy of the one kept for ``k``."""
    return _kept.remembered(k, search)
