"""What a worker keeps between the passes of a pair's direction (``pipeline.batch.passes``), and
between the directions of a pair.

A direction searched in a first pass is computed again, with its check, in a later one; its pulse
fit and exact minimum slenderness are deterministic functions of the record's samples and the
options, and so is the search (:mod:`rocking.searches`).  A worker keeps the last few of each,
keyed by a hash of every input (samples included), and answers the second pass with copies: the
same rows to the last bit, without the repeated work.  It also keeps the last pairs it read: a
pair's 38 directions are 38 tasks reading the same two files (kept while their size, time and
inode stay the same).
"""
from __future__ import annotations

from rocking.searches import Kept, digest

#: results kept per kind in a worker: a direction comes back for its next pass once its pair's
#: other directions of the pass are in (pipeline.batch.passes), so this covers the few pairs a
#: pool's workers go between, of 38 directions and two heights (under ``--limit`` two searches a
#: column, the overturning design's and the level's; about 20 kB each)
KEPT = 512
#: pairs of records kept (a few hundred kB each): the pairs a pool's worker goes between
PAIRS_KEPT = 4

_kept: dict[str, Kept] = {}


def on() -> None:
    """Keep results in this process from now on (the search's too)."""
    from rocking import searches

    searches.keep(KEPT)
    _kept.setdefault("fit", Kept(KEPT))
    _kept.setdefault("slenderness", Kept(KEPT))
    _kept.setdefault("pair", Kept(PAIRS_KEPT))


def off() -> None:
    """Keep nothing from now on; what was kept is dropped."""
    from rocking import searches

    searches.keep(0)
    _kept.clear()


def samples_key(record) -> tuple:
    """A record's samples, time axis and name, as a key."""
    return digest(record.acc), float(record.dt), float(record.t_start), str(record.name)


def file_key(path) -> tuple:
    """A file as a key: its path, and the size, modification time and inode it has now."""
    import os

    st = os.stat(path)
    return str(path), st.st_size, st.st_mtime_ns, st.st_ino, st.st_dev


def remembered(kind: str, key, compute):
    """``compute()``, or a copy of the result kept for ``key`` (kept only after :func:`on`)."""
    kept = _kept.get(kind)
    return compute() if kept is None else kept.remembered(key, compute)
