"""The README and the documentation: the first page's shape, its example run, and the Sphinx site
built with warnings as errors, its examples run (``sphinx.ext.doctest``)."""
from __future__ import annotations

import html as html_lib
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
#: the first page stays a first page
MAX_README_LINES = 150


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", text, re.S | re.M)


def test_readme_is_a_first_page():
    text = README.read_text(encoding="utf-8")
    lines = text.splitlines()
    assert len(lines) <= MAX_README_LINES, len(lines)
    # the two commands come first, right after the title, exactly as CI and users run them
    blocks = re.findall(r"^```bash\n(.*?)^```", text, re.S | re.M)
    assert blocks[0].split("#")[0].strip() == "pip install . && pipeline demo"
    test_command = blocks[1].split("#")[0].strip()
    assert test_command == 'pip install -e ".[test]" && python -m pytest'
    # CI runs the README's test command verbatim
    assert test_command in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert text.index(blocks[1]) < text.index("\n## ")
    # every relative link points at a file of the repository
    for target in re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text):
        assert (ROOT / target).exists(), target


def test_readme_table_is_a_real_run():
    """The table pasted in the README is the demo's, as ``pipeline run`` prints it (the rows of
    the demo computed by tests/test_html_report.py's run are compared there; here its format)."""
    from pipeline.reports import answer

    text = README.read_text(encoding="utf-8")
    table = re.search(r"^```text\n(record .*?)^pipeline run: ", text, re.S | re.M).group(1)
    head = table.splitlines()[0]
    assert head.split("  ")[0].strip() == "record"
    for h in answer.HEADERS:
        assert h in head


@pytest.mark.slow
def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    (code,) = _python_blocks(README.read_text(encoding="utf-8"))
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
    out = capsys.readouterr().out.split("\n")
    # the values the README's comments state
    assert out[:7] == ["sine 0.59 0.9", "True", "False 0.74", "2.441", "1.683", "2.158", ""]


#: the outside specification's name as a word (written so that this file does not hold it)
OUTSIDE_SPEC = re.compile(r"\bSPE[C]\b")


def test_no_specification_cited_in_the_package():
    """The package carries its own theory page; its code, tests, benchmarks and docs cite it
    ("docs/theory.md section N"), not an outside document."""
    paths = [README, ROOT / "CHANGELOG.md", ROOT / "pyproject.toml", *DOCS.glob("*.md"), DOCS / "conf.py"]
    for folder in ("pulses", "rocking", "pipeline", "tests", "benchmarks", "data"):
        paths += [p for p in (ROOT / folder).rglob("*")
                  if p.suffix in (".py", ".pyx", ".pxi", ".h", ".md", ".json") and p.is_file()]
    cited = [str(p.relative_to(ROOT)) for p in paths if OUTSIDE_SPEC.search(p.read_text(encoding="utf-8"))]
    assert not cited


def test_theory_sections_are_numbered_1_to_10():
    """The code cites "docs/theory.md section N": the sections must keep their numbers."""
    text = (DOCS / "theory.md").read_text(encoding="utf-8")
    numbers = [int(n) for n in re.findall(r"^## (\d+)\. ", text, re.M)]
    assert numbers == list(range(1, 11))
    titles = dict(re.findall(r"^## (\d+)\. (.*)$", text, re.M))
    assert titles["8"].startswith("Rocking frames") and titles["10"] == "Vertical ground motion"
    # equations numbered by section, each once
    tags = re.findall(r"\\tag\{(\d+)\.(\d+)\}", text)
    assert len(tags) == len(set(tags)) >= 20


