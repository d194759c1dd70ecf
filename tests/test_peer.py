"""PEER NGA-West2 downloads: the search report, the download as a folder and as a zip, unsafe zip
members, vertical polarity, and ``pipeline run DOWNLOAD`` end to end on the shared download."""
from __future__ import annotations

import csv
import io
import pathlib
import zipfile

import numpy as np
import pandas as pd
import pytest

import pulses
from pipeline.cli import main
from pulses import RecordError
from pulses import peer, triplets

#: ``../shared/records/peer_download`` beside the checkout: a real PEER search report and the files
#: of four of its 86 records (RSN 15, 41, 77, 78; RSN 78 has no vertical in PEER's database)
DOWNLOAD = pathlib.Path(__file__).resolve().parents[1].parent / "shared" / "records" / "peer_download"
COMPLETE = {15, 41, 77, 78}
#: the cheap run of the end-to-end tests: one column, one shape, no plots
RUN_ARGS = ["--block", "7.5x1.8", "--shapes", "sine", "--no-plots", "--quiet"]


@pytest.fixture
def download() -> pathlib.Path:
    if not (DOWNLOAD / peer.SEARCH_RESULTS).is_file():
        pytest.skip(f"the shared PEER download is not available: {DOWNLOAD} is absent "
                    "(../shared beside the checkout)")
    return DOWNLOAD


@pytest.fixture
def download_zip(download, tmp_path) -> pathlib.Path:
    """The shared download zipped as PEER delivers it (files at the top level)."""
    path = tmp_path / "PEERNGARecords_Unscaled.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for f in sorted(download.iterdir()):
            zf.write(f, f.name)
    return path


def reference_table(download) -> pd.DataFrame:
    """The metadata table read by pandas, independently of pulses.io.peer."""
    lines = (download / peer.SEARCH_RESULTS).read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("Result ID,"))
    n = next(i for i in range(start + 1, len(lines)) if not lines[i].strip()) - start - 1
    table = pd.read_csv(io.StringIO("\n".join(lines[start:start + 1 + n])), skipinitialspace=True, dtype=str)
    table.columns = [c.strip() for c in table.columns]
    return table.apply(lambda col: col.str.strip())


# -- the search report ---------------------------------------------------------------------------
def test_search_report_matches_an_independent_reading(download):
    d = peer.PeerDownload(download)
    ref = reference_table(download)
    assert len(d.search.entries) == len(ref) == 86
    assert d.search.scaling == "No Scaling"
    assert d.search.notes == ["These records are UNSCALED, AS RECORDED"]
    for e, (_, row) in zip(d.search.entries, ref.iterrows()):
        assert e.rsn == int(row["Record Sequence Number"])
        for key, (name, kind) in peer.METADATA.items():
            text = row[name]
            if text == "-":
                assert e.metadata[key] is None
            elif kind is str:
                assert e.metadata[key] == text
            else:
                assert e.metadata[key] == float(text)  # parsed exactly as written
        for attr, name in (("h1", "Horizontal-1 Acc. Filename"), ("h2", "Horizontal-2 Acc. Filename"),
                           ("vertical", "Vertical Acc. Filename")):
            assert getattr(e, attr) == (None if set(row[name]) == {"-"} else row[name])
    by_rsn = {e.rsn: e for e in d.search.entries}
    assert by_rsn[77].metadata["tp_s"] == 1.638 and by_rsn[77].vertical == "RSN77_SFERN_PULDWN.AT2"
    assert by_rsn[78].vertical is None  # "-----" in the report
    assert by_rsn[138].metadata["event"] == "Tabas_ Iran"  # as PEER writes it


def test_missing_files_are_those_not_in_the_download(download, download_zip):
    for source in (download, download_zip):
        d = peer.PeerDownload(source)
        complete = {e.rsn for e in d.search.entries if not d.missing(e)}
        assert complete == COMPLETE
        by_rsn = {e.rsn: e for e in d.search.entries}
        assert d.missing(by_rsn[7]) == ["RSN7_NWCALIF.C_C-FRN045.AT2", "RSN7_NWCALIF.C_C-FRN135.AT2",
                                        "RSN7_NWCALIF.C_C-FRN-UP.AT2"]


