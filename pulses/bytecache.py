"""A least-recently-used cache bounded by the bytes it holds, not by its number of entries.

The filters of the wavelet transforms grow with the scale, and the scales with the sampling rate:
one entry is a few kB for a 200 Hz record and several MB at 10 kHz, so a cache of a fixed number of
entries that is small for the one holds gigabytes for the other.  Here the results' arrays are
counted (``nbytes``, also inside tuples) and the least recently used entries are dropped once the
total exceeds the budget; a result larger than the whole budget is returned and not kept.
"""
from __future__ import annotations

import collections
import functools
import threading

import numpy as np


def nbytes(value) -> int:
    """Bytes held by ``value``'s arrays (recursively in tuples and lists); 64 for anything else."""
    if isinstance(value, np.ndarray):
        return int(value.nbytes)
    if isinstance(value, (tuple, list)):
        return sum(nbytes(v) for v in value)
    return 64


def byte_lru(max_bytes: int):
    """Decorator: memoise a function of hashable arguments within ``max_bytes`` of results.

    The wrapped function has ``cache_clear()``, ``cache_bytes()`` (bytes held now), ``max_bytes``
    and ``__wrapped__`` (the function itself, uncached)."""

    def decorate(func):
        entries: collections.OrderedDict = collections.OrderedDict()
        held = [0]
        lock = threading.Lock()

        @functools.wraps(func)
        def wrapper(*args):
            with lock:
                if args in entries:
                    entries.move_to_end(args)
                    return entries[args][0]
            value = func(*args)
            size = nbytes(value)
            if size > max_bytes:
                return value
            with lock:
                if args not in entries:
                    entries[args] = (value, size)
                    held[0] += size
                while held[0] > max_bytes:
                    _, (_, dropped) = entries.popitem(last=False)
                    held[0] -= dropped
            return value

        def cache_clear():
            with lock:
                entries.clear()
                held[0] = 0

        wrapper.cache_clear = cache_clear
        wrapper.cache_bytes = lambda: held[0]
        wrapper.max_bytes = max_bytes
        return wrapper

    return decorate
