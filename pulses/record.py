"""A ground-motion record: uniform samples of ground acceleration, read piecewise-linearly."""
from __future__ import annotations

import math

import numpy as np

G = 9.81  #: standard gravity used throughout the package, m/s^2


class Record:
    """Uniformly sampled ground acceleration.

    Between samples the acceleration is taken as linear (how every solver reads it).

    Parameters
    ----------
    acc : array_like
        Ground acceleration samples, m/s^2.
    dt : float
        Sampling interval, s.
    name : str, optional
        Identifier used in reports.
    t_start : float, optional
        Time of the first sample, s (default 0).
    metadata : dict, optional
        Header information (station, component, units as stated, source file, ...).

    Examples
    --------
    >>> import numpy as np
    >>> import pulses
    >>> t = np.arange(0, 10, 0.01)
    >>> rec = pulses.Record(0.3 * pulses.G * np.sin(2 * np.pi * t), dt=0.01, name="sine")
    >>> rec
    Record(name='sine', npts=1000, dt=0.01 s, PGA=0.3 g)
    >>> rec.npts, rec.duration, round(rec.pga / pulses.G, 2)
    (1000, 9.99, 0.3)
    >>> half = rec.scaled(0.5)
    >>> round(half.pga / pulses.G, 2)
    0.15
    """

    kind = 0
    shape = "record"

    def __init__(self, acc, dt, name=None, t_start=0.0, metadata=None):
        acc = np.ascontiguousarray(np.asarray(acc, dtype=float).ravel())
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"record {name!r}: time step dt must be positive and finite, got {dt!r}")
        if acc.size < 2:
            raise ValueError(f"record {name!r}: needs at least 2 samples, got {acc.size}")
        if not np.all(np.isfinite(acc)):
            bad = int(np.count_nonzero(~np.isfinite(acc)))
            raise ValueError(f"record {name!r}: {bad} sample(s) are NaN or infinite")
        self.acc = acc
        self.dt = dt
        self.name = name if name is not None else "record"
        self.t_start = float(t_start)
        self.metadata = dict(metadata or {})

    # -- basic facts -------------------------------------------------------------------
    @property
    def npts(self) -> int:
        return int(self.acc.size)

    @property
    def duration(self) -> float:
        """Time from first to last sample, s."""
        return (self.npts - 1) * self.dt

    @property
    def time(self) -> np.ndarray:
        """Sample times, s."""
        return self.t_start + self.dt * np.arange(self.npts)

    @property
    def support(self) -> tuple[float, float]:
        return (self.t_start, self.t_start + self.duration)

    @property
    def pga(self) -> float:
        """Peak absolute ground acceleration, m/s^2."""
        return float(np.max(np.abs(self.acc)))

    def __call__(self, t):
        """Ground acceleration (m/s^2) at time(s) ``t``, linear between samples, zero outside."""
        return np.interp(np.asarray(t, dtype=float), self.time, self.acc, left=0.0, right=0.0)

    def scaled(self, factor: float) -> "Record":
        """The same record with every sample multiplied by ``factor``."""
        return Record(self.acc * factor, self.dt, self.name, self.t_start, self.metadata)

    def __len__(self):
        return self.npts

    def __repr__(self):
        return (f"Record(name={self.name!r}, npts={self.npts}, dt={self.dt:g} s, "
                f"PGA={self.pga / G:.4g} g)")
