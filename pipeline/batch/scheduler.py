"""``pipeline run --dask ADDRESS``: the scheduler checked before any work, and a cluster lost while
the batch runs noticed within a bounded time.

A dask client given the address of something else hangs or fails in odd ways: an HTTP server (the
dashboard's port given by mistake) never answers its handshake, and a server that greets first
(SSH, SMTP) has its greeting read as the length of a message (numpy: "Unable to allocate 2.82
EiB").  A dask scheduler greets every connection at once with a small message of its own (its
handshake: a length of 8 bytes, then a few hundred bytes naming its compression and pickle
protocol), so :func:`check_address` connects itself, reads that greeting within
:data:`PROBE_S` seconds and says in one line what answered instead.  A refused connection fails at
once.

While the batch runs, :func:`next_result` waits for the next finished task and raises
:class:`ClusterLost` when the client has given up on its scheduler (it tries to reconnect for 20 s,
:data:`CONNECT_TIMEOUT`), or when a local cluster has had no worker for :data:`NO_WORKERS_S`
seconds; the runner then writes its reports with the records not computed listed in
``failures.csv`` (stage ``cluster``), and the same command run again finishes the batch.
"""
from __future__ import annotations

import socket
import struct
import time

from ..values import ArgumentError

#: seconds to connect to the scheduler and to read its greeting
PROBE_S = 5.0
#: the client's timeout to connect (and to reconnect, after which it closes)
CONNECT_TIMEOUT = "20s"
#: a local cluster with no worker for this long is lost (nothing will join it)
NO_WORKERS_S = 60.0
#: a greeting larger than this is not a dask handshake (a few hundred bytes)
MAX_GREETING = 1 << 20


class ClusterLost(RuntimeError):
    """The dask scheduler (or every worker of a local cluster) is gone; the batch cannot go on."""


def _host_port(address: str):
    """``(scheme, host, port)`` of a scheduler address (``tcp://host:8786``, ``host:8786``)."""
    scheme, sep, loc = address.partition("://")
    if not sep:
        scheme, loc = "tcp", address
    host, sep, port = loc.rpartition(":")
    host = host.strip("[]")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ArgumentError(f"--dask {address!r}: expected a scheduler address such as "
                            "tcp://HOST:8786, or 'local'")
    return scheme.lower(), host, int(port)


def check_address(address: str) -> None:
    """Raise :class:`ArgumentError` (one line) unless a dask scheduler answers at ``address``:
    nothing listens there, the host is unknown, or what answers is no dask scheduler (see the
    module's docstring).  Within :data:`PROBE_S` seconds twice at most."""
    scheme, host, port = _host_port(address)
    where = f"--dask {address}"
    try:
        sock = socket.create_connection((host, port), timeout=PROBE_S)
    except socket.gaierror as exc:
        raise ArgumentError(f"{where}: unknown host {host!r} ({exc.strerror or exc})") from None
    except ConnectionRefusedError:
        raise ArgumentError(f"{where}: nothing listens there (connection refused); start the "
                            f"scheduler with `dask scheduler`, or use --dask local") from None
    except (socket.timeout, TimeoutError):
        raise ArgumentError(f"{where}: no answer within {PROBE_S:g} s") from None
    except OSError as exc:
        raise ArgumentError(f"{where}: cannot connect: {exc.strerror or exc}") from None
    with sock:
        if scheme != "tcp":  # tls:// and others: their greeting is not read here
            return
        _read_greeting(sock, where)


def _read_greeting(sock, where: str) -> None:
    not_dask = (f"{where}: what answers there is not a dask scheduler"
                " (give the scheduler's address, tcp://HOST:8786 by default, not its dashboard's)")
    head = _recv(sock, 8)
    if head is None:
        raise ArgumentError(f"{not_dask}: it sent nothing within {PROBE_S:g} s "
                            "(a web server waits for a request)")
    (size,) = struct.unpack("<Q", head)
    if not 0 < size <= MAX_GREETING:
        raise ArgumentError(f"{not_dask}: it greeted with {head!r}")
    body = _recv(sock, size)
    if body is None or b"compression" not in body:
        raise ArgumentError(f"{not_dask}: its greeting is no dask handshake")


def _recv(sock, n: int) -> bytes | None:
    """``n`` bytes from ``sock`` within :data:`PROBE_S` seconds, or None."""
    deadline = time.monotonic() + PROBE_S
    out = b""
    while len(out) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        sock.settimeout(left)
        try:
            chunk = sock.recv(n - len(out))
        except (socket.timeout, TimeoutError, OSError):
            return None
        if not chunk:
            return None
        out += chunk
    return out


def lost(client) -> bool:
    """Whether ``client`` has given up on its scheduler."""
    return getattr(client, "status", "running") in ("closing", "closed")


class Watch:
    """Waits for a cluster's results, noticing when it is gone (:func:`next_result`)."""

    def __init__(self, client, address: str, local: bool):
        self.client, self.address, self.local = client, address, local
        self.idle_since = time.monotonic()  # no result since
        self.no_workers_since = None
        self.asked = 0.0  # when the workers were last counted

    def lost(self) -> ClusterLost:
        where = "the local cluster" if self.local else f"the dask scheduler at {self.address}"
        return ClusterLost(f"{where} was lost")

    def check(self) -> None:
        """Raise :class:`ClusterLost` if the cluster is gone."""
        if lost(self.client):
            raise self.lost()
        now = time.monotonic()
        if not self.local or now - self.idle_since < 5.0 or now - self.asked < 5.0:
            return
        self.asked = now  # only when nothing came for a while: counting asks the scheduler
        try:
            n = len(self.client.scheduler_info().get("workers", {}))
        except Exception:
            n = 0
        if n:
            self.no_workers_since = None
        elif self.no_workers_since is None:
            self.no_workers_since = now
        elif now - self.no_workers_since > NO_WORKERS_S:
            raise ClusterLost(f"the local cluster has had no worker for {NO_WORKERS_S:g} s")


def next_result(pending, watch: Watch, interrupts_check=None):
    """The next finished future of ``pending`` (a ``dask.distributed.as_completed``), or
    :class:`ClusterLost`."""
    while not pending.has_ready():
        watch.check()
        if interrupts_check is not None:
            interrupts_check()
        time.sleep(0.05)
    watch.idle_since = time.monotonic()
    return next(pending)
