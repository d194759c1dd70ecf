"""The answer of ``pipeline run`` in words: the table printed at the end of a run (its cells also
make the batch table of ``report.html``), the lines of each column's verdict over the suite, and the
fine print of what the design width keeps in reserve and what was tested above it.  Made from the
rows of ``design.csv`` and ``summary.csv`` (:mod:`pipeline.reports.design_table`).
"""
from __future__ import annotations

from .cells import display
from .design_table import RISK_COLUMNS, _whole, number, verdict_text


def _yes(value, yes="yes", no="no"):
    if value is None:
        return "-"
    return yes if value else no


def _m(value):
    v = number(value)
    return "-" if v is None else f"{v:.3f}"


def excess_text(value, reference) -> str | None:
    """``+2.5 %``: how far the width ``value`` lies above the ``reference`` width (the search
    width, in the reports), relative to it.

    Whole percent from 10 % (``+25 %``), tenths from 1 % (``+2.5 %``), hundredths below
    (``+0.25 %``, ``+0.02 %``) and ``<+0.01 %`` below 0.01 %, so that a failing width a hair above
    the reference never reads as ``+0.0 %``.  None when either is blank or ``value`` is not
    above ``reference``.
    """
    v, ref = number(value), number(reference)
    if v is None or ref is None or ref <= 0 or v <= ref:
        return None
    pct = 100.0 * (v - ref) / ref
    if pct < 0.01:
        return "<+0.01 %"
    return f"+{pct:.{0 if pct >= 10 else 1 if pct >= 1 else 2}f} %"


def failing_text(value, reference, unit=" m") -> str | None:
    """``0.608 m (+2.5 %)``: a failing width with how far it lies above ``reference``
    (:func:`excess_text`; metres only where that is blank); None where ``value`` is blank.
    ``unit=""`` gives ``0.608 (+2.5 %)`` for a column headed in metres."""
    v = number(value)
    if v is None:
        return None
    excess = excess_text(v, reference)
    return f"{v:.3f}{unit}" + (f" ({excess})" if excess else "")


def pulse_text(row) -> str:
    """``sine +0.71g 0.80s``: the governing pulse of a design row."""
    shape, ap, tp = row.get("governing_shape"), number(row.get("governing_ap_g")), number(row.get("governing_tp_s"))
    if not shape or ap is None or tp is None:
        return "-"
    return f"{shape} {ap:+.2f}g {tp:.2f}s"


def survives_text(row) -> str:
    """The printed verdict of the column as it stands (:func:`verdict_text`, ``yes`` for survives,
    the level's value for ``NO: exceeds level``), with ``passes alpha`` where the column does not
    overturn but its max|theta|/alpha reaches 1 (it passes its slenderness angle and comes
    back)."""
    text = row.get("verdict") or verdict_text(row)
    text = {"survives": "yes", "NO: exceeds level": f"NO: exceeds {number(row.get('design_limit')) or 0:g}"}.get(text, text)
    ratio = number(row.get("max_theta_ratio"))
    if text not in ("-", "NO") and ratio is not None and ratio >= 1.0:
        text = "NO: passes alpha" if text.startswith("NO: exceeds") else text + ", passes alpha"
    return text


def passes_text(ratio) -> str:
    """``, passes alpha`` where ``ratio`` (max|theta|/alpha of a column that does not overturn) is
    1 or more: the column passes its slenderness angle and comes back; else ``""``."""
    r = number(ratio)
    return ", passes alpha" if r is not None and r >= 1.0 else ""


def eq31_text(row) -> str:
    """``2.441 m``, or ``0.400 m BELOW`` where the Eq. 31 width is below the design width (``,
    overturns`` where its design overturns under the record; ``, passes alpha`` where it does not
    but passes its slenderness angle, ``eq31_width_max_theta_ratio`` where the row has it)."""
    text = _m(row.get("eq31_width_m"))
    if text == "-":
        return text
    text += " m"
    if row.get("eq31_below_design"):
        text += " BELOW" + (", overturns" if row.get("eq31_width_overturns") else "")
    if not row.get("eq31_width_overturns"):
        text += passes_text(row.get("eq31_width_max_theta_ratio"))
    return text