def test_zip_member_reads_like_the_file(download, download_zip):
    name = "RSN77_SFERN_PUL164.AT2"
    from_zip = peer.PeerDownload(download_zip).read_component(name)
    from_file = pulses.read_record(download / name)
    np.testing.assert_array_equal(from_zip.acc, from_file.acc)  # same parser, same bytes
    assert from_zip.dt == from_file.dt == 0.01
    assert from_zip.metadata["source"] == f"{download_zip}/{name}"
    assert from_zip.metadata["azimuth"] == 164.0


@pytest.mark.parametrize("text, message", [
    ("no table here\n", "not a PEER search report"),
    (" -- Summary of Metadata of Selected Records --\nResult ID, Year\n1, 1999\n", "no column"),
    (" -- Summary of Metadata of Selected Records --\nRecord Sequence Number, Horizontal-1 Acc. Filename, "
     "Horizontal-2 Acc. Filename, Vertical Acc. Filename\n7, ../a.AT2, b.AT2, -----\n", "not a plain file name"),
    (" -- Summary of Metadata of Selected Records --\nRecord Sequence Number, Horizontal-1 Acc. Filename, "
     "Horizontal-2 Acc. Filename, Vertical Acc. Filename, Magnitude\n7, a.AT2, b.AT2, -----, big\n", "not a number"),
])
def test_bad_search_reports_are_refused_with_the_reason(text, message):
    with pytest.raises(RecordError, match=message):
        peer.parse_search_results(text)


# -- unsafe zips -------------------------------------------------------------------------------------
def at2_text(values, component="90", dt=0.01) -> str:
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", f"Test, 1/1/2000, Station, {component}",
             "ACCELERATION TIME SERIES IN UNITS OF G", f"NPTS= {len(values)}, DT= {dt:.4f} SEC"]
    return "\n".join(lines + [" ".join(f"{v:.7E}" for v in values[i:i + 5]) for i in range(0, len(values), 5)]) + "\n"


def report_text(rows) -> str:
    head = ("\n -- Summary of Metadata of Selected Records --\nResult ID, Record Sequence Number, Scale Factor, "
            "Tp-Pulse Period (sec), Earthquake Name, Magnitude, Horizontal-1 Acc. Filename, "
            "Horizontal-2 Acc. Filename, Vertical Acc. Filename\n")
    body = "".join(f"{i + 1}, {rsn}, 2.0, -, \"Test\", 6.5, {a}, {b}, {v}\n" for i, (rsn, a, b, v) in enumerate(rows))
    return head + body + "\n"


def pulse_values(az, n=400):
    """A one-sine pulse in g, of another amplitude and period for each azimuth, with a tail."""
    t = 0.01 * np.arange(n)
    tp = 1.0 + az / 180.0
    return (0.4 - az / 900.0) * np.sin(2 * np.pi * t / tp) * (t < tp) + 0.001 * np.cos(t)


