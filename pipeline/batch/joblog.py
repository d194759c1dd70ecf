"""``pipeline run --log FILE``: one JSON line per record, for watching a long batch.

Each line is an object with ``record`` (its id), ``status`` (``ok``, ``reused`` from an earlier run,
or ``failed``), ``stage`` (where it failed, else null), ``seconds`` (wall time of the record on its
worker, s; 0 when reused), ``model`` (the governing pulse shape of the record's first row, null
when none), ``worker`` (``host:pid`` of the process that computed it), ``cpu_seconds`` (CPU time of
that process on the record, s; 0 when reused) and ``stages`` (wall time of each stage of the
record, s, as ``pipeline.batch.record.process_record`` measures them; for benchmarks).  Lines are appended and
flushed one by one, so ``tail -f`` shows the batch as it goes and a resumed run adds to the log.
"""
from __future__ import annotations

import json
import os
import socket

#: the result key under which :func:`pipeline.batch.runner.work` reports where and how long a record ran
WORKER, SECONDS, CPU = "worker", "wall_seconds", "cpu_seconds"


def here() -> str:
    """``host:pid`` of this process."""
    return f"{socket.gethostname()}:{os.getpid()}"


class JobLog:
    """An open ``--log`` file (``path`` None: nothing is written)."""

    def __init__(self, path):
        self.fh = None
        if path is not None:
            self.fh = open(path, "a", encoding="utf-8")

    def record(self, res: dict | None, record_id: str, *, reused: bool = False) -> None:
        if self.fh is None:
            return
        if reused:
            entry = {"record": record_id, "status": "reused", "stage": None, "seconds": 0.0,
                     "model": None, "worker": None, "cpu_seconds": 0.0, "stages": {}}
        else:
            fail = res.get("failure")
            rows = res.get("rows") or []
            entry = {"record": record_id, "status": "failed" if fail else "ok",
                     "stage": fail["stage"] if fail else None,
                     "seconds": round(float(res.get(SECONDS) or 0.0), 4),
                     "model": rows[0].get("pulse_shape") if rows else None,
                     "worker": res.get(WORKER), "cpu_seconds": round(float(res.get(CPU) or 0.0), 4),
                     "stages": {k: round(float(v), 4) for k, v in (res.get("seconds") or {}).items()}}
        self.fh.write(json.dumps(entry) + "\n")
        self.fh.flush()

    def close(self) -> None:
        if self.fh is not None:
            self.fh.close()
            self.fh = None
