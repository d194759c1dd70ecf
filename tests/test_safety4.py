"""Safe batches, fourth round: a cluster that dies, re-runs that are identical, orphans, the
Python API's rules.

Each test failed on the code before its fix.  The real pairs are read from ``../shared`` (skipped
without it); the tests that start processes or clusters are marked ``slow``.
"""
from __future__ import annotations

import pytest

from pipeline.batch import resume
from pipeline.cli import main

from .conftest import shared_record
from .test_pipeline_run import tree


def _rsn159():
    return [shared_record(f"haselREC_NGA-West2-Reduced/RSN159_{k}.AT2") for k in (1, 2)]


# -- re-runs and resumes: the same bytes --------------------------------------------------------------
@pytest.mark.slow
def test_reruns_and_resumes_of_a_pair_in_many_directions_give_the_same_files(tmp_path, capsys):
    """RSN159 in 14 directions: a direction's rows depend on the bound its check ran above, which
    its pair's passes set.  A re-run kept a direction's report of a later pass where a first pass
    asked for it, the passes went otherwise, and summary.csv changed (design_width_m,
    check_runs, failing_share).  Now a re-run computes nothing and changes no byte, and a run whose
    journal a kill cut short (any prefix of its lines) ends with the same files as one never
    stopped."""
    pair = _rsn159()
    out = tmp_path / "out"
    args = ["run", "--pair", *map(str, pair), "--directions", "12", "--block", "7.5x1.8",
            "--no-plots", "--out", str(out)]
    assert main(args) == 0
    first = tree(out)
    capsys.readouterr()
    assert main(args) == 0
    assert "(14 reused from an earlier run, 0 computed)" in capsys.readouterr().out
    assert tree(out) == first
    lines = (out / resume.RESUME).read_text().splitlines(keepends=True)
    assert lines[-1].startswith("pair  ")  # the pair's passes are done: kept whole
    for keep in (4, 9):  # the header and 3 (8) directions, no pair line: as a kill leaves it
        (out / resume.RESUME).write_text("".join(lines[:keep]))
        assert main(args) == 0
        assert tree(out) == first, keep