def _sphinx(builder: str, out: pathlib.Path, doctrees: pathlib.Path):
    for module in ("sphinx", "myst_parser", "numpydoc", "sphinx_gallery", "pydata_sphinx_theme"):
        pytest.importorskip(module, reason="the docs extra is not installed: pip install '.[docs]'")
    # DOCS_OFFLINE: no inventory is fetched, as on a machine without network (the build must be
    # warning-free either way; with network it links to numpy, scipy, pandas, obspy, matplotlib)
    env = dict(os.environ, DOCS_OFFLINE="1", MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", builder,
                           str(DOCS), str(out), "-d", str(doctrees)],
                          capture_output=True, text=True, timeout=1800, env=env)


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site built once (html, then the doctest builder on the same doctrees: read once)."""
    root = tmp_path_factory.mktemp("docs")
    html = _sphinx("html", root / "html", root / ".doctrees")
    assert html.returncode == 0, html.stdout[-3000:] + html.stderr[-3000:]
    doctest = _sphinx("doctest", root / "doctest", root / ".doctrees")
    assert doctest.returncode == 0, doctest.stdout[-3000:] + doctest.stderr[-3000:]
    return root


def _public(package):
    """The functions and classes of a package's ``__all__`` (constants and modules apart)."""
    import importlib
    import inspect

    mod = importlib.import_module(package)
    return [n for n in mod.__all__ if inspect.isclass(getattr(mod, n)) or inspect.isroutine(getattr(mod, n))]


@pytest.mark.slow
def test_docs_build_without_warnings(site):
    html = site / "html"
    for page in ("index", "getting-started", "commands", "theory", "validation", "performance", "api",
                 "api/pulses", "api/rocking", "api/pipeline", "gallery/index"):
        assert (html / f"{page}.html").is_file(), page
    # the gallery: each example ran and its figure is on its page
    examples = sorted((DOCS / "examples").glob("plot_*.py"))
    assert len(examples) >= 6
    for ex in examples:
        page = (html / "gallery" / f"{ex.stem}.html").read_text(encoding="utf-8")
        assert f"sphx_glr_{ex.stem}_001.png" in page, ex.stem
        assert (html / "_images" / f"sphx_glr_{ex.stem}_001.png").is_file(), ex.stem
    # getting started shows figures (the gallery's, drawn at build)
    start = (html / "getting-started.html").read_text(encoding="utf-8")
    assert start.count("_images/sphx_glr_plot_") >= 2
    # an API page shows the gallery's examples that use its name, with their figures
    page = (html / "api" / "generated" / "rocking.required_width.html").read_text(encoding="utf-8")
    assert "Gallery examples using it" in page and "sphx_glr_plot_width_vs_height_thumb.png" in page
    # the maths comes with the site, not from a CDN
    theory = (html / "theory.html").read_text(encoding="utf-8")
    assert "_static/mathjax/tex-chtml.js" in theory and "cdn" not in theory.lower()
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("package", ["pulses", "rocking", "pipeline"])
def test_every_public_name_has_a_page_with_examples_that_run(site, package):
    """Each function and class of ``__all__`` has its own page, with an Examples section that the
    doctest builder ran without a failure."""
    report = (site / "doctest" / "output.txt").read_text(encoding="utf-8")
    ran = {m.group(1): (int(m.group(2)), int(m.group(3)))
           for m in re.finditer(r"^Document: api/generated/(\S+)\n.*?^(\d+) passed and (\d+) failed",
                                report, re.S | re.M)}
    names = _public(package)
    assert names
    for name in names:
        full = f"{package}.{name}"
        page = site / "html" / "api" / "generated" / f"{full}.html"
        assert page.is_file(), full
        assert '<p class="rubric">Examples</p>' in page.read_text(encoding="utf-8"), f"{full}: no Examples section"
        passed, failed = ran.get(full, (0, 0))
        assert passed >= 2 and failed == 0, f"{full}: {passed} examples passed, {failed} failed"


@pytest.mark.slow
def test_docs_examples_run(site):
    report = (site / "doctest" / "output.txt").read_text(encoding="utf-8")
    tried = sum(int(n) for n in re.findall(r"^\s*(\d+) tests?\b", report, re.M))
    failures = re.search(r"(\d+) failures? in tests", report)
    assert failures and failures.group(1) == "0", report[-2000:]
    assert tried >= 3, report[-2000:]


CHROMIUM = shutil.which("chromium") or ("/usr/bin/chromium" if os.path.exists("/usr/bin/chromium") else None)

