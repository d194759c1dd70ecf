"""Reading accelerograms: PEER AT2 (both header styles), text/CSV, SAC, K-NET, and every refusal.

References are the files themselves (sample counts, first and last samples read by eye from the
files and listed in ../shared/records/MANIFEST.md) and the SAC standard (idep = iacc is nm/s^2).
"""
from __future__ import annotations

import numpy as np
import pytest

import pulses
from pulses import G, Record, RecordError, read_record, write_sac
from pulses.formats.at2 import _is_at2, _read_at2, parse_npts_dt

from .conftest import shared_record


# -- AT2 on the real files --------------------------------------------------------------------
# (file, npts, dt, first sample in g, last sample in g): copied by eye from the files
AT2_CASES = [
    ("Rinaldi228.AT2", 1991, 0.01, -0.2556093e-02, 0.005856269),                 # NPTS=, DT= style
    ("NGA_no_1063_RRS228.AT2", 1991, 0.01, -0.731461e-02, 0.00115999),           # NPTS, DT style
    ("shahi_baker_examples/example1.AT2", 7818, 0.005, -0.2964875e-03, 0.000429151),
    ("RSN181_IMPVALL.H_H-E06140.AT2", 7817, 0.005, 0.0008877145, -0.0008110627),  # odd count: short last line
]


@pytest.mark.parametrize("name,npts,dt,first,last", AT2_CASES)
def test_at2_sample_count_and_end_samples(name, npts, dt, first, last):
    path = shared_record(name)
    rec = read_record(path)
    # the count must equal NPTS and the last sample must be the file's last number: the
    # errors three PyPI readers make (last sample dropped or misplaced, time vector one off)
    assert rec.npts == npts
    assert rec.dt == dt
    assert rec.duration == pytest.approx((npts - 1) * dt, rel=1e-12)
    # samples are converted g -> m/s^2 with g = 9.81; the file's digits are exact in float64
    assert rec.acc[0] == pytest.approx(first * G, rel=1e-12)
    assert rec.acc[-1] == pytest.approx(last * G, rel=1e-12)
    assert rec.metadata["units"] == "g" and rec.metadata["units_source"] == "file"
    assert rec.metadata["format"] == "at2"


def test_at2_header_styles_and_metadata():
    new = read_record(shared_record("Rinaldi228.AT2"))
    old = read_record(shared_record("NGA_no_1063_RRS228.AT2"))
    assert new.metadata["header_style"] == "NPTS=, DT="
    assert old.metadata["header_style"] == "NPTS, DT"
    assert (new.metadata["station"], new.metadata["component"], new.metadata["event"]) == \
        ("Rinaldi Receiving Sta", "228", "Northridge-01")
    assert old.metadata["station"] == "RINALDI RECEIVING STA" and old.metadata["component"] == "228"
    # PGA against MANIFEST section 2 (0.8741 g and 0.8252 g, 4 digits)
    assert new.pga / G == pytest.approx(0.8741, abs=6e-5)
    assert old.pga / G == pytest.approx(0.8252, abs=6e-5)
    for key in ("station", "component", "event", "units", "format", "source", "warnings"):
        assert key in new.metadata


def test_parse_npts_dt_both_styles():
    assert parse_npts_dt("NPTS=   1991, DT=   .0100 SEC,   0 POLE") == (1991, 0.01)
    assert parse_npts_dt("1991    0.0100    NPTS, DT") == (1991, 0.01)
    assert parse_npts_dt("NPTS= 5, DT= 1.0E-02 SEC") == (5, 0.01)
    assert parse_npts_dt("nothing here") is None


def _write_at2(tmp_path, body, npts=12, dt=".0100", units_line="ACCELERATION TIME SERIES IN UNITS OF G",
               name="x.AT2"):
    path = tmp_path / name
    path.write_text("PEER NGA STRONG MOTION DATABASE RECORD\nTest-01, 1/2/2000, Somewhere, 90\n"
                    f"{units_line}\nNPTS=   {npts}, DT=   {dt} SEC,\n{body}")
    return path


def test_at2_touching_numbers_no_leading_zero_short_last_line(tmp_path):
    # no space before a minus sign, no leading zero, 5 a line and a short last line
    body = ("  -.1000000E-02-.2000000E-02  .3000000E-02  .4000000E-02-.5000000E-02\n"
            "   .6000000E-02  .7000000E-02  .8000000E-02  .9000000E-02  .1000000E-01\n"
            "  -.1100000E-01  .1200000E-01\n")
    rec = read_record(_write_at2(tmp_path, body))
    expect = np.array([-1, -2, 3, 4, -5, 6, 7, 8, 9, 10, -11, 12]) * 1e-3 * G
    np.testing.assert_allclose(rec.acc, expect, rtol=1e-15)


