"""The README and the documentation: the first page's shape, its example run, and the Sphinx site
built with warnings as errors, its examples run (``sphinx.ext.doctest``)."""
from __future__ import annotations

import pathlib
import re
import subprocess
import sys

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
    from pipeline import design_table

    text = README.read_text(encoding="utf-8")
    table = re.search(r"^```text\n(record .*?)^pipeline run: ", text, re.S | re.M).group(1)
    head = table.splitlines()[0]
    assert head.split("  ")[0].strip() == "record"
    for h in design_table.HEADERS:
        assert h in head


@pytest.mark.slow
def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    (code,) = _python_blocks(README.read_text(encoding="utf-8"))
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {"__name__": "readme"})
    out = capsys.readouterr().out.split("\n")
    # the values the README's comments state
    assert out[:6] == ["sine 0.59 0.9", "True", "False 0.74", "2.441", "1.683", ""]


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


def _sphinx(builder: str, out: pathlib.Path):
    pytest.importorskip("sphinx", reason="the docs extra is not installed: pip install '.[docs]'")
    pytest.importorskip("myst_parser", reason="the docs extra is not installed: pip install '.[docs]'")
    pytest.importorskip("numpydoc", reason="the docs extra is not installed: pip install '.[docs]'")
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", builder,
                           str(DOCS), str(out), "-d", str(out / ".doctrees")],
                          capture_output=True, text=True, timeout=1800)


@pytest.mark.slow
def test_docs_build_without_warnings(tmp_path):
    proc = _sphinx("html", tmp_path / "html")
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    for page in ("index", "getting-started", "commands", "theory", "validation", "performance", "api"):
        assert (tmp_path / "html" / f"{page}.html").is_file(), page
    api = (tmp_path / "html" / "api.html").read_text(encoding="utf-8")
    for name in ("pulses.fit_pulse", "pulses.classify_pulse", "rocking.simulate", "rocking.required_width"):
        assert f'id="{name}"' in api, name


@pytest.mark.slow
def test_docs_examples_run(tmp_path):
    proc = _sphinx("doctest", tmp_path / "doctest")
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    report = (tmp_path / "doctest" / "output.txt").read_text(encoding="utf-8")
    tried = sum(int(n) for n in re.findall(r"^\s*(\d+) tests?\b", report, re.M))
    failures = re.search(r"(\d+) failures? in tests", report)
    assert failures and failures.group(1) == "0", report[-2000:]
    assert tried >= 3, report[-2000:]
