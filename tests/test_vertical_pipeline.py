"""``pipeline run`` with the vertical component: --triplet, --pairs auto triplets, --vertical none,
a vertical whose polarity is not stated (refused, and said), on the shared PEER files."""
from __future__ import annotations

import csv
import pathlib

import numpy as np
import pytest

import pulses
import rocking
from pipeline.cli import main

from .vertical_cases import DOWNLOAD

RUN_ARGS = ["--block", "3x0.3", "--shapes", "sine", "--no-plots", "--quiet"]
#: RSN 41 (Lytle Creek, Castaic): short (3203 samples), a DWN vertical
H1, H2, V = "RSN41_LYTLECR_ORR021.AT2", "RSN41_LYTLECR_ORR291.AT2", "RSN41_LYTLECR_ORRDWN.AT2"


@pytest.fixture
def files():
    if not (DOWNLOAD / V).is_file():
        pytest.skip(f"the shared PEER download is not available: {DOWNLOAD} is absent")
    return [str(DOWNLOAD / n) for n in (H1, H2, V)]


def rows(out, name="summary.csv"):
    return list(csv.DictReader(open(out / name)))


@pytest.mark.slow
def test_dask_workers_get_the_vertical_too(files, tmp_path, monkeypatch):
    # the client ships a triplet's three files; each is spoilt on disk once read, so a worker
    # reading a path rather than the bytes would not find a record there (the vertical: a warning, no
    # vertical columns), and the rows (naming the files as given) are the one-process run's
    pytest.importorskip("dask.distributed")
    import shutil

    from pipeline.batch import remote

    folder = tmp_path / "in"
    folder.mkdir()
    copies = [str(shutil.copy(f, folder)) for f in files]
    args = ["--triplet", *copies, *RUN_ARGS, "--scale", "5", "--directions", "4"]
    assert main(["run", *args, "--out", str(tmp_path / "one")]) == 0
    read = remote.read_bytes

    first = {}

    def read_then_spoil(path):  # the client keeps what it read first
        if path not in first:
            first[path] = read(path)
            pathlib.Path(path).write_text("not a record\n")
        return first[path]

    monkeypatch.setattr(remote, "read_bytes", read_then_spoil)
    assert main(["run", *args, "--dask", "local", "--jobs", "2", "--out", str(tmp_path / "dask")]) == 0
    assert all(pathlib.Path(p).read_text() == "not a record\n" for p in copies)
    got, want = rows(tmp_path / "dask"), rows(tmp_path / "one")
    assert got == want and all(r["vertical_file"] == copies[2] and r["vertical_polarity"] == "DWN" for r in got)



@pytest.mark.slow
def test_dask_leaves_a_vertical_the_client_cannot_read_to_the_worker(files, tmp_path):
    # not shipped: the worker finds it unreadable too, and the rows say so as one process does
    pytest.importorskip("dask.distributed")
    unreadable = tmp_path / "RSN41_LYTLECR_ORRDWN.AT2"
    unreadable.mkdir()  # a folder: no file to read
    args = ["--triplet", files[0], files[1], str(unreadable), *RUN_ARGS, "--directions", "4"]
    assert main(["run", *args, "--out", str(tmp_path / "one")]) == 0
    assert main(["run", *args, "--dask", "local", "--jobs", "2", "--out", str(tmp_path / "dask")]) == 0
    got, want = rows(tmp_path / "dask"), rows(tmp_path / "one")
    assert got == want and all("vertical not used" in r["warnings"] for r in got)