@pytest.mark.slow
def test_obspy_reads_at2_through_the_plugin():
    import obspy

    path = shared_record("Rinaldi228.AT2")
    assert _is_at2(str(path))
    st = obspy.read(str(path))  # through the entry point declared in pyproject.toml
    assert len(st) == 1 and st[0].stats.npts == 1991 and st[0].stats.delta == 0.01
    assert st[0].stats.at2.units == "g"
    assert st[0].data[-1] == pytest.approx(0.005856269, rel=1e-12)
    assert _read_at2(str(path))[0].stats.station == "Rinaldi Receiving Sta"


# -- component orientation: metadata["azimuth"] and metadata["vertical"] -------------------------
# (file, component azimuth in degrees): the "component" column of ../shared/records/MANIFEST.md
AT2_AZIMUTHS = [
    ("Rinaldi228.AT2", 228), ("Rinaldi318.AT2", 318), ("NGA_no_1063_RRS228.AT2", 228),
    ("RSN77_SFERN_PUL164.AT2", 164), ("RSN181_IMPVALL.H_H-E06230.AT2", 230),
    ("RSN181_IMPVALL.H_H-E06140.AT2", 140), ("RSN879_LANDERS_LCN260.AT2", 260),
    ("RSN879_LANDERS_LCN345.AT2", 345), ("RSN1084_NORTHR_SCS052.AT2", 52),
    ("RSN1084_NORTHR_SCS142.AT2", 142), ("RSN6_IMPVALL.I_I-ELC180.AT2", 180),
    ("RSN15_KERN_TAF021.AT2", 21), ("RSN68_SFERN_PEL090.AT2", 90), ("RSN125_FRIULI.A_A-TMZ000.AT2", 0),
    ("RSN30_PARKF_C05085.AT2", 85), ("haselREC_NGA-West2-Reduced/RSN77_2.AT2", 254),
    ("haselREC_NGA-West2-Reduced/RSN150_1.AT2", 230), ("haselREC_NGA-West2-Reduced/RSN150_2.AT2", 320),
    ("haselREC_NGA-West2-Reduced/RSN250_1.AT2", 0), ("haselREC_NGA-West2-Reduced/RSN250_2.AT2", 90),
    ("haselREC_NGA-West2-Reduced/RSN159_1.AT2", 3), ("haselREC_NGA-West2-Reduced/RSN159_2.AT2", 273),
    ("haselREC_NGA-West2-Reduced/RSN6_2.AT2", 270), ("shahi_baker_examples/example1.AT2", 140),
    ("shahi_baker_examples/example2.AT2", 230),
]


@pytest.mark.parametrize("name,azimuth", AT2_AZIMUTHS)
def test_at2_azimuth_from_header(name, azimuth):
    meta = read_record(shared_record(name)).metadata
    assert meta["azimuth"] == azimuth and isinstance(meta["azimuth"], float)
    assert meta["vertical"] is False


@pytest.mark.parametrize("component,expect", [
    # NGA-West2 and older PEER component codes: a station code then the azimuth
    ("PUL164", {"azimuth": 164.0, "vertical": False}), ("H-E06230", {"azimuth": 230.0, "vertical": False}),
    ("LCN260", {"azimuth": 260.0, "vertical": False}), ("360", {"azimuth": 0.0, "vertical": False}),
    ("UP", {"vertical": True}), ("DWN", {"vertical": True}), ("V", {"vertical": True}),
    ("-UP", {"vertical": True}), ("E06UP", {"vertical": True}), ("HNZ", {"vertical": True}),
    ("FN", {"vertical": False}), ("TCU068-N", {"azimuth": 0.0, "vertical": False}),
    ("E", {"azimuth": 90.0, "vertical": False}), ("TMZ", {}),  # a station code, not a SEED channel
    ("", {}), ("Somewhere", {}), ("400", {}),  # nothing stated, or not an angle: nothing said
])
def test_at2_component_codes(tmp_path, component, expect):
    path = tmp_path / "c.AT2"
    path.write_text("PEER NGA STRONG MOTION DATABASE RECORD\n"
                    f"Test-01, 1/2/2000, Somewhere, {component}\n"
                    "ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   12, DT=   .0100 SEC,\n"
                    + "  .1E-01 -.2E-01  .3E-01 -.4E-01  .5E-01\n" * 2 + "  .1E-01 -.2E-01\n")
    meta = read_record(path).metadata
    assert {k: meta[k] for k in ("azimuth", "vertical") if k in meta} == expect


