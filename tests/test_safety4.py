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


# -- --dask at something that is no scheduler, or a scheduler that dies -------------------------------
@pytest.fixture
def not_schedulers():
    """``(banner port, HTTP port, refused port)`` on this host: a server that greets first (as SSH
    does), an HTTP server (the dashboard's port given by mistake), and a port nothing listens on."""
    import http.server
    import socket
    import threading

    def banner(sock):
        while True:
            try:
                conn, _ = sock.accept()
            except OSError:
                return
            conn.sendall(b"SSH-2.0-OpenSSH_9.6\r\n")
            threading.Timer(10.0, conn.close).start()

    ssh = socket.socket()
    ssh.bind(("127.0.0.1", 0))
    ssh.listen()
    threading.Thread(target=banner, args=(ssh,), daemon=True).start()
    web = http.server.HTTPServer(("127.0.0.1", 0), http.server.BaseHTTPRequestHandler)
    threading.Thread(target=web.serve_forever, daemon=True).start()
    free = socket.socket()
    free.bind(("127.0.0.1", 0))
    refused = free.getsockname()[1]
    free.close()
    yield ssh.getsockname()[1], web.server_address[1], refused
    web.shutdown()
    ssh.close()


def test_dask_at_what_is_no_scheduler_is_one_line_and_status_2_at_once(not_schedulers, tmp_path, capsys,
                                                                         monkeypatch):
    """A banner gave numpy's "Unable to allocate 2.82 EiB" traceback (status 1), an HTTP server
    hung for more than 120 s, a refused port took 20 s: each is now one line, exit status 2, before
    anything is read or written."""
    import time

    pytest.importorskip("dask.distributed")
    from pipeline.batch import scheduler

    monkeypatch.setattr(scheduler, "PROBE_S", 1.0)  # how long a silent server is given
    ssh, web, refused = not_schedulers
    from .test_pipeline_run import write_good

    record = write_good(tmp_path, 0, duration=2.0)  # never read: the error comes first
    for port, words in ((ssh, "it greeted with b'SSH-2.0-'"), (web, "it sent nothing within 1 s"),
                        (refused, "nothing listens there (connection refused)")):
        start = time.monotonic()
        code = main(["run", str(record), "--block", "7.5x1.8", "--out", str(tmp_path / "out"),
                     "--dask", f"tcp://127.0.0.1:{port}"])
        err = capsys.readouterr().err
        assert code == 2 and time.monotonic() - start < 3.0
        assert len(err.strip().splitlines()) == 1 and words in err, err
        assert not (tmp_path / "out").exists()
    with pytest.raises(ValueError, match="nothing listens there"):
        import pipeline

        pipeline.design([record], blocks="7.5x1.8", dask=f"tcp://127.0.0.1:{refused}")


@pytest.mark.slow
def test_a_scheduler_killed_mid_run_ends_it_with_its_reports_and_a_resume_finishes(tmp_path, capsys,
                                                                                     monkeypatch):
    """Six pairs on a cluster killed ten seconds in: the client gave up after 20 s, then the run
    sat idle until killed, with no design.csv, failures.csv or report.  Now it ends once the
    client gives up (its reconnection timeout, shortened here), with every report written and the
    tasks not computed in failures.csv (stage `cluster`, exit status 1); run again without dask, the
    batch is finished and every file is a clean run's."""
    import re
    import signal
    import subprocess
    import sys
    import threading
    import time

    pytest.importorskip("dask.distributed")
    from pipeline.batch import scheduler

    from .test_pipeline_run import read_csv
    from .test_site import _pair

    pair = _pair(tmp_path, "STK", 0.45, 0.3, 1)
    args = ["run", "--pair", *map(str, pair), "--directions", "18", "--block", "2x0.35", "--no-plots"]
    assert main([*args, "--out", str(tmp_path / "clean")]) == 0
    sched = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                              "--port", "0", "--no-dashboard"], stderr=subprocess.PIPE, text=True)
    workers = None
    try:
        for line in sched.stderr:
            m = re.search(r"Scheduler at:\s+(tcp://\S+)", line)
            if m:
                break
        address = m.group(1)
        workers = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address,
                                    "--nthreads", "1", "--no-dashboard"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        out = tmp_path / "out"
        killed = []

        def kill_when_some_are_done():
            while len(list(out.glob("*deg.csv"))) < 4:
                time.sleep(0.02)
            sched.send_signal(signal.SIGKILL)
            killed.append(time.monotonic())

        threading.Thread(target=kill_when_some_are_done, daemon=True).start()
        monkeypatch.setattr(scheduler, "CONNECT_TIMEOUT", "3s")
        capsys.readouterr()
        code = main([*args, "--out", str(out), "--dask", address])
        ended = time.monotonic()
    finally:
        for proc in (workers, sched):
            if proc is not None:
                proc.kill()
                proc.wait(timeout=30)
    assert killed and code == 1
    assert ended - killed[0] < 30.0  # the client's 3 s, and the reports
    assert "not computed, listed in failures.csv" in capsys.readouterr().err
    fails = read_csv(out / "failures.csv")
    assert fails and {f["stage"] for f in fails} == {"cluster"}
    assert (out / "design.csv").is_file() and (out / "report.html").is_file()
    assert main([*args, "--out", str(out)]) == 0
    assert tree(out) == tree(tmp_path / "clean")