def design_text(row) -> str:
    """``1.907 m``: the design width (`` (vertical)`` where the vertical governs, ``, passes
    alpha`` where a column of it passes its slenderness angle)."""
    w = number(row.get("design_width_m"))
    if w is None:
        return "-"
    return (f"{w:.3f} m" + (" (vertical)" if row.get("design_governed_by") == "with vertical" else "")
            + passes_text(row.get("design_max_theta_ratio")))


def verge_text(row) -> str:
    """``1.683 m, passes alpha``: the verge beside a level's design width (the overturning design
    width, no margin), with whether a column of it passes its slenderness angle."""
    w = number(row.get("overturning_width_m"))
    if w is None:
        return "-"
    return f"{w:.3f} m" + passes_text(row.get("overturning_max_theta_ratio"))


HEADERS = ("record", "column", "pulse-like", "governing pulse", "Eq.31 width", "design width",
           "search width", "survives")
#: the heading of the column added under a performance level (the default): the verge beside the
#: design width
VERGE_HEADER = "verge (no margin)"
#: the heading of the column added where a run used vertical components
VERTICAL_HEADER = "with vertical"


def table_cells(row) -> tuple[str, ...]:
    """The printed cells of one design row (also the batch table of ``report.html``): those of
    :data:`HEADERS`, with the verge after the design width where the row has the margin's columns
    (a performance level)."""
    name = display(row["record"])
    d = number(row.get("direction_deg"))
    if d is not None and (row.get("n_directions") or 1) > 1:
        name += f" @{d:.0f}deg"
    verge = (verge_text(row),) if "overturning_max_theta_ratio" in row else ()
    return (name, display(row.get("column") or "-"), _yes(row.get("pulse_like")), pulse_text(row),
            eq31_text(row), design_text(row)) + verge + (search_text(row), survives_text(row))


def headers_for(rows) -> tuple[str, ...]:
    """The printed table's headings for ``rows`` (:data:`HEADERS`, with :data:`VERGE_HEADER` after
    the design width under a level)."""
    if rows and "overturning_max_theta_ratio" in rows[0]:
        k = HEADERS.index("design width") + 1
        return HEADERS[:k] + (VERGE_HEADER,) + HEADERS[k:]
    return HEADERS


def search_text(row) -> str:
    """``0.584 m (-9.2 %)``: the search's first transition, with how far the design width lies
    above it (``-`` where blank)."""
    w = number(row.get("search_width_m"))
    if w is None:
        return "-"
    excess = excess_text(row.get("design_width_m"), w)
    return f"{w:.3f} m" + (f" ({excess})" if excess else "")


def vertical_text(row) -> str:
    """The verdict with the vertical: ``yes``, ``NO``, ``lifts off at 2.31 s`` (never ``yes``: the
    rocking model stops where the block leaves the ground) or ``-``."""
    t = number(row.get("vertical_lift_off_s"))
    if t is not None:
        return f"lifts off at {t:.2f} s"
    return _yes(row.get("survives_vertical"), no="NO")