def test_knet_direction_gives_azimuth():
    meta = read_record(shared_record("obspy_test_data/test.knet")).metadata
    assert meta["component"] == "EW"  # header "Dir. E-W" (MANIFEST: component E-W)
    assert meta["azimuth"] == 90.0 and meta["vertical"] is False


@pytest.mark.parametrize("cmpinc,cmpaz,kcmpnm,expect", [
    (90.0, 228.0, None, {"azimuth": 228.0, "vertical": False}),
    (90.0, None, None, {"vertical": False}),          # horizontal, azimuth not stated
    (0.0, 0.0, None, {"vertical": True}), (180.0, None, None, {"vertical": True}),
    (45.0, 30.0, None, {}),                           # inclined: neither
    (None, 228.0, None, {}),                          # cmpaz without cmpinc says nothing
    (None, None, "HNZ", {"vertical": True}), (None, None, "HN1", {"vertical": False}),
])
def test_sac_cmpinc_cmpaz(tmp_path, cmpinc, cmpaz, kcmpnm, expect):
    from obspy.io.sac import SACTrace

    sac = SACTrace(data=(0.3 * G * np.sin(np.linspace(0, 20, 500))).astype(np.float32), delta=0.01,
                   idep="iacc")
    if cmpinc is not None:
        sac.cmpinc = cmpinc
    if cmpaz is not None:
        sac.cmpaz = cmpaz
    if kcmpnm is not None:
        sac.kcmpnm = kcmpnm
    sac.write(str(tmp_path / "o.sac"))
    meta = read_record(tmp_path / "o.sac", units="m/s2").metadata
    assert {k: meta[k] for k in ("azimuth", "vertical") if k in meta} == expect


def test_orientation_through_sac_and_mseed(tmp_path):
    from obspy import Trace

    at2 = read_record(shared_record("Rinaldi228.AT2"))
    back = read_record(write_sac(at2, tmp_path / "r.sac"))  # cmpinc 90, cmpaz 228
    assert (back.metadata["azimuth"], back.metadata["vertical"]) == (228.0, False)
    tr = Trace(data=np.asarray(_record().acc, dtype=np.float64))
    tr.stats.delta, tr.stats.channel = 0.01, "HNZ"
    tr.write(str(tmp_path / "z.mseed"), format="MSEED")
    meta = read_record(tmp_path / "z.mseed", units="m/s2").metadata
    assert meta["vertical"] is True and "azimuth" not in meta
    text = read_record(shared_record("base_isolation_benchmark/rinaldi.txt"), units="cm/s2", dt=0.005,
                       column=1).metadata
    assert "azimuth" not in text and "vertical" not in text  # plain text states neither


# -- refusals: one clear RecordError each ----------------------------------------------------------
def test_missing_empty_truncated_npts(tmp_path):
    with pytest.raises(RecordError, match="no such file"):
        read_record(tmp_path / "nope.AT2")
    empty = tmp_path / "empty.AT2"
    empty.write_text("")
    with pytest.raises(RecordError, match="empty"):
        read_record(empty)
    header_only = tmp_path / "h.AT2"
    header_only.write_text("PEER\nA, 1/1/2000, B, 1\nACCELERATION IN UNITS OF G\n")
    with pytest.raises(RecordError, match="truncated"):
        read_record(header_only, format="at2")
    body = "  .1E-02  .2E-02  .3E-02  .4E-02  .5E-02\n  .6E-02\n"
    with pytest.raises(RecordError, match="truncated: header NPTS=12 but the file holds 6"):
        read_record(_write_at2(tmp_path, body, name="short.AT2"))
    with pytest.raises(RecordError, match="longer than its header says"):
        read_record(_write_at2(tmp_path, body, npts=4, name="long.AT2"))
    with pytest.raises(RecordError, match="line 5 is not a list of numbers"):
        read_record(_write_at2(tmp_path, "  .1E-02 abc\n", npts=2, name="junk.AT2"))


