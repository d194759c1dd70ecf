"""A ground-motion record: uniform samples of ground acceleration, read piecewise-linearly."""
from __future__ import annotations

import math

import numpy as np

from .units import G


class Record:
    """Uniformly sampled ground acceleration.

    Between samples the acceleration is taken as linear (how every solver reads it).

    Parameters
    ----------
    acc : array_like
        Ground acceleration samples of one component (one-dimensional; a 2-D array is refused),
        in m/s^2 unless ``units`` says otherwise.
    dt : float
        Sampling interval, s.
    name : str, optional
        Identifier used in reports.
    t_start : float, optional
        Time of the first sample, s (default 0).
    metadata : dict, optional
        Header information (station, component, units as stated, source file, ...).
    units : str, optional
        Units of ``acc``: ``"g"``, ``"m/s2"``, ``"cm/s2"`` (``"gal"``), ``"mm/s2"``, ``"nm/s2"``;
        the samples are converted to m/s^2 and ``metadata["units"]`` says what was given.  With
        ``units`` given, a peak no accelerogram has in those units (outside 1e-5 g to 10 g) gets
        the readers' message as a :class:`pulses.errors.UnitsWarning`, naming the units that
        would make it plausible.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> rec = pulses.Record(np.array([0.0, 0.874, -0.5, 0.0]), 0.01, units="g")
    >>> round(rec.pga, 3), rec.metadata["units"]
    (8.574, 'g')
    """

    kind = 0
    shape = "record"

    def __init__(self, acc, dt, name=None, t_start=0.0, metadata=None, *, units=None):
        acc = np.asarray(acc, dtype=float)
        if acc.ndim != 1:  # (2, N) would be two components end to end, (N, 2) interleaved
            raise ValueError(f"record {name!r}: acc must be one-dimensional, the samples of one "
                             f"component; got an array of shape {acc.shape}: for two components "
                             "make a Record of each (acc[:, k] or acc[k]; pulses.component "
                             "combines two), for a column of one (N, 1) use acc.ravel()")
        acc = np.ascontiguousarray(acc)
        raw_peak = float(np.max(np.abs(acc))) if acc.size else 0.0
        if units is not None:
            from .units import canonical_units, unit_factor

            acc = acc * unit_factor(units)
            metadata = {**(metadata or {}), "units": canonical_units(units)}
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
        if units is not None and raw_peak > 0.0:
            from .units import implausible_peak

            problem = implausible_peak(raw_peak, canonical_units(units), "given")
            if problem:
                import warnings

                from .errors import UnitsWarning

                warnings.warn(f"record {self.name!r}: {problem}", UnitsWarning, stacklevel=2)

    # -- obspy in and out ----------------------------------------------------------------
    @classmethod
    def from_trace(cls, trace, units=None, *, name=None) -> "Record":
        """A record from an :class:`obspy.Trace` (read, processed, or made in memory).

        The trace is interpreted as the file it was read from is (SAC ``idep``, K-NET's scale
        factor, the AT2 plugin's ``stats.at2`` header: data in g), then checked as
        :func:`pulses.read_record` checks a file: units are never guessed, a peak implausible for
        them is refused.  A trace made by :meth:`to_trace` gives back that record.

        Parameters
        ----------
        trace : obspy.Trace
            Uniformly sampled ground acceleration.
        units : str, optional
            Units of ``trace.data`` where ``trace.stats`` does not state them (MiniSEED, a trace
            made in memory), or to override SAC's standard nm/s^2.
        name : str, optional
            The record's name (default: the file the AT2 plugin read, else the trace's id).

        Raises
        ------
        pulses.RecordError
            Units neither stated nor given, a velocity record, an implausible peak.

        Examples
        --------
        >>> import numpy as np, obspy, pulses
        >>> tr = obspy.Trace(np.sin(np.arange(50) / 5.0) * 0.874, header={"delta": 0.01})
        >>> round(pulses.Record.from_trace(tr, units="g").pga / pulses.G, 3)
        0.874
        """
        from .formats.traces import trace_fields  # the formats load when a trace is first converted

        return cls(**trace_fields(trace, units, name=name))

    def to_trace(self):
        """This record as an :class:`obspy.Trace`: ``data`` in m/s^2, ``delta`` = ``dt``,
        ``starttime`` 1970-01-01 plus ``t_start``, station and channel from the metadata; the
        name, start and metadata kept in ``stats.pulses``, so that ``Record.from_trace`` gives the
        record back (after obspy's processing: with the trace's samples, step and start).

        Examples
        --------
        >>> import numpy as np, pulses
        >>> rec = pulses.Record(np.array([0.0, 1.0, -2.0, 0.5]), 0.01, name="demo")
        >>> tr = rec.to_trace()
        >>> tr.stats.delta, list(tr.data) == list(rec.acc), pulses.Record.from_trace(tr).name
        (0.01, True, 'demo')
        """
        from .formats.traces import record_trace

        return record_trace(self)

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