def metadata_text(row) -> str | None:
    """``RSN77 San Fernando 1971, Pacoima Dam: M6.61 Reverse, Rrup 1.8 km, Vs30 2016 m/s; Tp 1.64 s
    (PEER), 1.64 s (here)`` for a row of a PEER download (``summary.csv``'s ``peer_*``); None otherwise."""
    if not row.get("peer_rsn"):
        return None
    year = _whole(row["peer_year"]) if row.get("peer_year") is not None else ""
    parts = [f"RSN{_whole(row['peer_rsn'])} {row.get('peer_event') or ''} {year}".rstrip()]
    if row.get("peer_station"):
        parts[0] += f", {row['peer_station']}"
    site = []
    if number(row.get("peer_magnitude")) is not None:
        site.append(f"M{number(row['peer_magnitude']):.2f}" + (f" {row['peer_mechanism']}" if row.get("peer_mechanism") else ""))
    for key, label, unit in (("peer_rrup_km", "Rrup", "km"), ("peer_vs30_m_s", "Vs30", "m/s")):
        if number(row.get(key)) is not None:
            site.append(f"{label} {number(row[key]):g} {unit}")
    tp = number(row.get("peer_tp_s"))
    ours = number(row.get("velocity_tp_s"))
    if tp is not None or ours is not None:
        site.append("velocity pulse Tp " + ("-" if tp is None else f"{tp:.2f} s") + " (PEER), "
                    + ("-" if ours is None else f"{ours:.2f} s") + " (here)")
    return display(parts[0] + (": " + ", ".join(site) if site else ""))


#: the printed columns right-aligned (widths, aligned on the decimal point)
_RIGHT = ("Eq.31 width", "design width", VERGE_HEADER, "search width")


def _align_failing(body, col):
    """``body`` with the cells of column ``col`` (``0.608 m (+2.5 %)`` or ``-``) padded so that
    their metres line up on the decimal point and their percentages start in one place."""
    parts = [c[col].partition(" (") for c in body]
    head = max((len(h) for h, _, _ in parts), default=0)
    tail = max((len(sep + t) for _, sep, t in parts), default=0)
    return [c[:col] + (h.rjust(head) + (sep + t).ljust(tail),) + c[col + 1:]
            for c, (h, sep, t) in zip(body, parts)]


def _key(row, record="record"):
    return row.get(record) if record == "record" else (row.get("pair") or row.get("record")), row.get("column"), \
        number(row.get("direction_deg"))


def eq31_ratios(summary) -> dict:
    """``{(record or pair, column, direction): max|theta|/alpha of the Eq. 31 design}`` of the rows
    of ``summary.csv``, for :func:`eq31_text` on the design rows."""
    return {_key(r, "pair"): r.get("eq31_width_max_theta_ratio") for r in summary}


def with_eq31_ratio(row, ratios) -> dict:
    """A design row with ``eq31_width_max_theta_ratio`` (from :func:`eq31_ratios`) for its cells."""
    return {**row, "eq31_width_max_theta_ratio": ratios.get(_key(row))}


