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


# -- the resume key: the code, not only the version ---------------------------------------------------
@pytest.mark.slow
def test_a_change_of_the_code_or_its_settings_computes_the_records_again(tmp_path):
    """An editable install whose search settings changed kept its earlier reports ("3 reused, 0
    computed"): the key held only the version.  Here the packages are copied, run, a default of
    the search changed in the copy's source, and run again: nothing is kept."""
    import pathlib
    import re
    import shutil
    import subprocess
    import sys

    import rocking

    from .test_pipeline_run import BATCH_ARGS, write_good

    root = pathlib.Path(rocking.__file__).resolve().parents[1]
    code = tmp_path / "code"
    for name in resume.CODE_PACKAGES:
        shutil.copytree(root / name, code / name, ignore=shutil.ignore_patterns("__pycache__", "*.c"))
    records = [str(write_good(tmp_path, k, duration=4.0)) for k in range(2)]
    env = {**__import__("os").environ, "PYTHONPATH": str(code)}
    cmd = [sys.executable, "-m", "pipeline", "run", *records, *[a for a in BATCH_ARGS if a != "--quiet"],
           "--out", str(tmp_path / "out")]

    def counts():
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr
        return re.search(r"\((\d+) reused from an earlier run, (\d+) computed\)", proc.stdout).groups()

    assert counts() == ("0", "2")
    assert counts() == ("2", "0")
    search = code / "rocking" / "search.py"
    text = search.read_text()
    assert "\nDEFAULT_SETTINGS = SearchSettings()" in text
    search.write_text(text.replace("\nDEFAULT_SETTINGS = SearchSettings()",
                                   "\nDEFAULT_SETTINGS = SearchSettings()  # changed"))
    assert counts() == ("0", "2")


def test_the_code_digest_follows_every_code_file(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "a.py").write_text("x = 1\n")
    (pkg / "sub" / "b.pyx").write_text("y = 2\n")
    (pkg / "__pycache__").mkdir()
    before = resume.source_digest([pkg])
    (pkg / "__pycache__" / "a.pyc").write_bytes(b"cache")  # not code
    (pkg / "notes.txt").write_text("not code")
    assert resume.source_digest([pkg]) == before
    (pkg / "sub" / "b.pyx").write_text("y = 3\n")
    assert resume.source_digest([pkg]) != before
    assert resume.code_version().startswith(resume.package_version() + "+")