@pytest.mark.slow
def test_triplet_adds_the_response_with_the_vertical(files, tmp_path):
    out = tmp_path / "out"
    # scaled by 5 (PGA 0.1 to 0.13 g): the column rocks in some directions; the vertical is scaled too
    assert main(["run", "--triplet", *files, *RUN_ARGS, "--scale", "5", "--out", str(out)]) == 0
    summary = rows(out)
    assert any(float(r["vertical_max_theta_ratio"]) > 0.01 for r in summary)
    assert len(summary) >= 2  # the pair's directions
    first, second = pulses.read_pair(files[0], files[1])
    raw = pulses.read_record(files[2])
    block = rocking.Block.from_dimensions(3.0, 0.3)
    for r in summary:
        assert r["vertical_file"] == files[2] and r["vertical_polarity"] == "DWN"
        assert r["vertical_model"] in ("fast-vertical", "rest")
        # an independent reading: the component, the vertical times -1 (DWN), cut to one length
        n = min(first.npts, raw.npts)
        comp = pulses.component(first, second, float(r["direction_deg"]))
        comp = pulses.Record(5 * comp.acc[:n], comp.dt)
        up = pulses.Record(-5 * raw.acc[:n], raw.dt)
        ref = rocking.simulate_vertical_reference(block, comp, up)
        assert r["vertical_overturns"] == str(ref.overturned)
        # the recorded components' directions (0, 90) are exact; the pulse direction is written with
        # 6 significant digits (76.0844 deg), which moves the component by ~1e-6 rad and the peak
        # rotation by ~1e-4 of itself
        exact = r["direction_kind"].startswith("component")
        assert float(r["vertical_max_theta_ratio"]) == pytest.approx(ref.max_rotation_ratio,
                                                                      rel=1e-5 if exact else 1e-3, abs=1e-9)
        assert float(r["vertical_pga_g"]) == pytest.approx(5 * np.max(np.abs(raw.acc)) / pulses.G, rel=1e-5)
        assert r["vertical_lifts_off"] == "False"


@pytest.mark.slow
def test_pairs_auto_finds_the_vertical_and_none_leaves_it_out(files, tmp_path):
    out = tmp_path / "auto"
    assert main(["run", *files, "--pairs", "auto", *RUN_ARGS, "--out", str(out)]) == 0
    summary = rows(out)
    assert summary and all(r["vertical_file"] == files[2] for r in summary)
    assert all(r["file2"] for r in summary)  # designed as a pair, the vertical not as a record
    out = tmp_path / "none"
    assert main(["run", *files, "--pairs", "auto", "--vertical", "none", *RUN_ARGS, "--out", str(out)]) == 0
    assert all(r["vertical_file"] == "" and r["vertical_overturns"] == "" for r in rows(out))


@pytest.mark.slow
def test_a_vertical_without_polarity_is_not_used_and_said(files, tmp_path):
    text = pathlib.Path(files[2]).read_text().splitlines()
    text[1] = text[1].replace("DWN", "V1")  # the header no longer states the polarity
    unknown = tmp_path / "RSN41_LYTLECR_ORR-V1.AT2"
    unknown.write_text("\n".join(text) + "\n")
    out = tmp_path / "out"
    assert main(["run", "--triplet", files[0], files[1], str(unknown), *RUN_ARGS, "--out", str(out)]) == 0
    for r in rows(out):
        assert r["vertical_file"] == ""
        assert "vertical not used" in r["warnings"] and "polarity" in r["warnings"]


@pytest.mark.slow
def test_a_level_with_the_vertical_is_at_least_the_overturning_design_in_every_direction(files, tmp_path):
    """`--triplet ... --limit 0.5`: in every direction of the pair the design width (the wider of
    the level's with and without the vertical) is at least the overturning design width (the
    wider of the overturning designs with and without it), and the one with the vertical is at
    least that direction's overturning design with it; design.csv's is the widest over the
    directions; the design width is at least the plain run's; with --limit none the column is blank."""
    out = tmp_path / "level"
    assert main(["run", "--triplet", *files, *RUN_ARGS, "--scale", "5", "--limit", "0.5",
                 "--out", str(out)]) == 0
    summary = rows(out)
    assert len(summary) >= 2 and all(r["design_governed_by"] for r in summary)
    for r in summary:
        assert float(r["design_width_m"]) >= float(r["overturning_width_m"]) > 0
        assert float(r["design_width_m"]) >= float(r["vertical_design_width_m"])
    (design,) = rows(out, "design.csv")
    assert float(design["overturning_width_m"]) == max(float(r["overturning_width_m"]) for r in summary)
    plain = tmp_path / "plain"
    assert main(["run", "--triplet", *files, *RUN_ARGS, "--scale", "5", "--limit", "none", "--out", str(plain)]) == 0
    assert all(r["overturning_width_m"] == "" for r in rows(plain))
    # the level's design width is at least the plain run's (the overturning design), for the pair
    # and direction by direction; the overturning design of the level's run, checked only above
    # the level's width (here about twice the overturning one), is at most the plain run's
    (plain_design,) = rows(plain, "design.csv")
    assert float(design["design_width_m"]) >= float(plain_design["design_width_m"])
    by_dir = {r["direction_deg"]: float(r["design_width_m"]) for r in rows(plain)}
    for r in summary:
        assert float(r["design_width_m"]) >= by_dir[r["direction_deg"]]
        assert float(r["overturning_width_m"]) <= by_dir[r["direction_deg"]]