def test_velocity_and_displacement_refused(tmp_path):
    body = "  .1E-02  .2E-02  .3E-02  .4E-02  .5E-02\n  .6E-02  .7E-02  .8E-02  .9E-02  .1E-01\n"
    path = _write_at2(tmp_path, body, npts=10, units_line="VELOCITY TIME SERIES IN UNITS OF CM/S",
                      name="x.VT2")
    with pytest.raises(RecordError, match="velocity record"):
        read_record(path)
    with pytest.raises(RecordError, match="velocity or displacement"):
        read_record(_write_at2(tmp_path, body, npts=10), units="cm/s")


def test_nan_too_few_unknown_format_plausibility(tmp_path):
    nan = tmp_path / "nan.txt"
    nan.write_text("\n".join(["1.0", "nan"] + ["0.5"] * 20))
    with pytest.raises(RecordError, match="1 sample\\(s\\) are NaN or infinite"):
        read_record(nan, units="cm/s2", dt=0.01)
    few = tmp_path / "few.txt"
    few.write_text("1\n2\n3\n")
    with pytest.raises(RecordError, match="only 3 sample"):
        read_record(few, units="cm/s2", dt=0.01)
    blob = tmp_path / "blob.bin"
    blob.write_bytes(bytes(range(256)) * 8)
    with pytest.raises(RecordError, match="unknown format|not a text file|cannot read"):
        read_record(blob)
    big = tmp_path / "big.txt"
    big.write_text("\n".join(str(v) for v in [0.0, 850.0, -600.0] * 10))
    # 850 "g" is implausible (> 10 g); in cm/s2 it would be 0.87 g: the message says so
    with pytest.raises(RecordError, match="implausible.*units='cm/s2'"):
        read_record(big, units="g", dt=0.01)
    tiny = tmp_path / "tiny.txt"
    tiny.write_text("\n".join(str(v) for v in [0.0, 1e-8, -2e-8] * 10))
    with pytest.raises(RecordError, match="implausible"):
        read_record(tiny, units="m/s2", dt=0.01)
    strong = tmp_path / "strong.txt"
    strong.write_text("\n".join(str(v) for v in [0.0, 6.0, -2.0] * 10))
    rec = read_record(strong, units="g", dt=0.01)  # 6 g: kept, but with a warning
    assert any("above 5 g" in w for w in rec.metadata["warnings"])


# -- text and CSV ---------------------------------------------------------------------------------
def test_two_column_benchmark_text_needs_column_units_and_dt():
    path = shared_record("base_isolation_benchmark/rinaldi.txt")
    with pytest.raises(RecordError, match="column"):
        read_record(path)
    with pytest.raises(RecordError, match="does not state its units.*cm/sec\\^2"):
        read_record(path, column=1)  # the message quotes the file's comment
    with pytest.raises(RecordError, match="time step"):
        read_record(path, column=1, units="cm/s2")
    rec = read_record(path, format="text", units="cm/s2", dt=0.005, column=1)
    assert rec.npts == 6000 and rec.dt == 0.005
    # MANIFEST section 2: col 1 peaks at 0.8402 g (-0.8402 g at 2.695 s), i.e. 824 cm/s^2 in
    # the file ("-8.24E+02"; the manifest divided by 980.665 cm/s^2, the package uses g = 9.81)
    assert rec.pga == pytest.approx(8.24, rel=1e-12)
    assert rec.pga / 9.80665 == pytest.approx(0.8402, abs=6e-5)
    assert rec.time[np.argmax(np.abs(rec.acc))] == pytest.approx(2.695)
    assert rec.metadata["units"] == "cm/s2" and rec.metadata["units_source"] == "user"
    assert read_record(path, units="gal", dt=0.005, column=2).name == "rinaldi.txt:col2"