#: first in the theory page's head (a copy beside it): records every error, then once MathJax has
#: typeset the page writes into the DOM how many formulas it rendered and whether raw TeX is left
_MATH_PROBE = r"""<script>
(function () {
  var errors = [];
  window.addEventListener("error", function (e) {
    var t = e.target;
    errors.push(t && t !== window && (t.src || t.href) ? "failed to load " + (t.src || t.href) : String(e.message));
  }, true);
  var ce = console.error;
  console.error = function () { errors.push(Array.prototype.join.call(arguments, " ")); ce.apply(console, arguments); };
  function report(extra) {
    var text = document.body.innerText;
    var pre = document.createElement("pre");
    pre.id = "probe-result";
    pre.textContent = JSON.stringify({rendered: document.querySelectorAll("mjx-container").length,
                                      raw: text.indexOf("\\[") >= 0 || text.indexOf("\\tag") >= 0 || text.indexOf("\\frac") >= 0,
                                      errors: errors.concat(extra || [])});
    document.body.appendChild(pre);
  }
  window.addEventListener("load", function () {
    if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
      MathJax.startup.promise.then(function () { report(); }, function (e) { report(["MathJax: " + e]); });
    } else { report(["MathJax did not load"]); }
  });
})();
</script>"""


@pytest.mark.slow
@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian: apt-get install chromium; "
                                              ".ci/run installs it)")
def test_theory_maths_render_offline_in_chromium(site):
    """The theory page in headless Chromium with every host unreachable: MathJax, copied into the
    site, renders every formula (no raw TeX left) with no console error."""
    html = site / "html"
    page = (html / "theory.html").read_text(encoding="utf-8")
    probe = html / "theory-probe.html"  # beside the page: the same relative links
    probe.write_text(page.replace("<head>", "<head>" + _MATH_PROBE, 1), encoding="utf-8")
    with tempfile.TemporaryDirectory() as profile:
        proc = subprocess.run(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--no-first-run", "--disable-component-update", "--disable-sync", f"--user-data-dir={profile}",
             # networking off: every host name fails to resolve, any proxy is a closed port
             "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9",
             "--allow-file-access-from-files", "--enable-logging=stderr", "--v=0",
             "--virtual-time-budget=20000", "--dump-dom", probe.as_uri()],
            capture_output=True, text=True, timeout=180)
    m = re.search(r'<pre id="probe-result"[^>]*>(.*?)</pre>', proc.stdout, re.S)
    assert m, f"chromium showed no result (exit {proc.returncode}): {proc.stderr[-2000:]}"
    result = json.loads(html_lib.unescape(m.group(1)))
    n_tex = theory_formulas()
    assert result["errors"] == []
    assert not result["raw"]
    assert result["rendered"] >= n_tex >= 20, (result["rendered"], n_tex)
    console = [l for l in proc.stderr.splitlines() if "CONSOLE" in l and ("Uncaught" in l or "ERROR" in l)]
    assert console == [], console


def theory_formulas() -> int:
    """Numbered formulas of docs/theory.md (each display formula carries a tag)."""
    return len(re.findall(r"\\tag\{", (DOCS / "theory.md").read_text(encoding="utf-8")))


# -- one name and one design width per record file -----------------------------------------------
def _records_table() -> list[dict]:
    """The rows of "The records these pages use" in docs/records.md."""
    text = (DOCS / "records.md").read_text(encoding="utf-8")
    section = text[text.index("## The records these pages use"):]
    rows = [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in section.splitlines() if line.startswith("| ")]
    head, body = rows[0], rows[1:]
    return [dict(zip(head, r)) for r in body]


def _doc_texts() -> dict[str, str]:
    return {p.name: p.read_text(encoding="utf-8") for p in [README, *sorted(DOCS.glob("*.md"))]}


def _sentences(text: str) -> list[str]:
    # a sentence ends at ". " before a capital, a bold mark or a new paragraph ("Eq. 31" does not)
    return re.split(r"(?<=[.;:])\s+(?=[A-Z*(`])|\n\s*\n", text.replace("\n", " \n"))


def test_each_record_file_has_one_name_and_one_release():
    rows = _records_table()
    files = [r["file"].strip("`") for r in rows if r["file"] != "-"]
    names = [r["name in these pages"] for r in rows]
    assert len(files) == len(set(files)) and len(names) == len(set(names)), (files, names)
    assert all(r["release"] for r in rows)
    # where one recording has several releases, its bare name (without the release) is ambiguous:
    # every mention in the docs carries the release in parentheses
    bases = {}
    for name in names:
        m = re.match(r"(.*?) \((.*)\)$", name)
        if m:
            bases.setdefault(m.group(1), []).append(m.group(2))
    for base, releases in bases.items():
        bare = re.compile(rf"{re.escape(base)}(?! \((?:{'|'.join(map(re.escape, releases))})\))")
        found = [f"{page}: ...{text[max(0, m.start() - 40):m.end() + 40]}..."
                 for page, text in _doc_texts().items() for m in bare.finditer(text)]
        assert not found, f"{base!r} without its release: {found}"