def test_unsafe_members_are_never_read_and_fail_their_record(tmp_path, monkeypatch):
    """A zip whose members climb out (``..``), are absolute or oversized: those members are refused
    unread, the records that need them fail with the reason, the others are read; nothing is
    written anywhere (the zip is read in memory)."""
    path = tmp_path / "sub" / "bad.zip"
    path.parent.mkdir()
    big = at2_text(pulse_values(0, n=5000), "0")
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr(peer.SEARCH_RESULTS, report_text([
            (1, "A000.AT2", "A090.AT2", "-----"), (2, "B000.AT2", "B090.AT2", "-----"),
            (3, "C000.AT2", "C090.AT2", "-----"), (4, "D000.AT2", "D090.AT2", "-----")]))
        zf.writestr("A000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("A090.AT2", at2_text(pulse_values(90), "90"))
        zf.writestr("../B000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("B090.AT2", at2_text(pulse_values(90), "90"))
        zf.writestr("/C000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("C090.AT2", at2_text(pulse_values(90), "90"))
        zf.writestr("D000.AT2", big)
        zf.writestr("D090.AT2", at2_text(pulse_values(90), "90"))
    before = sorted(p for p in tmp_path.rglob("*"))
    monkeypatch.setattr(peer, "MAX_MEMBER_BYTES", len(big) - 1)
    d = peer.PeerDownload(path)
    assert set(d.refused) == {"../B000.AT2", "/C000.AT2"}
    by_rsn = {e.rsn: e for e in d.search.entries}
    assert d.missing(by_rsn[1]) == []
    assert d.missing(by_rsn[2]) == ["B000.AT2"] and "climbs out" in d.refusal("B000.AT2")
    assert d.missing(by_rsn[3]) == ["C000.AT2"] and "absolute" in d.refusal("C000.AT2")
    assert d.read_component("A000.AT2").npts == 400
    with pytest.raises(RecordError, match="larger than"):
        d.read_component("D000.AT2")
    with pytest.raises(RecordError, match="climbs out"):
        d.read_bytes("B000.AT2")
    assert sorted(p for p in tmp_path.rglob("*")) == before  # nothing extracted or written


@pytest.mark.slow
def test_unsafe_zip_in_pipeline_run(tmp_path):
    """``pipeline run`` on such a zip: the record that is complete is designed (a pair, scaled by
    the search's factor with --peer-scales), the others are failures with their reasons, status 1."""
    path = tmp_path / "bad.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr(peer.SEARCH_RESULTS, report_text([(1, "A000.AT2", "A090.AT2", "-----"),
                                                       (2, "B000.AT2", "B090.AT2", "-----")]))
        zf.writestr("A000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("A090.AT2", at2_text(pulse_values(90), "90"))
        zf.writestr("../B000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("B090.AT2", at2_text(pulse_values(90), "90"))
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out), "--peer-scales"]) == 1
    pairs = list(csv.DictReader(open(out / "pairs.csv")))
    assert [r["peer_rsn"] for r in pairs] == ["1"]
    assert pairs[0]["peer_scaled"] == "True" and float(pairs[0]["scale"]) == 2.0
    # the component-1 direction is the first file, scaled by 2: its PGA in g
    rows = list(csv.DictReader(open(out / "summary.csv")))
    first = [r for r in rows if r["direction_kind"] == "component-1"][0]
    assert float(first["pga_g"]) == pytest.approx(2 * np.max(np.abs(pulse_values(0))), rel=1e-6)
    fails = list(csv.DictReader(open(out / "failures.csv")))
    assert len(fails) == 1 and "climbs out of the archive" in fails[0]["reason"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.zip", "out"]


# -- verticals ---------------------------------------------------------------------------------------
def test_vertical_polarity_from_name_and_header(download):
    d = peer.PeerDownload(download)
    up = d.read_component("RSN15_KERN_TAF-UP.AT2")
    dwn = d.read_component("RSN41_LYTLECR_ORRDWN.AT2")
    assert triplets.vertical_polarity(up) == 1 and triplets.vertical_polarity(dwn) == -1
    np.testing.assert_array_equal(triplets.upward(dwn).acc, -dwn.acc)  # DWN: multiplied by -1
    np.testing.assert_array_equal(triplets.upward(up).acc, up.acc)


@pytest.mark.parametrize("name, component, expected", [
    ("X-UP.AT2", "UP", 1), ("XDWN.AT2", "DWN", -1), ("X-V1.AT2", "UP", 1),
    ("X-V1.AT2", "V1", None), ("X-UP.AT2", "DWN", None), ("RSN138_TABAS_BOS-V1.AT2", "V", None),
])
def test_vertical_polarity_is_never_guessed(tmp_path, name, component, expected):
    path = tmp_path / name
    path.write_text(at2_text(pulse_values(0, n=50), component))
    rec = pulses.read_record(path)
    if expected is None:
        with pytest.raises(RecordError, match="polarity"):
            triplets.vertical_polarity(rec)
    else:
        assert triplets.vertical_polarity(rec) == expected


# -- pipeline run on the shared download -------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("as_zip", [False, True], ids=["folder", "zip"])
def test_pipeline_run_on_the_shared_download(download, download_zip, tmp_path, as_zip, capsys):
    """The floor: one pair row per complete record, the metadata columns equal to the report's,
    the records not downloaded listed in peer-not-downloaded.csv (one line said, not failures),
    exit status 0: every downloaded record was designed."""
    source = download_zip if as_zip else download
    out = tmp_path / "out"
    loud = [a for a in RUN_ARGS if a != "--quiet"]  # the table is printed unless --quiet
    assert main(["run", str(source), *loud, "--out", str(out)]) == 0
    captured = capsys.readouterr()
    printed = captured.out
    assert "82 not in the download (listed in peer-not-downloaded.csv)" in captured.err
    assert "failed" not in printed + captured.err
    pairs = list(csv.DictReader(open(out / "pairs.csv")))
    assert sorted(int(r["peer_rsn"]) for r in pairs) == sorted(COMPLETE)
    ref = reference_table(download).set_index("Record Sequence Number")
    columns = {"peer_event": "Earthquake Name", "peer_year": "Year", "peer_station": "Station Name",
               "peer_magnitude": "Magnitude", "peer_mechanism": "Mechanism", "peer_rjb_km": "Rjb (km)",
               "peer_rrup_km": "Rrup (km)", "peer_vs30_m_s": "Vs30 (m/sec)",
               "peer_lowest_usable_freq_hz": "Lowest Useable Frequency (Hz)", "peer_tp_s": "Tp-Pulse Period (sec)",
               "peer_scale_factor": "Scale Factor"}
    for r in pairs:
        row = ref.loc[r["peer_rsn"]]
        for col, name in columns.items():
            want = "" if row[name] == "-" else row[name]
            try:
                assert float(r[col]) == float(want), col
            except ValueError:
                assert r[col] == want, col
        assert r["peer_scaled"] == "False" and float(r["scale"]) == 1.0  # default: unscaled
        assert r["file2"] and r["governing_direction_deg"] != ""
    # PEER's Tp of the pulse-like record next to ours (the same period, 1.638 s, for RSN 77)
    rsn77 = [r for r in pairs if r["peer_rsn"] == "77"][0]
    assert float(rsn77["peer_tp_s"]) == 1.638
    assert abs(float(rsn77["velocity_tp_s"]) - 1.638) < 0.05
    # the printed summary and report.html say which earthquake, where, and PEER's Tp beside ours
    # (the report's values: RSN 77 is San Fernando 1971, M 6.61, Rrup 1.81 km, Tp 1.638 s)
    line77 = [ln for ln in printed.splitlines() if ln.startswith("RSN77_") and ": RSN77 " in ln]
    assert len(line77) == 1, printed
    assert "San Fernando 1971" in line77[0] and "M6.61" in line77[0] and "Rrup 1.81 km" in line77[0]
    assert "Tp 1.64 s (PEER)" in line77[0]
    page = (out / "report.html").read_text()
    assert "RSN77 San Fernando 1971" in page and "Tp 1.64 s (PEER)" in page
    # every row of summary.csv carries the metadata too
    summary = list(csv.DictReader(open(out / "summary.csv")))
    assert {r["peer_rsn"] for r in summary} == {str(k) for k in COMPLETE}
    assert list(csv.DictReader(open(out / "failures.csv"))) == []
    absent = list(csv.DictReader(open(out / "peer-not-downloaded.csv")))
    assert len(absent) == 86 - len(COMPLETE)
    assert {int(a["peer_rsn"]) for a in absent} == {e.rsn for e in peer.PeerDownload(download).search.entries} - COMPLETE
    rsn256 = [a for a in absent if a["peer_rsn"] == "256"][0]
    assert (rsn256["h1"], rsn256["h2"], rsn256["vertical"]) == (
        "RSN256_MAMMOTH.AH_C-XMG000.AT2", "RSN256_MAMMOTH.AH_C-XMG270.AT2", "")
    if as_zip:  # read in memory: nothing beside the zip but the reports
        assert sorted(p.name for p in download_zip.parent.iterdir()) == [download_zip.name, "out"]
        assert rsn77["file"] == f"{download_zip}/RSN77_SFERN_PUL164.AT2"
        # a second run reuses every record (the key is the zip's content)
        assert main(["run", str(source), *RUN_ARGS, "--out", str(out)]) == 0
        assert list(csv.DictReader(open(out / "pairs.csv"))) == pairs


def test_peer_scales_without_a_download_is_an_argument_error(tmp_path):
    rec = tmp_path / "a.AT2"
    rec.write_text(at2_text(pulse_values(0), "0"))
    assert main(["run", str(rec), *RUN_ARGS, "--out", str(tmp_path / "o"), "--peer-scales"]) == 2


def test_check_triplet_cuts_to_one_axis_and_refuses_what_is_not_a_vertical(tmp_path):
    def rec(name, component, n=300, dt=0.01):
        path = tmp_path / name
        path.write_text(at2_text(pulse_values(0 if component in ("0", "UP", "DWN", "V1") else 90, n=n), component, dt))
        return pulses.read_record(path)

    h1, h2 = rec("S000.AT2", "0", n=305), rec("S090.AT2", "90", n=310)
    a, b, up = pulses.check_triplet(h1, h2, rec("SDWN.AT2", "DWN", n=300))
    assert a.npts == b.npts == up.npts == 300
    np.testing.assert_array_equal(up.acc, -pulses.read_record(tmp_path / "SDWN.AT2").acc)
    assert up.metadata["polarity"] == "DWN"
    with pytest.raises(RecordError, match="polarity"):
        pulses.check_triplet(h1, h2, rec("S-V1.AT2", "V1"))
    with pytest.raises(RecordError, match="horizontal component, not a vertical"):
        pulses.check_triplet(h1, h2, rec("S180.AT2", "180"))
    with pytest.raises(RecordError, match="time steps differ"):
        pulses.check_triplet(h1, h2, rec("S2-UP.AT2", "UP", dt=0.02))
    with pytest.raises(RecordError, match="lengths differ"):
        pulses.check_triplet(h1, h2, rec("S3-UP.AT2", "UP", n=250))
    late = rec("S4-UP.AT2", "UP")
    late = pulses.Record(late.acc, late.dt, late.name, 2.0, late.metadata)
    with pytest.raises(RecordError, match=r"different times \(0 s for the horizontals, 2 s for the vertical\)"):
        pulses.check_triplet(h1, h2, late)


def test_a_zip_that_is_not_a_peer_download_is_a_failure_not_a_crash(tmp_path):
    path = tmp_path / "other.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("readme.txt", "no search report here")
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out)]) == 1
    fails = list(csv.DictReader(open(out / "failures.csv")))
    assert len(fails) == 1 and "no _SearchResults.csv in the zip" in fails[0]["reason"]


def test_a_download_zipped_inside_a_folder_is_read_next_to_its_report(tmp_path):
    path = tmp_path / "nested.zip"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("PEERNGARecords_Unscaled/" + peer.SEARCH_RESULTS,
                    report_text([(1, "A000.AT2", "A090.AT2", "A-UP.AT2")]))
        zf.writestr("PEERNGARecords_Unscaled/A000.AT2", at2_text(pulse_values(0), "0"))
        zf.writestr("PEERNGARecords_Unscaled/A090.AT2", at2_text(pulse_values(90), "90"))
        zf.writestr("elsewhere/A-UP.AT2", at2_text(pulse_values(0), "UP"))  # not beside the report
    d = peer.PeerDownload(path)
    (entry,) = d.search.entries
    assert d.missing(entry) == ["A-UP.AT2"]
    assert d.read_component("A090.AT2").metadata["source"] == f"{path}/PEERNGARecords_Unscaled/A090.AT2"
    assert entry.metadata["scale_factor"] == 2.0 and entry.metadata["tp_s"] is None