# -- workers end with the main process ----------------------------------------------------------------
def _descendants(pid) -> set:
    """The processes below ``pid`` (Linux /proc), children of children included."""
    import glob

    out, todo = set(), [pid]
    while todo:
        p = todo.pop()
        for path in glob.glob(f"/proc/{p}/task/*/children"):
            try:
                with open(path) as fh:
                    kids = {int(k) for k in fh.read().split()}
            except OSError:
                continue
            todo += list(kids - out)
            out |= kids
    return out


def _alive(pid) -> bool:
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] not in (b"Z", b"X")
    except (OSError, IndexError):
        return False


@pytest.mark.slow
@pytest.mark.skipif(not __import__("os").path.isdir("/proc/self/task"), reason="needs Linux's /proc")
@pytest.mark.parametrize("how", [["--jobs", "2"], ["--dask", "local", "--jobs", "2"]], ids=["pool", "dask"])
def test_workers_fork_server_and_resource_tracker_end_when_the_main_process_is_killed(how, tmp_path):
    """SIGKILL of `pipeline run --jobs 2` (as an out-of-memory killer does) left the fork server,
    the resource tracker and both workers alive and idle 300 s later (about 500 MB)."""
    import signal
    import subprocess
    import sys
    import time

    from .test_pipeline_run import BATCH_ARGS, write_good

    if "--dask" in how:
        pytest.importorskip("dask.distributed")
    records = [str(write_good(tmp_path, k, duration=30.0)) for k in range(8)]
    proc = subprocess.Popen([sys.executable, "-m", "pipeline", "run", *records, *BATCH_ARGS, *how,
                             "--out", str(tmp_path / "out")],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    below = set()
    while time.monotonic() < deadline and proc.poll() is None:
        below |= _descendants(proc.pid)
        if len(below) >= 3 and list((tmp_path / "out").glob("good*.csv")):  # workers at work
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the batch ended before it could be killed"
    below |= _descendants(proc.pid)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and any(map(_alive, below)):
        time.sleep(0.1)
    left = [p for p in below if _alive(p)]
    for p in left:  # not to leave them behind whatever the outcome
        __import__("os").kill(p, signal.SIGKILL)
    assert not left


# -- pulses.Record: one component ----------------------------------------------------------------------
@pytest.mark.parametrize("shape", [(2, 500), (500, 2), (500, 1), ()])
def test_a_record_of_an_array_not_one_dimensional_is_refused(shape):
    """(2, N) became the two components end to end (twice the duration) and (N, 2) interleaved,
    each designed as one record."""
    import numpy as np

    import pulses

    acc = np.ones(shape) if shape else np.float64(1.0)
    with pytest.raises(ValueError, match=r"one-dimensional.*shape"):
        pulses.Record(acc, 0.01)
    assert pulses.Record(np.ones(500), 0.01).duration == pytest.approx(4.99)


# -- jobs > 1 from a script: the guard -------------------------------------------------------------------
_SCRIPT = """\
import sys
print("top level", flush=True)
import pipeline

def work():
    run = pipeline.design(sys.argv[1:], blocks="7.5x1.8", shapes="sine", jobs=2)
    print("failed", len(run.failures), flush=True)

{call}
"""


@pytest.mark.slow
def test_jobs_from_a_script_without_the_guard_fails_at_once_naming_it(tmp_path):
    """Every record failed with "A process in the process pool was terminated abruptly", and each
    worker ran the script's top level again.  Now the call fails before any process starts, with
    the guard in the message; under the guard (or in a function it calls) the batch runs."""
    import subprocess
    import sys

    from .test_pipeline_run import write_good

    records = [str(write_good(tmp_path, k, duration=3.0)) for k in range(2)]
    for call, guarded in (("work()", False), ('if __name__ == "__main__":\n    work()', True)):
        script = tmp_path / "batch.py"
        script.write_text(_SCRIPT.format(call=call))
        proc = subprocess.run([sys.executable, str(script), *records], capture_output=True, text=True,
                              cwd=tmp_path, timeout=300)
        if guarded:  # (the workers import the script, so its first line runs in each)
            assert proc.returncode == 0 and "failed 0" in proc.stdout, proc.stderr
        else:
            assert proc.stdout.count("top level") == 1, proc.stdout  # no worker was started
            assert proc.returncode == 1 and "failed" not in proc.stdout
            assert 'RuntimeError: jobs=2 starts worker processes' in proc.stderr
            assert 'if __name__ == "__main__":' in proc.stderr and "line 9" in proc.stderr


def test_the_guard_is_found_in_either_spelling():
    from pipeline.batch.mainguard import guarded_lines

    source = "a = 1\nif '__main__' == __name__:\n    b = 2\n    c = 3\nif __name__ == 'x':\n    d = 4\n"
    assert guarded_lines(source) == [(3, 4)]


# -- the smaller items ----------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("extra", [[], ["--jobs", "2"]], ids=["one", "pool"])
def test_quiet_silences_warnings_here_and_in_the_workers(extra, tmp_path):
    """-q printed obspy's warning on a SAC file's sample spacing and numpy's overflow for
    --limit 1e-320 (what a record's reading warns of that matters is in its rows)."""
    import subprocess
    import sys

    import pulses
    from pulses.fit.synthetic import synthetic_record

    paths = []
    for k in range(2):  # sampled at 300 Hz: obspy warns that it rounds the spacing
        r = synthetic_record("sine", 0.5 * pulses.G, 1.0, 2.0, 4.0, dt=1 / 300, noise=0.1, seed=k)
        paths.append(str(tmp_path / f"odd{k}.sac"))
        pulses.write_sac(pulses.Record(r.acc, 1 / 300, f"odd{k}"), paths[-1])
    cmd = [sys.executable, "-m", "pipeline", "run", *paths, "--block", "7.5x1.8", "--shapes", "sine",
           "--no-plots", "--limit", "1e-320", *extra, "--out", str(tmp_path / "out")]
    loud = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert loud.returncode == 0 and "Warning" in loud.stderr  # the warnings this is about
    quiet = subprocess.run([*cmd, "-q", "--force"], capture_output=True, text=True, cwd=tmp_path)
    assert quiet.returncode == 0 and quiet.stderr == "" and quiet.stdout == ""


# -- pipeline.design() follows pipeline run's rules ------------------------------------------------------
@pytest.mark.parametrize("kw, argv, words", [
    (dict(up_to=0.5), ["--up-to", "0.5"], "must lie between 1 and 1000"),
    (dict(up_to=5000), ["--up-to", "5000"], "must lie between 1 and 1000"),
    (dict(up_to=-2.0), ["--up-to=-2"], "must lie between 1 and 1000"),
    (dict(cap_mass_ratio=5000), ["--cap-mass-ratio", "5000"], "must be a number between 0 and 1000"),
    (dict(cap_mass_ratio=-1), ["--cap-mass-ratio=-1"], "must be a number between 0 and 1000"),
    (dict(dt=-0.01), ["--dt=-0.01"], "(s) must be a positive finite number"),
    (dict(dt=5), ["--dt", "5"], "(s) must lie between 1e-05 s and 1 s"),
    (dict(limit=1.5), ["--limit", "1.5"], "(max|theta|/alpha) must be a number in (0, 1]"),
    (dict(limit=0.0), ["--limit", "0"], "(max|theta|/alpha) must be a number in (0, 1]"),
    # argparse took -inf for an option: "expected one argument"
    (dict(limit=float("-inf")), ["--limit", "-inf"], "(max|theta|/alpha) must be a number in (0, 1]"),
    (dict(up_to=-1e5), ["--up-to", "-1e5"], "must lie between 1 and 1000"),
    (dict(directions=-1), ["--directions=-1"], "must be 0 to 180"),
    (dict(directions=500), ["--directions", "500"], "must be 0 to 180"),
    (dict(scale=1e6), ["--scale", "1e6"], "must lie between 0.001 and 1000"),
    (dict(jobs=-1), ["--jobs=-1"], "must be 0 (one per CPU) to 256"),
    (dict(column=0), ["--column", "0"], "counts from 1"),
])
def test_design_refuses_what_pipeline_run_refuses_in_the_same_words(kw, argv, words, tmp_path, capsys):
    """up_to 0.5 or 5000 and cap_mass_ratio 5000 passed where the command line refuses them;
    negative up_to, cap_mass_ratio or dt became failed rows instead of a ValueError."""
    import pipeline

    from .test_pipeline_run import write_good

    record = write_good(tmp_path, 0, duration=2.0)
    with pytest.raises(ValueError) as info:
        pipeline.design([record], blocks="7.5x1.8", out=tmp_path / "py", **kw)
    assert words in str(info.value) and str(info.value).startswith(next(iter(kw)))
    assert main(["run", str(record), "--block", "7.5x1.8", "--out", str(tmp_path / "cli"), *argv]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "py").exists() and not (tmp_path / "cli").exists()


@pytest.mark.parametrize("kw, words", [
    (dict(force="no"), "force: expected True or False"), (dict(fragility="no"), "fragility: expected True or False"),
    (dict(quiet="no"), "quiet: expected True or False"), (dict(thorough=1), "thorough: expected True or False"),
    (dict(plots=1), "plots: expected True, False, None or one of"), (dict(glob=5), "glob: expected text"),
    (dict(directions=2.0), "directions: expected a whole number"), (dict(jobs=True), "jobs: expected a whole number"),
])
def test_design_takes_booleans_only_as_booleans(kw, words, tmp_path):
    """plots="none", force="no", fragility="no" and quiet="no" all meant True; glob=5 raised a raw
    TypeError."""
    import pipeline

    with pytest.raises(TypeError, match=__import__("re").escape(words)):
        pipeline.design([tmp_path / "a.sac"], blocks="7.5x1.8", **kw)
    with pytest.raises(ValueError, match="'governing', 'all', 'none'"):
        pipeline.design([tmp_path / "a.sac"], blocks="7.5x1.8", plots="no")


def test_design_takes_thorough_plots_all_or_none_and_numpy_integers(tmp_path):
    """design() had no thorough and no plots="all", and refused np.int64 for directions and jobs."""
    import numpy as np

    import pipeline
    from pipeline.cli import build_parser
    from pipeline.plan import plan_from
    from pipeline.commands import run as run_command

    from .test_pipeline_run import write_good

    for plots, cli in (("all", ["--plots", "all"]), ("none", ["--no-plots"]), ("governing", []), (False, ["--no-plots"])):
        plan = plan_from([tmp_path / "a.sac"], blocks="7.5x1.8", heights=None, pairs=None, directions=np.int64(3),
                         vertical="auto", limit=None, restitution=None, jobs=np.int64(1), out=None, shapes=None,
                         weighting="background", units=None, dt=None, scale=None, plots=plots, force=False,
                         quiet=True, thorough=True)
        args = build_parser().parse_args(["run", "a.sac", "--block", "7.5x1.8", "--thorough", *cli])
        assert plan.options == run_command.options_from(args, **{k: getattr(plan.options, k) for k in (
            "shapes", "weighting", "vertical", "cap_mass_ratio", "fragility", "up_to", "limit")})
        assert plan.directions == 3 and plan.jobs == 1
    record = write_good(tmp_path, 0, duration=2.0)
    run = pipeline.design([record], blocks="7.5x1.8", shapes="sine", directions=np.int64(0), jobs=np.int64(1))
    assert run.exit_code == 0 and len(run.design) == 1


def test_a_record_sampled_too_coarsely_is_said_so_not_too_short():
    import numpy as np

    import pulses

    rec = pulses.Record(np.random.default_rng(1).normal(size=200), 10.0, "coarse")  # 1990 s long
    with pytest.raises(pulses.FitError, match="sampled every 10 s, too coarsely"):
        pulses.fit_pulse(rec)


def test_a_full_disk_at_a_figure_still_writes_design_csv_and_report_html(tmp_path, capsys, monkeypatch):
    """When the disk filled at a figure, design.csv and report.html were never written."""
    import errno

    from pipeline.reports import files, outfiles

    from .test_pipeline_run import write_good

    records = [str(write_good(tmp_path, k, duration=2.0)) for k in range(2)]
    real = files.Outputs.write

    def full_at_figures(self, rel, data):
        if str(rel) == outfiles.SUMMARY_PLOT:
            raise OSError(errno.ENOSPC, f"No space left on device: '{rel}'")
        return real(self, rel, data)

    monkeypatch.setattr(files.Outputs, "write", full_at_figures)
    out = tmp_path / "out"
    assert main(["run", *records, "--block", "7.5x1.8", "--shapes", "sine", "--out", str(out)]) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert (out / "design.csv").is_file() and (out / "report.html").is_file()
    assert not (out / outfiles.SUMMARY_PLOT).exists()
    monkeypatch.undo()
    assert main(["run", *records, "--block", "7.5x1.8", "--shapes", "sine", "--out", str(out), "-q"]) == 0
    assert (out / outfiles.SUMMARY_PLOT).is_file()


def test_a_batch_whose_every_record_failed_draws_no_empty_figure(tmp_path):
    from pipeline.reports import files, outfiles

    bad = tmp_path / "bad.sac"
    bad.write_bytes(b"not a record")
    out = tmp_path / "out"
    assert main(["run", str(bad), "--block", "7.5x1.8", "--out", str(out), "-q"]) == 1
    assert (out / "design.csv").is_file() and (out / "report.html").is_file()
    assert not list(out.rglob("*.png"))
    assert not (out / outfiles.SUMMARY_PLOT).exists()


def test_the_suite_table_is_rounded_as_suite_csv(tmp_path):
    """DesignRun.suite carried unrounded floats while suite.csv holds 6 significant digits."""
    import csv

    import pipeline

    from .test_pipeline_run import write_good

    records = [write_good(tmp_path, k, duration=2.0) for k in range(3)]
    run = pipeline.design(records, blocks="7.5x1.8", shapes="sine", out=tmp_path / "out", plots=False)
    with open(tmp_path / "out" / "suite.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert list(run.suite.columns) == rows[0]
    for got, want in zip(run.suite.itertuples(index=False), rows[1:]):
        for value, cell in zip(got, want):
            if isinstance(value, float) and cell:
                assert value == float(cell), (value, cell)  # the file's number, not a finer one


# -- the report's words -----------------------------------------------------------------------------------
def test_the_report_names_its_pgvs_and_says_why_the_governing_pulse_is_not_the_best_fit(tmp_path):
    """The demo's report gave "PGV 0.241 m/s" and a line below "PGV 25 cm/s" (two definitions, two
    units, unnamed), "its design overturns under 0", and no word on why a symmetric Ricker governed
    a record made with an antisymmetric one."""
    import html
    import re

    import pipeline
    from pipeline.commands.demo import bundled_records

    with bundled_records() as paths:
        pipeline.design(paths[:2], blocks="7.5x1.8", out=tmp_path / "out", plots=False)
    page = html.unescape(re.sub(r"<[^>]+>", " ", (tmp_path / "out" / "report.html").read_text()))
    assert "cm/s" not in page
    assert "velocity after the fitter's baseline correction" in page
    assert "the indicator's PGV, in the pulse's direction and without baseline correction" in page
    assert "its design overturns" not in page and "a column of Eq. 31's width overturns under none" in page
    # the antisymmetric Ricker record is governed by a symmetric Ricker, and the page says why
    assert "so it is not always the best fit" in page and "fits ricker-anti best" in page
    # g = 9.81 is the paper's value, not standard gravity (9.80665), and columns.md says so
    columns = (tmp_path / "out" / "columns.md").read_text()
    assert "g = 9.81 m/s^2, the value of the paper" in columns and "standard gravity is 9.80665" in columns


def test_a_levels_overturning_width_says_whether_it_is_whole():
    """Under --limit, overturning_width_m carried a less refined number than without it (1.85944
    against 1.8608) under the same words: where the level's own width governs, it is only what was
    established, and the report says so."""
    from pipeline.reports.html_report import _overturning_words

    assert "set by the overturning design width 1.861 m" in _overturning_words(
        {"overturning_width_m": 1.8608, "design_width_m": 1.8608})
    words = _overturning_words({"overturning_width_m": 1.85944, "design_width_m": 2.1})
    assert "at least 1.859 m: refined only as far as it could change the design width" in words
    assert _overturning_words({"design_width_m": 2.1}) == ""
