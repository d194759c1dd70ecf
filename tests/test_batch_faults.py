"""``pipeline run`` when a worker process dies, and dask workers that cannot see the inputs."""
from __future__ import annotations

import pytest

from pipeline.batch import remote, runner, worker
from pipeline.cli import main

from .test_pipeline_run import BATCH_ARGS, read_csv, tree, write_good


@pytest.fixture(scope="module")
def six(tmp_path_factory):
    folder = tmp_path_factory.mktemp("faults-in")
    return [str(write_good(folder, k, duration=4.0)) for k in range(6)]


@pytest.fixture(scope="module")
def reference(six, tmp_path_factory):
    out = tmp_path_factory.mktemp("faults-ref")
    assert main(["run", *six, *BATCH_ARGS, "--out", str(out)]) == 0
    return tree(out)


def _check_worker_failure(out, reference, killer="good02"):
    """Only ``killer`` failed, as a worker failure; every other report is the serial run's."""
    fails = read_csv(out / "failures.csv")
    assert [(f["record"], f["stage"]) for f in fails] == [(killer, "worker")]
    got = tree(out)
    for name, data in reference.items():
        if name.startswith("good") and not name.startswith(killer):
            assert got[name] == data, name
    assert f"{killer}.csv" not in got
    rows = read_csv(out / "summary.csv")
    assert [r["record"] for r in rows] == [f"good{k:02d}" for k in range(6) if f"good{k:02d}" != killer]


@pytest.mark.slow
@pytest.mark.parametrize("how", [["--jobs", "2"], ["--jobs", "2", "chunks"], ["--dask", "local", "--jobs", "2"]],
                         ids=["pool", "pool-chunks", "dask"])
def test_a_worker_killed_at_one_record_fails_that_record_only(how, six, reference, tmp_path, monkeypatch):
    if "--dask" in how:
        pytest.importorskip("dask.distributed")
    if "chunks" in how:  # records sent three at a time: the killer's chunk mates are run again, alone
        how = how[:-1]
        monkeypatch.setattr(worker, "chunk_size", lambda queued, jobs: min(3, queued))
    import glob
    import tempfile

    leftovers = lambda: set(glob.glob(f"{tempfile.gettempdir()}/pipeline-record-*"))
    before = leftovers()
    monkeypatch.setenv(runner.TEST_KILL_ENV, "good02")  # the worker running good02 SIGKILLs itself
    out = tmp_path / "out"
    assert main(["run", *six, *BATCH_ARGS, *how, "--out", str(out)]) == 1
    _check_worker_failure(out, reference)
    # the killed dask worker's copy of good02 is in its own folder, which dask removes, not left
    # in the system's temporary folder
    assert leftovers() <= before
    # run again without the fault: only good02 is computed, and the files are the serial run's
    monkeypatch.delenv(runner.TEST_KILL_ENV)
    assert main(["run", *six, *BATCH_ARGS, *how, "--out", str(out)]) == 0
    assert tree(out) == reference


@pytest.mark.slow
def test_dask_workers_need_no_access_to_the_inputs(six, reference, tmp_path, monkeypatch):
    """Every input file is deleted as soon as the client has read it: the workers (other processes)
    can only have the bytes the client shipped, and the reports are those of a serial run."""
    pytest.importorskip("dask.distributed")
    import os
    import shutil

    folder = tmp_path / "in"
    shutil.copytree(os.path.dirname(six[0]), folder)
    paths = [str(folder / os.path.basename(p)) for p in six]
    read = remote.read_bytes

    def read_then_delete(path):
        data = read(path)
        os.unlink(path)
        return data

    monkeypatch.setattr(remote, "read_bytes", read_then_delete)
    out = tmp_path / "out"
    assert main(["run", *paths, *BATCH_ARGS, "--dask", "local", "--jobs", "2", "--out", str(out)]) == 0
    assert not os.listdir(folder)
    got = tree(out)
    for name, data in reference.items():
        if name.startswith("good"):  # the rows name the path given, so compare the other cells
            assert got[name].replace(str(folder).encode(), os.path.dirname(six[0]).encode()) == data, name


def test_records_go_to_the_workers_in_chunks_then_one_at_a_time():
    # a long queue in chunks of CHUNK, then smaller ones as it empties, the last few alone
    sizes, queued = [], 200
    while queued:
        k = worker.chunk_size(queued, 2)
        assert 1 <= k <= min(worker.CHUNK, queued)
        sizes.append(k)
        queued -= k
    assert sizes[0] == worker.CHUNK and sizes[-8:] == [1] * 8 and sizes == sorted(sizes, reverse=True)