def table_text(rows, failures=(), summary=()) -> str:
    """The compact table printed at the end of ``pipeline run``: every design row, then every failed
    record (``failures``: rows of ``failures.csv``) with its reason, then the search report's
    metadata of each record of a PEER download (``summary``: rows of ``summary.csv``)."""
    headers = headers_for(rows)
    ratios = eq31_ratios(summary)
    body = [table_cells(with_eq31_ratio(r, ratios)) for r in rows]
    if any(r.get("survives_vertical") is not None for r in rows):
        # the verdict with the vertical, and the design width with it (the widest over a pair's
        # directions, from summary.csv's rows) beside the horizontal one
        widths = {}
        for r in summary:
            key = (r.get("pair") or r.get("record"), r.get("column"))
            w = number(r.get("vertical_design_width_m"))
            if w is not None:
                widths[key] = max(w, widths.get(key, w))
        headers = headers + (VERTICAL_HEADER,)
        body = [c + (vertical_text(r) + (f", design {widths[(r['record'], r.get('column'))]:.3f} m"
                                          if (r["record"], r.get("column")) in widths else ""),)
                for c, r in zip(body, rows)]
    body = _align_failing(body, headers.index("search width"))
    widths = [max([len(h)] + [len(c[i]) for c in body]) for i, h in enumerate(headers)]
    right = {i for i, h in enumerate(headers) if h in _RIGHT}  # widths, aligned on the decimal point

    def line(cells):
        return "  ".join(c.rjust(w) if i in right else c.ljust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    lines = [line(headers), line(["-" * w for w in widths])]
    lines += [line(c) for c in body]
    for f in failures:
        lines.append(f"{display(f['record'])}  failed ({f['stage']}): {' '.join(display(f['reason']).split())}")
    lines += [""] + verdict_lines(rows) + [t for t in (governing_print(rows, summary), fine_print(rows)) if t]
    seen = {}
    for r in summary:
        text = metadata_text(r)
        if text:
            seen.setdefault(r.get("pair") or r.get("record"), text)
    if seen:
        lines.append("")
        lines += [f"{display(name)}: {text}" for name, text in seen.items()]
    return "\n".join(lines) + "\n"


def _count(rows, key, value=True) -> int:
    return sum(1 for r in rows if r.get(key) == value)


def verdict_lines(rows) -> list[str]:
    """The lines that end a run (and head ``report.html``): per column, the suite's answer (the
    design width covering every record), the Eq. 31 line, then the fine print of the design width."""
    by_column = {}
    for r in rows:
        by_column.setdefault(r.get("column"), []).append(r)
    out = []
    for column, group in by_column.items():
        widths = [(number(r.get("design_width_m")), r) for r in group]
        widths = [(w, r) for w, r in widths if w is not None]
        if not widths:
            continue
        top, gov = max(widths, key=lambda wr: wr[0])
        n = len(group)
        limit = number(gov.get("design_limit"))
        level = "" if limit is None else f" for max theta/alpha <= {limit:g}"
        line = (f"Suite, column {display(column)}: the design width covering all {n} record(s) is "
                f"{top:.3f} m{level} (set by {display(gov['record'])})")
        verges = [v for v in (number(r.get("overturning_width_m")) for r in group) if v is not None]
        if verges:
            line += f"; the verge (no margin) is {max(verges):.3f} m"
        if gov.get("width_m") is not None:
            safe = _count(group, "verdict", "NO: safe island")
            fails = _count(group, "verdict", "NO")
            exceed = _count(group, "verdict", "NO: exceeds level")
            line += (f"; as it stands ({number(gov['width_m']):.3f} m) it "
                     + ("passes: it survives every record" if not (safe or fails or exceed) and top <= number(gov["width_m"])
                        else f"FAILS: {fails} record(s) overturn it"
                        + ("" if limit is None else f", {exceed} exceed the level")
                        + f", {safe} leave it on a safe island"))
        out.append(line + risk_words(gov))
        out.append(eq31_line(group))
        out += _friction_line(column, group)
    return out


def eq31_line(group) -> str:
    """The Eq. 31 line of one column's design rows: how often its width is below the design width,
    and how often a column of that width overturns under its record."""
    n = len(group)
    below = _count(group, "eq31_below_design")
    over = _count(group, "eq31_width_overturns")
    return (f"Eq. 31 is below the design width on {below} of {n} record(s); a column of Eq. 31's width "
            f"overturns under {'none' if not over else f'{over} of them'}.")


def governing_print(rows, summary) -> str | None:
    """Why the governing pulse is not the best fit, where it is not on some record: the rule, and
    the records (``rows``: design rows, ``summary``: summary.csv's, whose ``pulse_shape`` is the
    best fit)."""
    best = {}
    for r in summary:
        key = (r.get("pair") or r.get("record"), r.get("column"), r.get("direction_deg"))
        best.setdefault(key, r.get("pulse_shape"))
    others = []
    for r in rows:
        shape = best.get((r.get("record"), r.get("column"), r.get("direction_deg")))
        if shape and r.get("governing_shape") and shape != r["governing_shape"]:
            others.append(f"{display(r['record'])} fits {shape} best")
    if not others:
        return None
    shown = "; ".join(dict.fromkeys(others[:3])) + ("; ..." if len(others) > 3 else "")
    return ("Governing pulse: of the shapes that fit almost as well as the best (a score at least 0.7 "
            "of its), the one whose Eq. 31 width is widest, since shapes that fit almost equally well "
            "can ask for very different columns; so it is not always the best fit "
            f"({len(others)} of {len(rows)} row(s) here: {shown}).")


def risk_words(row) -> str:
    """``; at the site it fails at 2.1e-04/yr; the width for the site's target rate is 2.140 m``
    from a design row's risk columns ("" without ``--hazard``; risk.csv says more)."""
    rate, width = (number(row.get(k)) for k in RISK_COLUMNS.names)
    text = ""
    if rate is not None:
        text += f"; at the site it fails at {rate:.2e}/yr"
    if width is not None:
        text += f"; the width for the site's target rate is {width:.3f} m"
    return text


def _friction_line(column, group) -> list[str]:
    """With ``--friction``: how many records make the column slide (outside the model)."""
    judged = [r for r in group if r.get("slides") is not None]
    if not judged:
        return []
    demand = max((number(r.get("friction_demand")) or 0.0) for r in judged)
    n = _count(judged, "slides")
    return [f"Friction, column {display(column)}: {n} of {len(judged)} record(s) make it slide "
            f"(as it stands or at its design width: outside the rocking model, see validity); "
            f"the rocking needs up to {demand:.3g}."]


def check_reach_words() -> str:
    """How far above the search width the check looks, in words ("1.5 times it";
    ``rocking.search.SearchSettings.check_span``)."""
    from rocking.search import DEFAULT_SETTINGS

    span = float(DEFAULT_SETTINGS.check_span)
    return "twice it" if span == 2.0 else f"{span:g} times it"


def check_bin_words() -> str:
    """The width of the check's bins, relative to the search width, in words ("0.5 %";
    ``rocking.search.SearchSettings.check_bin_width``)."""
    from rocking.search import DEFAULT_SETTINGS

    return f"{100.0 * float(DEFAULT_SETTINGS.check_bin_width):g} %"


def margin_print(rows) -> str:
    """What the design width keeps in reserve: under a level, the dependable width and the verge
    beside it; with ``--limit none``, that the design width is the verge; and where a quoted
    width lets the column pass its slenderness angle."""
    limits = {number(r.get("design_limit")) for r in rows if r.get("design_width_m") is not None}
    if not limits:
        return ""
    if limits == {None}:
        return ("Margin: none, the design width is the verge of overturning (--limit none): at it "
                "a column may pass its slenderness angle (max theta/alpha >= 1) and come back; "
                "without --limit the design width keeps max theta/alpha <= 0.5 (docs/design.md). ")
    shown = ", ".join(f"{v:g}" for v in sorted(v for v in limits if v is not None))
    passes = sum(1 for r in rows if passes_text(r.get("overturning_max_theta_ratio")))
    return (f"Margin: the design width keeps max theta/alpha <= {shown} under the record (0.5: the "
            "dependable design, peaks at or below alpha/2) and is at least the verge. Verge (no "
            "margin): the narrowest width found not to overturn; where the level governs it is "
            "checked only above the design width (--limit none checks it in full: it lies between "
            "the two)" + (f"; at the verge the column passes its slenderness angle on {passes} of "
                          f"{len(rows)} row(s) (passes alpha)" if passes else "") + ". ")


def fine_print(rows) -> str | None:
    """What the design width keeps in reserve (:func:`margin_print`) and what was tested above it
    (None where no check ran)."""
    runs = [number(r.get("check_runs")) for r in rows if number(r.get("check_runs"))]
    if not runs:
        return margin_print(rows).strip() or None
    return (margin_print(rows) + "Design width: at least every width the search and the check above it found to "
            f"fail, refined just above the widest; the check ran {min(runs):.0f}"
            + (f"-{max(runs):.0f}" if max(runs) > min(runs) else "")
            + f" widths per record from the search width up to {check_reach_words()} (or the "
            "no-uplift width), more where the response varied from one width to the next; thinner "
            "failing slivers may remain (docs/slivers.md). Search width: the "
            "search's first transition, with how far the design width lies above it.")
