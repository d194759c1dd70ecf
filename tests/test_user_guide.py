"""The user guide reads as a user's guide: each page opens with a worked example (a command or
Python with its output) within its first 40 lines, and no page of the documentation tells the
history of the package (issue numbers, earlier versions, "used to", "this round"): that is the
CHANGELOG's, and the measurements are the validation pages'."""
from __future__ import annotations

import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

#: a worked example starts within this many lines of the page's top
FIRST_LINES = 40

#: the pages a user reads to do a job: each opens with a worked example
USER_GUIDE = [
    "records", "fitting", "classification", "solver", "design", "site", "peer", "slivers",
    "risk", "validity",
]

#: what tells history rather than what the package does (case-insensitive).  A station's number
#: (El Centro #6) is not an issue's; a number with a unit after "since" is a value, not a version
HISTORY = re.compile("|".join([
    r"\bissues?\b",                          # the tracker's business, not the user's
    r"(?<![\w/])#\d{2,}\b",                  # #34
    r"\b0\.\d+\.(?:\d+|x)\b",                # 0.5.0, 0.1.x
    r"\b0\.\d+'s\b",                         # 0.6's check
    r"\b(?:before|since|until|after) (?:version )?0\.\d{1,2}\b(?![-\d])(?!\s?(?:%|(?:g|s|m|x|rad|Hz|times)\b))",
    r"\bversion \d",
    r"\b(?:earlier|previous|older|old|former) (?:version|release|layout|default|rule|round)s?\b",
    r"\bthe former\b", r"\bformerly\b", r"\bused to\b", r"\bthis round\b", r"\bprevious round\b",
]), re.I)


def history_mentions(text: str) -> list[str]:
    """Each line of ``text`` that mentions an issue or an earlier version, with what matched."""
    return [f"line {n}: {m.group(0)!r} in {line.strip()[:100]!r}"
            for n, line in enumerate(text.splitlines(), 1) for m in HISTORY.finditer(line)]


def first_example_line(text: str) -> int | None:
    """The line (from 1) where the page's first worked example shows its output: the first output
    line of a doctest block, or of a console block (a ``$`` command and what it printed)."""
    lines = text.splitlines()
    fence, kind = None, None
    for n, line in enumerate(lines, 1):
        stripped = line.strip()
        if fence is None:
            m = re.match(r"^(`{3,}|~{3,})\s*(\{doctest\}|console|pycon|python)?", stripped)
            if m and stripped.startswith(m.group(1)):
                fence, kind, prompt_seen = m.group(1), m.group(2) or "", False
            continue
        if stripped.startswith(fence):
            fence = None
            continue
        if kind in ("{doctest}", "pycon", "python"):
            if stripped.startswith(">>>"):
                prompt_seen = True
            elif prompt_seen and stripped and not stripped.startswith("..."):
                return n
        elif kind == "console":
            if stripped.startswith("$ "):
                prompt_seen = True
            elif prompt_seen and stripped:
                return n
    return None


def test_the_checks_read_what_they_should():
    """The two checks on made-up text: they must be able to fail."""
    assert history_mentions("the verified width before 0.5; since issue 34, see #41")
    assert history_mentions("0.3.0's run of the script") and history_mentions("it used to hop")
    assert not history_mentions("El Centro #6 at 0.5 g; before 0.5 s the block rests; since 0.25 %")
    assert not history_mentions("the rates rise with the level (0.002 at 0.2 after 0.001 at 0.1)")
    assert history_mentions("as after 0.7, the level") and history_mentions("until 0.10 it did")
    page = "# A page\n\n```{doctest}\n>>> 1 + 1\n2\n```\n"
    assert first_example_line(page) == 5
    assert first_example_line("# A page\n\n```bash\npipeline run x\n```\n") is None
    assert first_example_line("```console\n$ pipeline demo\nwrote demo-output\n```\n") == 3


@pytest.mark.parametrize("page", USER_GUIDE)
def test_user_guide_page_opens_with_an_example_and_tells_no_history(page):
    text = (DOCS / f"{page}.md").read_text(encoding="utf-8")
    line = first_example_line(text)
    assert line is not None and line <= FIRST_LINES, f"{page}.md: first example output at line {line}"
    found = history_mentions(text)
    assert not found, f"{page}.md: " + "; ".join(found)


def _other_pages():
    guide = {p if isinstance(p, str) else p.values[0] for p in USER_GUIDE}
    for path in sorted(DOCS.glob("*.md")):
        if path.stem not in guide:
            yield path.stem


@pytest.mark.parametrize("page", list(_other_pages()))
def test_no_docs_page_tells_history(page):
    """Every other page of docs/ too (validation, performance, the index ...): the history is the
    CHANGELOG's."""
    found = history_mentions((DOCS / f"{page}.md").read_text(encoding="utf-8"))
    assert not found, f"{page}.md: " + "; ".join(found)


def _other_sources():
    """The rest of what the site and the repository's first page show: the README, and the
    gallery's scripts and index (their text becomes the gallery's pages)."""
    yield ROOT / "README.md"
    yield from sorted((DOCS / "examples").glob("*.py"))
    yield from sorted((DOCS / "examples").glob("*.rst"))


@pytest.mark.parametrize("path", list(_other_sources()), ids=lambda p: p.name)
def test_readme_and_gallery_tell_no_history(path):
    found = history_mentions(path.read_text(encoding="utf-8"))
    assert not found, f"{path.relative_to(ROOT)}: " + "; ".join(found)


def _docstrings(package: str):
    """``(name, docstring)`` of each public name of ``package`` and of its classes' public members:
    the text of the API reference's pages."""
    import importlib
    import inspect

    mod = importlib.import_module(package)
    for name in mod.__all__:
        obj = getattr(mod, name)
        yield f"{package}.{name}", inspect.getdoc(obj) or ""
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_") and member != "__init__":
                    continue
                doc = inspect.getdoc(value) if (callable(value) or isinstance(value, property)) else None
                if doc:
                    yield f"{package}.{name}.{member}", doc


@pytest.mark.parametrize("package", ["pulses", "rocking", "pipeline"])
def test_api_pages_tell_no_history(package):
    """The API reference is written from the public names' docstrings: they too say what the code
    does, not how it came to be."""
    found = [f"{name}: {hit}" for name, doc in _docstrings(package) for hit in history_mentions(doc)]
    assert not found, "; ".join(found)