def test_csv_with_time_column_bom_and_comments(tmp_path):
    path = tmp_path / "rec.csv"
    t = np.arange(50) * 0.01
    acc = 0.1 * np.sin(2 * np.pi * t)
    lines = ["# pyslammer-style record", "# units: g", "time,acc"] + [f"{a:.2f},{b:.6f}" for a, b in zip(t, acc)]
    path.write_text("\n".join(lines), encoding="utf-8-sig")  # byte-order mark
    rec = read_record(path, units="g")  # dt from the time column
    assert rec.dt == pytest.approx(0.01, rel=1e-12) and rec.npts == 50
    np.testing.assert_allclose(rec.acc, np.round(acc, 6) * G, rtol=1e-12)
    other = read_record(path, units="g", dt=0.02)  # the file's time column wins, with a warning
    assert other.dt == pytest.approx(0.01) and "file says 0.01 s" in other.metadata["warnings"][0]
    bad = tmp_path / "uneven.csv"
    tt = np.concatenate([np.arange(20) * 0.01, 0.25 + np.arange(20) * 0.01])
    bad.write_text("\n".join(f"{a:.3f},0.1" for a in tt))
    with pytest.raises(RecordError, match="non-uniform sampling"):
        read_record(bad, units="g")
    ragged = tmp_path / "ragged.txt"
    ragged.write_text("1 2\n3 4\n5\n")
    with pytest.raises(RecordError, match="truncated last line"):
        read_record(ragged, units="g", dt=0.01, column=1)


# -- SAC, K-NET, MiniSEED ----------------------------------------------------------------------------
def _record(n=400, dt=0.01, peak_g=0.5):
    t = np.arange(n) * dt
    return Record(peak_g * G * np.sin(2 * np.pi * t) * np.exp(-t), dt, name="demo",
                  metadata={"station": "STA1", "component": "HNE", "event": "Test quake"})


def test_write_sac_round_trip(tmp_path):
    rec = _record(dt=0.005)
    path = write_sac(rec, tmp_path / "demo.sac")
    back = read_record(path)  # no units: idep = iacc means nm/s^2 by the SAC standard
    assert back.metadata["units"] == "nm/s2" and back.metadata["units_source"] == "file"
    assert back.dt == 0.005  # float32 delta read back as the shortest decimal
    assert back.npts == rec.npts
    # SAC stores float32: 2^-24 = 6e-8 relative rounding of each sample
    np.testing.assert_allclose(back.acc, rec.acc, rtol=0, atol=1.2e-7 * rec.pga)
    assert back.metadata["station"] == "STA1" and back.metadata["component"] == "HNE"
    assert back.metadata["event"] == "Test quake"


def test_sac_units_idep_and_override(tmp_path):
    from obspy.io.sac import SACTrace

    data = (0.3 * G * np.sin(np.linspace(0, 20, 500))).astype(np.float32)  # m/s^2 under iacc
    sac = SACTrace(data=data, delta=0.01, idep="iacc")
    sac.write(str(tmp_path / "wild.sac"))
    # honoured as nm/s^2 the peak is 3e-10 g: refused, naming the units that make sense
    with pytest.raises(RecordError, match="implausible.*units='m/s2'"):
        read_record(tmp_path / "wild.sac")
    rec = read_record(tmp_path / "wild.sac", units="m/s2")
    assert rec.pga == pytest.approx(float(np.abs(data).max()), rel=1e-7)  # float32 data, read as is
    SACTrace(data=data, delta=0.01, idep="ivel").write(str(tmp_path / "vel.sac"))
    with pytest.raises(RecordError, match="velocity record"):
        read_record(tmp_path / "vel.sac")
    SACTrace(data=data, delta=0.01).write(str(tmp_path / "unk.sac"))
    with pytest.raises(RecordError, match="does not state its units"):
        read_record(tmp_path / "unk.sac")


def test_knet_scale_factor_applied():
    rec = read_record(shared_record("obspy_test_data/test.knet"))
    # header "Max. Acc. (gal) 4.383": after the scale factor and mean removal, 4.383 gal
    assert rec.pga == pytest.approx(0.04383, abs=2e-5)
    assert rec.metadata["units"] == "m/s2" and rec.metadata["station"] == "AKT013"


def test_mseed_needs_units(tmp_path):
    from obspy import Trace

    tr = Trace(data=np.asarray(_record().acc * 100.0, dtype=np.float64))  # cm/s^2, no units in file
    tr.stats.delta = 0.01
    tr.write(str(tmp_path / "x.mseed"), format="MSEED")
    with pytest.raises(RecordError, match="carry no units"):
        read_record(tmp_path / "x.mseed")
    rec = read_record(tmp_path / "x.mseed", units="cm/s2")
    np.testing.assert_allclose(rec.acc, _record().acc, rtol=1e-12)


def test_public_names():
    for name in ("read_record", "RecordError", "write_sac", "fit_pulse", "PulseFit"):
        assert hasattr(pulses, name), name
    assert issubclass(RecordError, ValueError)