def _close_to_printed(stated: str, width: float) -> bool:
    """``width`` rounds to the number ``stated`` at the digits it prints."""
    return abs(float(stated) - width) <= 0.5 * 10 ** -len(stated.split(".")[1]) + 1e-9


def test_each_record_file_has_one_design_width_across_the_docs():
    """Every sentence that names a record (or its file) and states its design width or its verge,
    and every row of the demo's table, gives the width of docs/records.md's table (at the digits
    printed)."""
    checked = 0
    for row in _records_table():
        if row["design width, 7.5 m"] == "-":
            continue
        width = float(row["design width, 7.5 m"].split()[0])
        verge = float(row["verge, 7.5 m"].split()[0])
        file = row["file"].strip("`")
        keys = {row["name in these pages"], file, file.rsplit("/", 1)[-1]}
        for page, text in _doc_texts().items():
            if page == "records.md":
                continue
            stem = file.rsplit(".", 1)[0]
            for line in re.findall(rf"^{re.escape(stem)}\s+7\.5x1\.8\s.*$", text, re.M):  # the demo's table
                numbers = re.findall(r"(\d+\.\d+) m\b", line)
                if len(numbers) < 2:  # not the run's printed table (a DataFrame shown in a page)
                    continue
                assert _close_to_printed(numbers[1], width), (page, line)
                if len(numbers) > 3:   # the verge beside it (the table of a level, the default)
                    # where the level governs, the verge is checked only above the design width and
                    # prints what was established, at most the full verge (which lies between it
                    # and the design width: Rinaldi 228 (NGA-West2) prints 1.841 m, in full 1.843 m)
                    assert (_close_to_printed(numbers[2], verge)
                            or float(numbers[2]) <= verge <= float(numbers[1])), (page, line)
                checked += 1
            prose = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)  # the tables above: by column
            for sentence in _sentences(prose):
                if not any(k in sentence for k in keys) or "cap_mass_ratio" in sentence:
                    continue
                for stated in re.findall(r"(?:verified|design) width[^;()]*?(\d+\.\d+) m\b", sentence):
                    assert _close_to_printed(stated, width), (page, row["name in these pages"], stated, sentence)
                    checked += 1
                for stated in re.findall(r"\bverge\b[^;()]*?(\d+\.\d+) m\b", sentence):
                    assert _close_to_printed(stated, verge), (page, row["name in these pages"], stated, sentence)
                    checked += 1
    assert checked >= 8  # the demo's five rows in two pages and the Rinaldi sentences were read


@pytest.mark.slow
def test_the_records_table_is_a_real_run():
    """The design widths of docs/records.md's table, computed again: the bundled records, and the
    real ones where ../shared is beside the checkout (text files read as their comments say)."""
    import importlib.resources

    import pulses
    import rocking

    text_options = {"units": "cm/s2", "dt": 0.005, "column": 1}
    checked = 0
    for row in _records_table():
        file, stated = row["file"].strip("`"), row["design width, 7.5 m"]
        if stated == "-":
            continue
        bundled = importlib.resources.files("pipeline.data") / file
        path = bundled if bundled.is_file() else ROOT.parent / "shared" / "records" / "raw" / file
        if not path.is_file():
            continue
        rec = pulses.read_record(str(path), **(text_options if file.endswith(".txt") else {}))
        verge = rocking.required_width(7.5, rec, rule="exact").width
        width = rocking.required_width(7.5, rec, rule="exact", limit=0.5, overturning=True).width
        # the table prints 3 decimals: the widths round to it
        assert _close_to_printed(stated.split()[0], width), (file, width, stated)
        assert _close_to_printed(row["verge, 7.5 m"].split()[0], verge), (file, verge, row["verge, 7.5 m"])
        checked += 1
    assert checked >= 5  # at least the bundled records
