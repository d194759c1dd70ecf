"""Is a record pulse-like?  Shahi & Baker's (2014) velocity-pulse classification.

A port of the authors' own MATLAB code (``shreyshahi/PulseClassification``, MIT licence:
``classification_algo.m``, ``analyze_record.m``, ``find_Ipulse.m``, ``find_Tp.m``), step by step:

1. Velocity in cm/s: cumulative sum of the acceleration times ``dt`` (no baseline correction).
2. The continuous wavelet transform with the Daubechies-4 wavelet (:func:`pulses.db4.db4_cwt`, MATLAB's
   legacy ``cwt(x, scales, 'db4')``) of both components at 51 coarse scales: pseudo-periods
   ``Tp = 1.4 a dt`` from 0.25 s to 15 s (:func:`coarse_scales`).
3. Five candidates.  The strongest orientation at a point of the (scale, time) map is exact:
   the transform is linear, so the coefficient of the component at ``theta`` is
   ``C1 cos(theta) + C2 sin(theta)``, largest in magnitude at ``theta = atan(C2 / C1)``, where it
   is ``sqrt(C1^2 + C2^2)``.  Each candidate is the global maximum of ``C1^2 + C2^2``; the map is
   then cleared within ``0.4 a`` samples of its time and the next maximum taken.
4. Each candidate, on the component in its orientation: the scale refined to every integer
   between the coarse neighbours (largest ``|C|`` at the candidate's time); the pulse is the sum
   of 10 wavelets at that scale, each the largest ``|C|`` of the running residual within
   ``ceil(0.4 a)`` samples of the first one, contributing ``psi C / sqrt(a)``.
5. ``PGV ratio`` (residual's peak over the record's), ``energy ratio`` (residual's over the
   record's, measured on the level-1 approximation coefficients of the discrete db4 transform
   with symmetric extension, as MATLAB's one-output ``dwt(x, 'db4')``),
   ``PC = 0.63 PGV ratio + 0.777 energy ratio`` and the pulse indicator ``PI`` (a quadratic in
   the centred PC and PGV in cm/s).  Pulse-like: ``PI > 0`` and not late, i.e. when the pulse
   has reached 5 % of its energy the record has not yet reached 17 % of its own.
6. The record is pulse-like if any candidate is; its Tp is the first such candidate's.

Where this differs from the reference: the transform at the refined scales is evaluated only
at the times the algorithm reads (the same numbers, less work); ties in a maximum go to the
first index rather than producing MATLAB's vectors.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pywt

from .db4 import FC, WAVELET, WindowedTransform, cwt_at, cwt_point, cwt_rows, unit_wavelet
from .errors import RecordError
from .record import Record

#: range of pseudo-periods of the coarse scales, s, and the number of steps between them
TP_MIN, TP_MAX, N_STEPS = 0.25, 15.0, 50
#: candidates taken from the (scale, time) map
N_CANDIDATES = 5
#: wavelets summed into one pulse
N_WAVELETS = 10
#: half-width, in units of the scale, of the window around a pulse (candidates and wavelets)
WINDOW = 10.0 / 25.0
#: principal component PC = PC_PGV * PGV ratio + PC_ENERGY * energy ratio
PC_PGV, PC_ENERGY = 0.63, 0.777
#: centring of PC and of PGV (cm/s) in the indicator
PC_MEAN, PC_SCALE = 1.208421, 0.2462717
PGV_MEAN, PGV_SCALE = 11.58861, 18.88015
#: PI = c0 + cPP P^2 + cVV V^2 + cP P + cV V + cPV P V
PI_COEFFICIENTS = (-7.817, -0.5679, -0.1516, -3.0253, -1.7396, -2.7156)
#: a velocity is one-sided when its peak one way is at least this many times its peak the other
ONE_SIDED_RATIO = 4.0
#: late pulse: when the pulse has reached PULSE_PERCENT of its energy the record has reached
#: RECORD_PERCENT of its own or more
LATE_PULSE_PERCENT, LATE_RECORD_PERCENT = 5.0, 17.0
#: m/s to cm/s: the indicator's constants are in cm/s
CM_PER_M = 100.0


def coarse_scales(dt: float) -> np.ndarray:
    """The 51 coarse scales (samples) for time step ``dt`` (s): ``Tp`` from 0.25 s to about 15 s.

    ``scaleMin = floor(TpMin / 1.4 / dt)``, ``step = ceil((TpMax / 1.4 / dt - scaleMin) / 50)``.
    """
    lo = math.floor(TP_MIN * FC / dt)
    step = math.ceil((TP_MAX * FC / dt - lo) / N_STEPS)
    return lo + step * np.arange(N_STEPS + 1)


def tp_of_scale(scale: float, dt: float) -> float:
    """Pseudo-period (s) of the db4 wavelet at ``scale`` samples of ``dt`` s."""
    return scale * dt / FC


def dwt_energy(v) -> float:
    """Energy measure of ``analyze_record.m``: the sum of squares of MATLAB's one-output
    ``dwt(v, 'db4')`` (level-1 approximation coefficients, symmetric half-point extension)."""
    approx = pywt.dwt(np.asarray(v, dtype=float), WAVELET, mode="symmetric")[0]
    return float(np.einsum("i,i->", approx, approx))


def integral_energy(v) -> float:
    """The simpler energy measure: sum of ``v^2`` (proportional to the integral of v^2 dt)."""
    v = np.asarray(v, dtype=float)
    return float(np.einsum("i,i->", v, v))


def pulse_indicator(pgv_ratio: float, energy_ratio: float, pgv_cm_s: float) -> float:
    """Shahi & Baker's pulse indicator PI (positive: pulse-like, unless late).

    Parameters
    ----------
    pgv_ratio, energy_ratio : float
        Residual's peak velocity and energy over the record's.
    pgv_cm_s : float
        Peak velocity of the record in the pulse's orientation, cm/s.
    """
    pc = PC_PGV * pgv_ratio + PC_ENERGY * energy_ratio
    p = (pc - PC_MEAN) / PC_SCALE
    v = (pgv_cm_s - PGV_MEAN) / PGV_SCALE
    c0, cpp, cvv, cp, cv, cpv = PI_COEFFICIENTS
    return c0 + cpp * p * p + cvv * v * v + cp * p + cv * v + cpv * p * v


# -- results ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class PulseCandidate:
    """One of the five candidate pulses.

    Attributes
    ----------
    is_pulse : bool
        ``indicator > 0`` and not late.
    indicator : float
        Pulse indicator PI.
    tp : float
        Pseudo-period of the pulse's wavelets, s.
    scale : int
        Refined scale, samples.
    pgv : float
        Peak velocity of the record in the candidate's orientation, m/s.
    pgv_ratio, energy_ratio : float
        Residual over record.
    late : bool
        The record reached 17 % of its energy before the pulse reached 5 % of its own.
    arrival : float
        Time (s, on the record's time axis) of the last sample at which the pulse has reached
        at most 5 % of its energy: the instant the late rule looks at.
    orientation : float
        Degrees from the first component towards the second, in (-90, 90].
    time : float
        Time (s) of the candidate's maximum in the (scale, time) map.
    velocity : numpy.ndarray
        Record's velocity in the candidate's orientation, m/s.
    pulse : numpy.ndarray
        Extracted pulse, m/s, on the record's samples.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 20.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.5, 4.0)(t), 0.01)
    >>> cand = pulses.classify_pulse(rec).candidates[0]
    >>> cand.is_pulse, cand.velocity.shape == cand.residual.shape
    (True, True)
    """

    is_pulse: bool
    indicator: float
    tp: float
    scale: int
    pgv: float
    pgv_ratio: float
    energy_ratio: float
    late: bool
    arrival: float
    orientation: float
    time: float
    velocity: np.ndarray = field(repr=False, compare=False)
    pulse: np.ndarray = field(repr=False, compare=False)

    @property
    def residual(self) -> np.ndarray:
        """Record's velocity minus the pulse, m/s."""
        return self.velocity - self.pulse


@dataclass(frozen=True, repr=False)
class PulseClassification:
    """Result of :func:`classify_pulse`.

    The scalar fields are those of the chosen candidate: the first pulse-like one (the
    reference code's Tp), or where none is, the one with the largest indicator (how close the
    record came).

    Attributes
    ----------
    name : str
        Record name (``first+second`` for a pair).
    is_pulse : bool
        Pulse-like: some candidate is.
    indicator, tp, pgv, pgv_ratio, energy_ratio, late, arrival, orientation
        Of the chosen candidate (see :class:`PulseCandidate`; ``tp`` in s, ``pgv`` in m/s,
        ``orientation`` in degrees from the first component towards the second, 0 for one
        component).
    azimuth : float or None
        The pulse direction, degrees clockwise from north in [0, 180) (an axis: the pulse has
        either sign), where both components' azimuths are known (one: its own azimuth).
    candidates : tuple of PulseCandidate
        The five candidates, strongest wavelet coefficient first.
    chosen : int
        Index of the chosen candidate.
    t_start, dt : float
        Time of the first sample and time step, s.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 20.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.5, 4.0)(t), 0.01)
    >>> c = pulses.classify_pulse(rec)
    >>> c.pulse.shape == rec.acc.shape, c.candidate is c.candidates[c.chosen]
    (True, True)
    """

    name: str
    azimuth: float | None
    candidates: tuple = field(repr=False)
    chosen: int = 0
    t_start: float = field(default=0.0, repr=False)
    dt: float = field(default=0.0, repr=False)

    @property
    def candidate(self) -> PulseCandidate:
        return self.candidates[self.chosen]

    def __repr__(self):
        return (f"PulseClassification(name={self.name!r}, is_pulse={self.is_pulse}, "
                f"indicator={self.indicator:.4g}, tp={self.tp:.4g} s, pgv={self.pgv:.4g} m/s, "
                f"orientation={self.orientation:.4g} deg, azimuth={self.azimuth})")

    # the chosen candidate's values (it is pulse-like exactly when some candidate is)
    is_pulse = property(lambda self: self.candidate.is_pulse)
    indicator = property(lambda self: self.candidate.indicator)
    tp = property(lambda self: self.candidate.tp)
    pgv = property(lambda self: self.candidate.pgv)
    pgv_ratio = property(lambda self: self.candidate.pgv_ratio)
    energy_ratio = property(lambda self: self.candidate.energy_ratio)
    late = property(lambda self: self.candidate.late)
    arrival = property(lambda self: self.candidate.arrival)
    orientation = property(lambda self: self.candidate.orientation)

    @property
    def pulse(self) -> np.ndarray:
        """Extracted velocity pulse, m/s, on the record's samples."""
        return self.candidate.pulse

    @property
    def velocity(self) -> np.ndarray:
        """Record's velocity in the pulse's orientation, m/s."""
        return self.candidate.velocity

    @property
    def residual(self) -> np.ndarray:
        return self.candidate.residual

    @property
    def time(self) -> np.ndarray:
        """Sample times, s."""
        return self.t_start + self.dt * np.arange(self.pulse.size)

    @property
    def reason(self) -> str:
        """The verdict in one sentence: which of Shahi & Baker's tests decided it, with the numbers;
        and, for a record not pulse-like whose velocity is one-sided (peak one way at least
        :data:`ONE_SIDED_RATIO` times the other), that their wavelets are two-sided, so such a
        pulse may be missed."""
        if self.is_pulse:
            text = (f"pulse-like: indicator PI = {self.indicator:.1f} > 0 and the pulse arrives early "
                    f"enough")
        elif self.late:
            text = ("not pulse-like: the pulse arrives late (the record had reached "
                    f"{LATE_RECORD_PERCENT:g} % of its energy before the pulse reached {LATE_PULSE_PERCENT:g} % "
                    "of its own)")
        else:
            text = (f"not pulse-like: indicator PI = {self.indicator:.1f} <= 0 (without the extracted "
                    f"pulse the record keeps {100 * self.pgv_ratio:.0f} % of its peak velocity and "
                    f"{100 * self.energy_ratio:.0f} % of its energy; the indicator's PGV, in the "
                    f"pulse's direction and without baseline correction, {self.pgv:.3g} m/s)")
        v = self.velocity
        big, small = (max(v.max(), -v.min()), min(v.max(), -v.min())) if v.size else (0.0, 0.0)
        if not self.is_pulse and big > 0 and big >= ONE_SIDED_RATIO * max(small, 0.0):
            text += ("; the velocity is one-sided, which Shahi & Baker's two-sided wavelets fit "
                     "poorly: a one-sided pulse may be judged not pulse-like")
        return text

    def to_frame(self):
        """One row per candidate (:class:`pandas.DataFrame`), strongest first, ``chosen`` marking
        the one whose values the classification reports (``tp`` in s, ``pgv`` in m/s)."""
        import pandas as pd

        from .export import fields_dict

        rows = [{"name": self.name, "candidate": i, "chosen": i == self.chosen,
                 **fields_dict(c)} for i, c in enumerate(self.candidates)]
        return pd.DataFrame(rows)

    def as_dict(self) -> dict:
        """The scalar fields (plain Python types).

        Examples
        --------
        >>> import numpy as np, pulses
        >>> t = np.arange(0.0, 20.0, 0.01)
        >>> rec = pulses.Record(pulses.make_pulse("sine", 4.0, 1.5, 5.0)(t), 0.01)
        >>> pulses.classify_pulse(rec).as_dict()["is_pulse"]
        True
        """
        return {"name": self.name, "is_pulse": bool(self.is_pulse), "indicator": float(self.indicator),
                "tp": float(self.tp), "pgv": float(self.pgv), "pgv_ratio": float(self.pgv_ratio),
                "energy_ratio": float(self.energy_ratio), "late": bool(self.late),
                "arrival": float(self.arrival), "orientation": float(self.orientation),
                "azimuth": None if self.azimuth is None else float(self.azimuth)}


# -- the classification ----------------------------------------------------------------------

def _analyze(signal: np.ndarray, dt: float, col: int, row: int, scales: np.ndarray, energy) -> dict:
    """``analyze_record.m`` for one candidate; ``signal`` in cm/s.

    The transform of the running residual over the search window is that of the record minus
    those of the wavelets taken so far (the transform is linear); a wavelet wholly inside the
    record is the same samples shifted, so its transform is one kernel shifted, computed once.
    Wavelets cut by the record's ends are transformed as they are."""
    n = signal.size
    refined = np.arange(scales[max(0, row - 1)], scales[min(scales.size - 1, row + 1)] + 1)
    z = np.abs(cwt_point(signal, refined, col))
    scale = int(refined[int(np.argmax(z))])
    half = math.ceil(scale * WINDOW)
    # every window searched lies within 2 half of the candidate's time: one transform covers all
    reach_lo, reach_hi = max(0, col - 2 * half), min(n, col + 2 * half + 1)
    around = cwt_at(signal, scale, reach_lo, reach_hi)
    lo, hi = max(0, col - half), min(n, col + half + 1)
    k = int(np.argmax(np.abs(around[lo - reach_lo:hi - reach_lo])))
    at0 = lo + k
    coef = around[at0 - reach_lo]
    # later wavelets are sought within `half` samples of the first one
    lo, hi = max(0, at0 - half), min(n, at0 + half + 1)
    window = around[lo - reach_lo:hi - reach_lo].copy()
    first, shape = unit_wavelet(scale)
    centre = -first
    span = 2 * half
    kernel = None  # transform of the unit wavelet at lags -span..span, when first needed
    cut = None  # transform over the window of wavelets cut by the record's ends, when needed
    pulse = np.zeros(n)
    at = at0
    for i in range(N_WAVELETS):
        if i:
            k = int(np.argmax(np.abs(window)))
            at, coef = lo + k, window[k]
        amp = coef / math.sqrt(scale)
        start = at - centre
        a, b = max(start, 0), min(start + shape.size, n)
        pulse[a:b] += amp * shape[a - start:b - start]
        if i == N_WAVELETS - 1:
            break
        if a == start and b == start + shape.size:  # wholly inside: the shifted kernel
            if kernel is None:
                kernel = WindowedTransform(scale, centre, centre + 2 * span + 1, span, span + shape.size)(shape, span)
            window -= amp * kernel[lo - at + span:hi - at + span]
        else:  # cut by the record's ends: the transform of the samples kept
            if cut is None:  # inputs: every sample a wavelet centred in the window can cover
                cut = WindowedTransform(scale, lo, hi, max(0, lo - centre), min(n, hi - 1 - centre + shape.size))
            window -= cut(amp * shape[a - start:b - start], a)
    resid = signal - pulse
    e_signal = np.cumsum(signal * signal)
    e_pulse = np.cumsum(pulse * pulse)
    reached = np.flatnonzero(e_pulse <= LATE_PULSE_PERCENT / 100.0 * e_pulse[-1])
    if reached.size:
        idx = int(reached[-1])
        late = bool(e_signal[idx] >= LATE_RECORD_PERCENT / 100.0 * e_signal[-1])
    else:  # the pulse starts on the first sample
        idx, late = 0, False
    pgv = float(np.max(np.abs(signal)))
    pgv_ratio = float(np.max(np.abs(resid))) / pgv
    energy_ratio = energy(resid) / energy(signal)
    indicator = pulse_indicator(pgv_ratio, energy_ratio, pgv)
    return dict(is_pulse=bool(indicator > 0 and not late), indicator=float(indicator),
                tp=tp_of_scale(scale, dt), scale=scale, pgv=pgv / CM_PER_M, pgv_ratio=pgv_ratio,
                energy_ratio=float(energy_ratio), late=late, arrival_index=idx,
                pulse=pulse / CM_PER_M, velocity=signal / CM_PER_M)


class _StrongestMap:
    """The (scale, time) map of ``C1^2 + C2^2`` as the candidates need it, in memory proportional
    to the record's length (not times the 51 scales): for each time, the largest value over the
    scales (``peak``), the first scale where it is reached (``row``) and the coefficients there;
    and the coefficients at the first scale, which a cleared time returns to.

    :meth:`add` takes the rows in any order; :meth:`strongest` and :meth:`clear` then give what
    the whole map would (:func:`numpy.argmax`'s first index on ties), value for value."""

    def __init__(self, n: int, n_rows: int, pair: bool):
        self.peak = np.zeros(n)
        self.row = np.full(n, n_rows, dtype=np.intp)  # none yet: every row comes first
        shape = (2, n) if pair else (1, n)
        self.coef = np.zeros(shape)
        self.coef0 = np.zeros(shape)

    def add(self, i: int, row: np.ndarray) -> None:
        """Row ``i`` of the transform (shape (n,), or (2, n) for a pair)."""
        row = row.reshape(self.coef.shape)
        power = row[0] * row[0]
        if row.shape[0] == 2:
            power += row[1] * row[1]
        better = power > self.peak
        better |= (power == self.peak) & (self.row > i)
        np.copyto(self.peak, power, where=better)
        self.row[better] = i
        np.copyto(self.coef, row, where=better)
        if i == 0:
            self.coef0[...] = row

    def strongest(self) -> tuple[int, int, float, float]:
        """(row, column, C1, C2) of the largest value; on a tie between columns, the first in
        row-major order."""
        cols = np.flatnonzero(self.peak == self.peak.max())
        col = int(cols[0]) if cols.size == 1 else int(cols[np.lexsort((cols, self.row[cols]))[0]])
        c = self.coef[:, col]
        return int(self.row[col]), col, float(c[0]), float(c[1]) if c.size == 2 else 0.0

    def clear(self, cleared: slice) -> None:
        """Set the map to zero at times ``cleared``: their largest value is then 0, first at row 0."""
        self.peak[cleared] = 0.0
        self.row[cleared] = 0
        self.coef[:, cleared] = self.coef0[:, cleared]


def classify_pulse(record: Record, other: Record | None = None, *, energy=dwt_energy) -> PulseClassification:
    """Classify a record, or a pair of horizontal components, as pulse-like or not.

    Shahi & Baker (2014), as their MATLAB code implements it (see the module's description).

    Parameters
    ----------
    record : Record
        Ground acceleration, m/s^2 (the first component of a pair).
    other : Record, optional
        The second, orthogonal, horizontal component; orientations are measured from
        ``record``'s direction towards this one's.  Same ``dt``; lengths within 20 samples are
        truncated to the shorter.
    energy : callable, optional
        Energy measure of a velocity history for the energy ratio: :func:`dwt_energy` (the
        reference's, default) or :func:`integral_energy`.

    Returns
    -------
    PulseClassification

    Raises
    ------
    RecordError
        A pair that cannot be used (see :func:`pulses.pairs.check_pair`).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 20.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.5, 4.0)(t), 0.01)
    >>> c = pulses.classify_pulse(rec)
    >>> c.is_pulse, len(c.candidates)
    (True, 5)
    """
    from .pairs import _azimuth, check_pair, rotated_azimuth

    if other is not None:
        record, other = check_pair(record, other)
    dt = record.dt
    v1 = np.cumsum(record.acc) * (dt * CM_PER_M)
    v2 = np.cumsum(other.acc) * (dt * CM_PER_M) if other is not None else None
    if not np.any(v1) and (v2 is None or not np.any(v2)):
        raise RecordError(f"{record.name}: the velocity is zero throughout; nothing to classify")
    scales = coarse_scales(dt)
    if scales[0] < 1:
        raise RecordError(f"{record.name}: time step {dt:g} s is too long for pulses of "
                          f"{TP_MIN:g} s (at most {TP_MIN * FC:g} s)")
    # the (scale, time) map of C1^2 + C2^2, kept as the candidates need it (_StrongestMap)
    x = v1 if v2 is None else np.stack([v1, v2])
    strongest = _StrongestMap(x.shape[-1], scales.size, v2 is not None)
    for i, row in cwt_rows(x, tuple(float(a) for a in scales)):
        strongest.add(i, row)
    del x
    candidates = []
    for _ in range(N_CANDIDATES):
        row, col, a, b = strongest.strongest()
        theta = math.atan(b / a) if a != 0.0 else (math.pi / 2 if b != 0.0 else 0.0)
        signal = v1 * math.cos(theta) + v2 * math.sin(theta) if v2 is not None else v1
        d = _analyze(signal, dt, int(col), int(row), scales, energy)
        candidates.append(PulseCandidate(
            is_pulse=d["is_pulse"], indicator=d["indicator"], tp=d["tp"], scale=d["scale"],
            pgv=d["pgv"], pgv_ratio=d["pgv_ratio"], energy_ratio=d["energy_ratio"], late=d["late"],
            arrival=record.t_start + d["arrival_index"] * dt, orientation=math.degrees(theta),
            time=record.t_start + int(col) * dt, velocity=d["velocity"], pulse=d["pulse"]))
        reach = WINDOW * scales[row]  # clear samples strictly within `reach` of the maximum
        strongest.clear(slice(max(0, math.floor(col - reach) + 1), max(0, math.ceil(col + reach))))
    pulse_like = [i for i, c in enumerate(candidates) if c.is_pulse]
    chosen = pulse_like[0] if pulse_like else int(np.argmax([c.indicator for c in candidates]))
    c = candidates[chosen]
    if other is not None:
        azimuth = rotated_azimuth(record, other, c.orientation)
    else:
        azimuth = _azimuth(record)
    name = record.name if other is None else f"{record.name}+{other.name}"
    return PulseClassification(
        name=name, azimuth=None if azimuth is None else azimuth % 180.0,
        candidates=tuple(candidates), chosen=chosen, t_start=record.t_start, dt=dt)
