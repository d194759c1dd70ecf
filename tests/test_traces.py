"""obspy in and out: ``Record.from_trace(r.to_trace())`` is ``r``; an AT2 read through obspy (the
package's plugin) and ``from_trace`` is what ``read_record`` reads; units are taken from what a
reader put in ``trace.stats`` or given, never guessed; ``Record(units=...)`` converts and warns of
an implausible peak; a Stream of two or three components is a pair or a triplet."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import pulses
from pulses import G, RecordError
from pulses.errors import UnitsWarning

from .conftest import SHARED_RECORDS
from .vertical_cases import DOWNLOAD

obspy = pytest.importorskip("obspy")


def _same(a, b):
    """Equal records: samples and time axis bit for bit, name and metadata equal."""
    assert np.array_equal(a.acc, b.acc) and a.dt == b.dt and a.t_start == b.t_start
    assert a.name == b.name and a.metadata == b.metadata


def _at2_files():
    files = sorted(SHARED_RECORDS.glob("*.AT2")) + sorted(DOWNLOAD.glob("*.AT2"))
    if not files:
        pytest.skip(f"real records not available: {SHARED_RECORDS}")
    return files


def test_a_record_comes_back_from_its_trace():
    t = np.arange(0.0, 7.0, 0.0033)  # a step 1/dt does not give back exactly in floating point
    rec = pulses.Record(pulses.make_pulse("sine", 0.4 * G, 1.0, 1.0)(t), 0.0033, name="r",
                        t_start=-1.25, metadata={"station": "ST01", "component": "HNE", "azimuth": 90.0})
    tr = rec.to_trace()
    assert tr.stats.station == "ST01" and tr.stats.channel == "HNE" and tr.stats.npts == rec.npts
    _same(pulses.Record.from_trace(tr), rec)
    _same(pulses.Record.from_trace(tr.copy()), rec)  # obspy's copy keeps what from_trace needs
    tr.trim(tr.stats.starttime + 1.0)  # obspy's processing moves the start: the record follows
    cut = pulses.Record.from_trace(tr)
    k = rec.npts - cut.npts  # samples obspy cut (the nearest to 1 s: 303)
    # obspy keeps times to the nanosecond: the start moves by k dt to within that
    assert k == 303 and cut.t_start == pytest.approx(rec.t_start + k * rec.dt, abs=1e-8)
    assert np.array_equal(cut.acc, rec.acc[-cut.npts:])


def test_every_at2_read_through_obspy_is_read_records(tmp_path):
    for path in _at2_files():
        tr = obspy.read(str(path))[0]
        _same(pulses.Record.from_trace(tr), pulses.read_record(path))


def test_a_processed_at2_trace_keeps_its_units_g():
    """The issue's case: a trace the AT2 plugin read (data in g), processed in obspy, handed over."""
    path = _at2_files()[0]
    tr = obspy.read(str(path))[0]
    tr.detrend("demean")
    rec = pulses.Record.from_trace(tr)
    assert rec.metadata["units"] == "g" and rec.pga == pytest.approx(np.max(np.abs(tr.data)) * G, rel=1e-15)
    other = pulses.Record.from_trace(tr, units="m/s2")  # the AT2's own units win, as read_record's
    assert other.pga == rec.pga and "passed but the file states g" in other.metadata["warnings"][0]


def test_units_are_never_guessed_and_an_implausible_peak_is_refused():
    tr = obspy.Trace(np.sin(np.arange(200) / 9.0) * 0.874, header={"delta": 0.01})
    with pytest.raises(RecordError, match="carry no units.*units="):
        pulses.Record.from_trace(tr)
    assert pulses.Record.from_trace(tr, units="g").pga == pytest.approx(0.874 * G, rel=1e-3)
    with pytest.raises(RecordError, match="implausible.*units='g'"):  # 0.87 nm/s^2
        pulses.Record.from_trace(tr, units="nm/s2")


def test_record_units_convert_and_warn_like_the_readers():
    data = np.sin(np.arange(100) / 7.0) * 0.874
    rec = pulses.Record(data, 0.01, units="g")
    assert np.array_equal(rec.acc, data * G) and rec.metadata["units"] == "g"
    assert np.array_equal(pulses.Record(data * 100.0, 0.01, units="gal").acc, data * 100.0 * 0.01)
    with pytest.warns(UnitsWarning, match=r"implausible.*units='g'"):
        pulses.Record(data, 0.01, units="nm/s2")
    with pytest.raises(RecordError, match="velocity"):
        pulses.Record(data, 0.01, units="cm/s")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pulses.Record(data * 1e4, 0.01)  # no units given: m/s^2 as ever, no check


def test_a_stream_of_two_or_three_components_is_a_pair_or_a_triplet():
    files = sorted(DOWNLOAD.glob("RSN77_*.AT2"))
    if len(files) != 3:
        pytest.skip(f"the PEER download is absent: {DOWNLOAD}")
    stream = obspy.Stream([obspy.read(str(f))[0] for f in files])  # 164, 254, DWN
    h1, h2, up = pulses.from_stream(stream)
    ref = pulses.triplets.check_triplet(*(pulses.read_record(f) for f in files))
    for a, b in zip((h1, h2, up), ref):
        _same(a, b)
    assert up.metadata["vertical"] is True and np.array_equal(up.acc, -pulses.read_record(files[2]).acc)
    pair = pulses.from_stream(stream[:2])
    _same(pair[0], pulses.read_pair(files[0], files[1])[0])
    with pytest.raises(ValueError, match="two horizontal components"):
        pulses.from_stream(stream[:1])
    with pytest.raises(RecordError, match="exactly one vertical"):
        pulses.from_stream(obspy.Stream([stream[0], stream[1], stream[0].copy()]))