# -- the format registry -------------------------------------------------------------------------
def test_formats_are_registered_once_with_their_names():
    from pulses import formats

    names = [f.name for f in formats.registered()]
    assert names[:2] == ["at2", "text"]  # the sniffing order: AT2 before columns of numbers
    assert {"at2", "text", "sac", "knet", "mseed", "obspy"} <= set(names)
    for alias, name in (("peer", "at2"), ("CSV", "text"), ("txt", "text"), ("ascii", "text"),
                        ("SAC", "sac"), ("miniseed", "mseed"), ("KNET", "knet")):
        assert formats.by_name(alias).name == name
    assert formats.by_obspy_name("SAC").name == "sac" and formats.by_obspy_name("KNET").name == "knet"
    with pytest.raises(ValueError, match="registered already"):
        formats.register(formats.RecordFormat(name="other", aliases=("peer",), read=lambda p, o: None))


def test_a_new_format_is_read_without_touching_read_record(tmp_path):
    from pulses import formats

    # a made-up format: "DT <s>" then one sample a line, in cm/s^2 as the (made-up) standard says
    def detect(path):
        with open(path, "rb") as fh:
            return fh.read(3) == b"DT "

    def read(path, options):
        with open(path) as fh:
            dt = float(fh.readline().split()[1])
            values = np.array([float(v) for v in fh], dtype=float)
        return formats.Reading(values, dt, {"format": "dtlist"}, units="cm/s2",
                               units_rule=formats.UNITS_STATED)

    path = tmp_path / "x.rec"
    samples = [0.0, 120.0, -350.0, 80.0] * 5
    path.write_text("DT 0.02\n" + "\n".join(str(v) for v in samples) + "\n")
    formats.register(formats.RecordFormat(name="dtlist", detect=detect, read=read, sniff_order=5))
    try:
        rec = read_record(path, units="g")  # stated units win over a user's, with a warning
        assert rec.dt == 0.02 and rec.metadata["format"] == "dtlist"
        np.testing.assert_array_equal(rec.acc, np.array(samples) * 0.01)  # cm/s^2 -> m/s^2
        assert rec.metadata["units"] == "cm/s2" and "file states cm/s2" in rec.metadata["warnings"][0]
        assert read_record(path, format="dtlist").npts == 20
    finally:
        formats.unregister("dtlist")
    assert formats.by_name("dtlist") is None


# -- length limit and reading in blocks ------------------------------------------------------------
def test_records_longer_than_max_samples_refused(tmp_path):
    text = tmp_path / "long.txt"
    text.write_text("\n".join(f"{0.1 * np.sin(k):.6f}" for k in range(50)))
    assert read_record(text, units="g", dt=0.01, max_samples=50).npts == 50  # at the limit: read
    with pytest.raises(RecordError, match="more than 49 samples; a record may have at most 49"):
        read_record(text, units="g", dt=0.01, max_samples=49)
    body = "  .1E-02 -.2E-02  .3E-02 -.4E-02  .5E-02\n" * 2 + "  .6E-02 -.7E-02\n"
    at2 = _write_at2(tmp_path, body)  # NPTS = 12
    assert read_record(at2, max_samples=12).npts == 12
    with pytest.raises(RecordError, match="12 samples; a record may have at most 11"):
        read_record(at2, max_samples=11)  # refused from the header, before the samples are read
    liar = _write_at2(tmp_path, body, npts=5, name="liar.AT2")  # says 5, holds 12
    with pytest.raises(RecordError, match="more than 10 samples; a record may have at most 10"):
        read_record(liar, max_samples=10)
    sac = write_sac(_record(n=400), tmp_path / "long.sac")
    with pytest.raises(RecordError, match="400 samples; a record may have at most 399"):
        read_record(sac, max_samples=399)
    from pulses.formats import MAX_SAMPLES

    assert MAX_SAMPLES == 10**7


def test_reading_in_blocks_gives_every_sample(tmp_path, monkeypatch):
    import pulses.formats.at2
    import pulses.formats.text

    rng = np.random.default_rng(3)
    acc = rng.normal(0.0, 0.2, 1003)
    csv = tmp_path / "blocks.csv"
    rows = [f"{k * 0.01:.2f},{float(a)!r}" for k, a in enumerate(acc)]
    csv.write_text("# comment\ntime,acc\n" + "\n".join(rows[:500]) + "\n% a comment mid-file\n"
                   + "\n".join(rows[500:]) + "\n")
    at2 = _write_at2(tmp_path, "".join(" ".join(f"{a:.7E}" for a in acc[i:i + 5]) + "\n"
                                       for i in range(0, acc.size, 5)), npts=acc.size)
    whole = read_record(csv, units="g"), read_record(at2)
    # blocks of about 100 characters: block edges fall everywhere, a comment inside one
    monkeypatch.setattr(pulses.formats.text, "_BLOCK_CHARS", 100)
    monkeypatch.setattr(pulses.formats.at2, "_BLOCK_CHARS", 100)
    blocks = read_record(csv, units="g"), read_record(at2)
    # repr() and %.7E digits read back exactly (float64 parsing is correctly rounded)
    np.testing.assert_array_equal(whole[0].acc, acc * G)
    np.testing.assert_array_equal(blocks[0].acc, acc * G)
    np.testing.assert_array_equal(blocks[1].acc, whole[1].acc)
    np.testing.assert_array_equal(whole[1].acc, np.array([float(f"{a:.7E}") for a in acc]) * G)
    assert whole[0].metadata["comments"] == blocks[0].metadata["comments"] == ["comment", "a comment mid-file"]


# -- file names: any bytes, any length ----------------------------------------------------------
def test_names_not_utf8_with_controls_and_long(tmp_path):
    import os

    data = shared_record("Rinaldi228.AT2").read_bytes()
    reference = read_record(shared_record("Rinaldi228.AT2"))
    odd = os.path.join(os.fsencode(tmp_path), b"rec-\xff\xfe.AT2")  # Latin-1 bytes, not UTF-8
    with open(odd, "wb") as fh:
        fh.write(data)
    for path in (odd, os.fsdecode(odd)):  # bytes, and str with PEP 383 surrogates
        rec = read_record(path)
        np.testing.assert_array_equal(rec.acc, reference.acc)
        assert rec.name == "rec-\\xff\\xfe.AT2"  # the bytes written as escapes
        rec.name.encode("utf-8")  # safe to write to a UTF-8 report
    with pytest.raises(RecordError) as err:
        read_record(os.path.join(os.fsencode(tmp_path), b"gone-\xff.AT2"))
    assert "gone-\\xff.AT2: no such file" in str(err.value)
    str(err.value).encode("utf-8")
    newline = tmp_path / "two\nlines.AT2"
    newline.write_bytes(data)
    assert read_record(newline).name == "two\\nlines.AT2"
    long = tmp_path / ("L" * 246 + ".AT2")  # 250 bytes, near the 255 a Linux file name may have
    long.write_bytes(data)
    assert read_record(long).name == long.name and read_record(long).npts == 1991


# -- pipeline convert ------------------------------------------------------------------------------
@pytest.mark.slow
def test_pipeline_convert_to_sac_and_mseed(tmp_path, capsys):
    from pipeline.cli import main

    at2 = shared_record("Rinaldi228.AT2")
    txt = shared_record("base_isolation_benchmark/rinaldi.txt")
    out = tmp_path / "out"
    assert main(["convert", str(at2), "--to", "sac", "--out", str(out)]) == 0
    back = read_record(out / "Rinaldi228.sac")  # idep = iacc, nm/s^2: no units needed
    orig = read_record(at2)
    assert back.npts == orig.npts and back.dt == orig.dt
    np.testing.assert_allclose(back.acc, orig.acc, rtol=0, atol=1.2e-7 * orig.pga)  # float32
    assert main(["convert", str(txt), "--to", "sac", "--out", str(out), "--units", "cm/s2",
                 "--dt", "0.005", "--column", "2"]) == 0
    col2 = read_record(out / "rinaldi.col2.sac")
    assert col2.npts == 6000 and col2.pga == pytest.approx(read_record(txt, units="cm/s2", dt=0.005, column=2).pga,
                                                           rel=1e-7)
    assert main(["convert", str(at2), "--to", "mseed", "--out", str(out)]) == 0
    assert "read back with --units m/s2" in capsys.readouterr().out
    np.testing.assert_allclose(read_record(out / "Rinaldi228.mseed", units="m/s2").acc, orig.acc, rtol=1e-15)
    # a file that cannot be read: one line on stderr, exit status 1; bad units: exit status 2
    assert main(["convert", str(txt), "--to", "sac", "--out", str(out)]) == 1
    assert "column" in capsys.readouterr().err
    assert main(["convert", str(at2), "--to", "sac", "--out", str(out), "--units", "furlongs"]) == 2
