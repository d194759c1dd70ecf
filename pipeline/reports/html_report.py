"""``report.html``: one page in ``--out`` on which to review a batch of ``pipeline run``.

It opens from the disk in any browser, with no server and no network: the style and the few lines
that sort the table are in the page, and the figures are the run's own PNGs, linked by relative
paths (``plots/...``), so the page stays small and a folder moved as a whole keeps working.  The
page holds the batch table (the rows of ``design.csv``; a click on a heading sorts by it), every
record with its classification, fitted pulse, verdicts and figure, the failures with their
reasons, and the summary, suite and fragility figures where the run drew them.  It depends on
nothing but the rows and files of the run (no date, no path of the machine), so a re-run writes the
same bytes.
"""
from __future__ import annotations

import html
import pathlib
import urllib.parse

from . import cells, outfiles
from .answer import (check_reach_words, design_text, eq31_ratios, eq31_text, failing_text, metadata_text,
                     fine_print, governing_print, passes_text, pulse_text, search_text, survives_text, verdict_lines,
                     verge_text, vertical_text, with_eq31_ratio)
from .design_table import number as _num
from .shapes import FIT_TOLERANCE


_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:1.5em auto;max-width:90em;
padding:0 1em;color:#222;line-height:1.4}
h1{font-size:1.5em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ccc}h3{font-size:1.05em}
table{border-collapse:collapse;font-size:.9em;margin:.5em 0}
th,td{border:1px solid #ccc;padding:.2em .5em;text-align:left;vertical-align:top}
td.n{text-align:right;font-variant-numeric:tabular-nums}
thead th{background:#f0f0f0;cursor:pointer;user-select:none}
.wide{overflow-x:auto}
thead th.asc::after{content:" \\25B2"}thead th.desc::after{content:" \\25BC"}
tr.no td{background:#fde8e8}tr.island td{background:#fff6dc}
img{max-width:100%;height:auto;border:1px solid #ddd}
.rec{margin-top:1.5em}.muted{color:#666}dl{display:grid;grid-template-columns:max-content auto;gap:.1em 1em}
dt{font-weight:600}dd{margin:0}
"""

# sorts the table whose heading is clicked: by the cells' data-v (numbers as numbers, blanks last)
_JS = """
document.querySelectorAll("table.sortable").forEach(function (table) {
  var heads = table.tHead.rows[0].cells;
  Array.prototype.forEach.call(heads, function (th, col) {
    th.addEventListener("click", function () {
      var asc = !th.classList.contains("asc");
      Array.prototype.forEach.call(heads, function (h) { h.classList.remove("asc", "desc"); });
      th.classList.add(asc ? "asc" : "desc");
      var body = table.tBodies[0], rows = Array.prototype.slice.call(body.rows);
      function key(row) {
        var v = row.cells[col].getAttribute("data-v"), x = Number(v);
        return v === "" ? null : (isNaN(x) ? v : x);
      }
      rows.sort(function (a, b) {
        var x = key(a), y = key(b);
        if (x === null || y === null) { return x === y ? 0 : (x === null ? 1 : -1); }
        if (typeof x !== typeof y) { x = String(x); y = String(y); }
        var c = x < y ? -1 : (x > y ? 1 : 0);
        return asc ? c : -c;
      });
      rows.forEach(function (r) { body.appendChild(r); });
    });
  });
});
"""



def _whole(value):
    """A count as a whole number (``1500``, not ``1500.0`` as a CSV round trip gives it)."""
    number = _num(value)
    return int(number) if number is not None and float(number).is_integer() else value

def _e(value) -> str:
    return html.escape(cells.display("" if value is None else value), quote=True)


def _sort_value(value) -> str:
    """The ``data-v`` of a cell: a number as ``repr`` (read back as that number by the page), else text."""
    v = _num(value)
    if v is not None and not isinstance(value, bool):
        return repr(v) if v != int(v) or abs(v) >= 1e15 else str(int(v))
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    return cells.display(value)


def _cell(value, shown=None, numeric=False) -> str:
    shown = _e(shown if shown is not None else ("-" if value is None else value))
    cls = ' class="n"' if numeric else ""
    return f'<td{cls} data-v="{_e(_sort_value(value))}">{shown}</td>'


def _fixed(value, digits=3, unit=""):
    v = _num(value)
    return None if v is None else f"{v:.{digits}f}{unit}"


def _yes(value):
    return "-" if value is None else ("yes" if value else "no")


def _href(rel: str) -> str:
    return urllib.parse.quote(rel, safe="/")


def _anchor(record_id) -> str:
    # "_" escaped too: "a+b" (a%2Bb) and "a_2Bb" were one anchor
    return "r-" + urllib.parse.quote(cells.display(record_id), safe="").replace("_", "%5F").replace("%", "_")


def _batch_table(design, anchors, ratios=None) -> list[str]:
    directions = any(r["direction_deg"] is not None for r in design)  # pairs in the run
    vertical = any(r.get("survives_vertical") is not None for r in design)  # verticals in the run
    verge = any("overturning_max_theta_ratio" in r for r in design)  # a performance level: the margin
    heads = ["record", "column"] + (["direction (deg)"] if directions else []) + [
        "pulse-like", "velocity Tp (s)", "governing pulse", "ap (g)", "Tp (s)", "Eq. 31 width (m)",
        "design width (m)"] + (["verge, no margin (m)"] if verge else []) + [
        "search width (m)", "widest failing width (m)", "width (m)", "survives"] + (
        ["with vertical"] if vertical else []) + ["max theta/alpha"]
    out = ['<div class="wide"><table class="sortable" id="batch"><thead><tr>'
           + "".join(f"<th>{_e(h)}</th>" for h in heads) + "</tr></thead><tbody>"]
    for r in design:
        r = with_eq31_ratio(r, ratios or {})
        surv = survives_text(r)
        cls = ' class="no"' if surv == "NO" else ' class="island"' if surv.startswith("NO:") else ""
        target = anchors.get(r["record"])
        name = _e(r["record"])
        name = f'<a href="#{target}">{name}</a>' if target else name
        out.append(
            f"<tr{cls}>"
            f'<td data-v="{_e(r["record"])}">{name}</td>'
            + _cell(r["column"])
            + (_cell(r["direction_deg"], _fixed(r["direction_deg"], 1), numeric=True) if directions else "")
            + _cell(r["pulse_like"], _yes(r["pulse_like"]))
            + _cell(r["velocity_tp_s"], _fixed(r["velocity_tp_s"], 2), numeric=True)
            + _cell(r["governing_shape"])
            + _cell(r["governing_ap_g"], _fixed(r["governing_ap_g"], 3), numeric=True)
            + _cell(r["governing_tp_s"], _fixed(r["governing_tp_s"], 3), numeric=True)
            + _cell(r["eq31_width_m"], eq31_text(r).replace(" m", ""), numeric=True)
            + _cell(r["design_width_m"], design_text(r).replace(" m", "", 1), numeric=True)
            + (_cell(r.get("overturning_width_m"), verge_text(r).replace(" m", "", 1), numeric=True) if verge else "")
            + _cell(r.get("search_width_m"), search_text(r).replace(" m", ""), numeric=True)
            + _cell(r.get("widest_failing_width_m"),
                    failing_text(r.get("widest_failing_width_m"), r.get("search_width_m"), unit=""), numeric=True)
            + _cell(r["width_m"], _fixed(r["width_m"]), numeric=True)
            + _cell(surv if r["survives"] is not None else None, surv)
            + (_cell(r.get("survives_vertical"), vertical_text(r)) if vertical else "")
            + _cell(r["max_theta_ratio"], "overturned" if r.get("survives") is False and r.get("verdict") == "NO"
                    and (_num(r["max_theta_ratio"]) or 0) > 1 else _fixed(r["max_theta_ratio"]), numeric=True)
            + "</tr>")
    out.append("</tbody></table></div>")
    return out


def _record_section(rid, rows, failure, plot, anchor, friction=None) -> list[str]:
    """The section of one record: its facts, a line per column, its failure and figures."""
    first = rows[0] if rows else {}
    out = [f'<section class="rec" id="{anchor}"><h3>{_e(rid)}</h3>']
    if first:
        out.append("<dl>" + "".join(f"<dt>{_e(k)}</dt><dd>{_e(v)}</dd>" for k, v in _facts(first)) + "</dl>")
        out.append("<ul>")
        out += [f"<li>{_e('; '.join(_row_words(r, first)))}</li>" for r in rows]
        out.append("</ul>")
    if failure:
        out.append(f'<p class="muted">failed ({_e(failure["stage"])}): {_e(failure["reason"])}</p>')
    if plot:
        out.append(f'<p><img src="{_href(plot)}" alt="{_e(rid)}: record, pulses and rotation histories"></p>')
    if friction:
        out.append(f'<p><a href="{_href(friction)}">the friction its responses need against time</a></p>')
    out.append("</section>")
    return out


def _facts(first) -> list[tuple[str, object]]:
    """``(label, value)`` of what a record's first row says of the record: its file, reading, pulse."""
    facts = [("file", first.get("file"))]
    if metadata_text(first):
        facts.append(("PEER search report", metadata_text(first)))
    if first.get("file2"):
        facts.append(("second component", first.get("file2")))
    if first.get("direction_deg") is not None:
        facts.append(("direction", f"{_fixed(first['direction_deg'], 1)} deg ({first.get('direction_kind') or ''})"))
    if _num(first.get("scale")) not in (None, 1.0):
        facts.append(("scale", first.get("scale")))
    facts += [
        ("PGA, PGV", f"{_fixed(first.get('pga_g'), 3) or '-'} g, {_fixed(first.get('pgv_m_s'), 3) or '-'} m/s "
                     "(peaks of the record's acceleration and of its velocity after the fitter's "
                     "baseline correction)"),
        ("pulse-like", f"{_yes(first.get('pulse_like'))} (indicator {_fixed(first.get('velocity_pulse_indicator'), 2) or '-'}, "
                       f"velocity Tp {_fixed(first.get('velocity_tp_s'), 2) or '-'} s, "
                       f"orientation {_fixed(first.get('orientation_deg'), 1) or '-'} deg)"
                       + (f": {first['pulse_like_reason']}" if first.get("pulse_like_reason") else "")),
        ("fitted pulse", f"{first.get('pulse_shape') or '-'}: ap {_fixed(first.get('pulse_ap_g'), 3) or '-'} g, "
                         f"Tp {_fixed(first.get('pulse_tp_s'), 3) or '-'} s, score {_fixed(first.get('pulse_score'), 2) or '-'} "
                         f"({first.get('pulse_fit') or '-'} least squares); shapes fitting almost as well (score at least "
                         f"{FIT_TOLERANCE:g} x the best): "
                         f"{first.get('shapes_fitting') or '-'}"),
    ]
    if first.get("warnings"):
        facts.append(("warnings", first.get("warnings")))
    return facts


def _row_words(r, first) -> list[str]:
    """The parts of the line of one row (one column) of a record whose first row is ``first``."""
    governs = f"column {r.get('column')}: governing pulse {pulse_text(r)}"
    if r.get("governing_shape") and r.get("governing_shape") != first.get("pulse_shape"):
        governs += (f" (not the best fit, {first.get('pulse_shape')}: of the shapes that fit, "
                    "the one asking for the widest column by Eq. 31)")
    parts = [governs,
             f"Eq. 31 width {_fixed(r.get('eq31_width_m')) or '-'} m"
             + (" (below the design width)" if (_num(r.get("eq31_width_m")) or 0) < (_num(r.get("design_width_m")) or 0) else "")
             + (" (overturns)" if r.get("eq31_width_overturns") else ""),
             f"design width {_fixed(r.get('design_width_m')) or '-'} m"
             + (f" (governed by the {r['design_governed_by']} motion)" if r.get("design_governed_by") else "")
             + (f" for max theta/alpha <= {r['design_limit']:g}" if _num(r.get("design_limit")) else
                " (--limit none: the verge of overturning, no margin)")
             + (f" (max theta/alpha {_fixed(r['design_max_theta_ratio'], 2)} there"
                + passes_text(r["design_max_theta_ratio"]) + ")"
                if _num(r.get("design_max_theta_ratio")) is not None else "")
             + _overturning_words(r),
             f"search width {_fixed(r.get('search_width_m')) or '-'} m"]
    if r.get("restitution_values_run") is not None:
        parts.append(f"restitution {r['restitution']} ({_whole(r.get('restitution_values_run'))} "
                     f"value(s) run, {r.get('restitution_governing')} governed: "
                     f"{r.get('restitution_design_widths_m')}); at the design width eta "
                     f"{_fixed(r.get('design_eta'), 4) or '-'}, r {_fixed(r.get('design_r'), 4) or '-'}")
    if r.get("check_runs"):
        share = _num(r.get("failing_share"))
        parts.append(f"check above the search width: {_whole(r.get('check_runs'))} widths up to "
                     f"{check_reach_words()} (or the no-uplift width), "
                     + (f"{100 * share:.2g} % fail, the widest at "
                        + (failing_text(r.get("widest_failing_width_m"), r.get("search_width_m")) or "-")
                        + " (the design width lies just above it)"
                        if share else "none fails"))
    parts += _as_stands_words(r)
    if r.get("validity"):
        parts.append(f"model: {r['validity']}")
    return parts


def _as_stands_words(r) -> list[str]:
    """The verdicts of a row's column as it stands (without and with the vertical); none for a
    height only."""
    if r.get("column_kind") != "block":
        return []
    surv = survives_text({"survives": None if r.get("overturns") is None else not r["overturns"],
                          "design_adequate": r.get("design_adequate"),
                          "max_theta_ratio": r.get("max_theta_ratio")})
    verdict = {"yes": "survives", "NO": "overturns",
               "NO: safe island": "NO: survives only on a safe island (narrower than the design width)"}
    parts = [f"as it stands: {verdict.get(surv, surv)}"
             + ("" if r.get("overturns") else f", max theta/alpha {_fixed(r.get('max_theta_ratio')) or '-'}")]
    if r.get("vertical_overturns") is not None:
        lift = _num(r.get("vertical_t_lift_off_s")) if r.get("vertical_lifts_off") else None
        said = ("overturns" if r["vertical_overturns"] else
                "survives" if lift is None else
                f"lifts off at {lift:.2f} s (the ground falls faster than gravity: the rocking "
                "model stops there, no verdict)")
        parts.append(f"with the vertical ({r.get('vertical_model') or '-'}): {said}"
                     + f", max theta/alpha {_fixed(r.get('vertical_max_theta_ratio')) or '-'}")
    return parts


def _overturning_words(r) -> str:
    """Under a level: the verge (no margin) beside the design width, and what it is (in full where
    it sets the design width, else the part established: it is refined only where it can change
    the design width)."""
    over, design = _num(r.get("overturning_width_m")), _num(r.get("design_width_m"))
    if over is None:
        return ""
    there = (f" (max theta/alpha {_fixed(r['overturning_max_theta_ratio'], 2)} there"
             + passes_text(r["overturning_max_theta_ratio"]) + ")"
             if _num(r.get("overturning_max_theta_ratio")) is not None else "")
    if design is None or over >= design:
        return (f", set by the overturning design width {_fixed(over)} m, the verge (no margin){there}: "
                "a width that overturns fails every level")
    return (f", above the verge (no margin), the overturning design width (at least {_fixed(over)} m: "
            f"refined only as far as it could change the design width){there}")


def report_html(design, rows, failures, record_ids, figures, title="pipeline run") -> str:
    """The page.

    Parameters
    ----------
    design : list of dict
        Rows of ``design.csv`` (:func:`pipeline.reports.design_table.design_rows`).
    rows : list of dict
        Rows of ``summary.csv``.
    failures : list of dict
        Rows of ``failures.csv``.
    record_ids : list of str
        Every record of the run, in input order (failed ones too).
    figures : dict
        ``{record id or "summary", "suite", "fragility": path relative to --out}`` of the figures
        the run wrote.
    """
    by_record = {}
    for r in rows:
        by_record.setdefault(r["record"], []).append(r)
    failed = {f["record"]: f for f in failures}
    anchors = {rid: _anchor(rid) for rid in record_ids}
    # a pair's row in the batch table links to its first direction
    pair_anchor = {}
    for r in rows:
        pair_anchor.setdefault(r.get("pair") or r["record"], anchors.get(r["record"]))
    n_ok = len([rid for rid in record_ids if rid in by_record and rid not in failed])
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           '<meta name="viewport" content="width=device-width, initial-scale=1">',
           f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
           f"<h1>{_e(title)}</h1>"]
    out += [f'<p class="verdict"><b>{_e(line)}</b></p>' for line in verdict_lines(design)]
    out += [f'<p class="muted">{_e(t)}</p>' for t in (governing_print(design, rows), fine_print(design)) if t]
    out += [
           f"<p>{len(record_ids)} records, {len(failures)} failed. Files: "
           + ", ".join(f'<a href="{_href(f)}">{_e(f)}</a>' for f in
                       ("design.csv", "summary.csv", "failures.csv", "columns.md"))
           + ". Click a heading to sort the table. Rows in red: the column as it stands overturns; "
             "in yellow: it survives only on a safe island (a slightly wider column overturns) or rocks "
             "past the level, flagged like a failure.</p>",
           "<h2>Designs</h2>"]
    out += _batch_table(design, pair_anchor, eq31_ratios(rows))
    if failures:
        out.append(f'<h2 id="failures">Failures ({len(failures)})</h2>')
        out.append('<table class="sortable" id="failed"><thead><tr><th>record</th><th>file</th><th>stage</th>'
                   "<th>error</th><th>reason</th></tr></thead><tbody>")
        for f in failures:
            out.append("<tr>" + "".join(_cell(f.get(k)) for k in ("record", "file", "stage", "error", "reason"))
                       + "</tr>")
        out.append("</tbody></table>")
    site = [(k, label) for k, label in (("summary", "Required against actual slenderness"),
                                        ("suite", "Suite: share of records whose design width a column of width B reaches"),
                                        ("fragility", "Collapse fragility"),
                                        ("risk_widths", "Risk at the site: annual rate of failure against the width"),
                                        ("risk_disaggregation", "Risk at the site: where the rate comes from"))
            if figures.get(k)]
    if site:
        out.append("<h2>Batch figures</h2>")
        for k, label in site:
            out.append(f"<h3>{_e(label)}</h3><p><img src=\"{_href(figures[k])}\" alt=\"{_e(label)}\"></p>")
    out += _validity_section(rows, figures)
    out.append(f"<h2>Records ({n_ok} processed)</h2>")
    for rid in record_ids:
        out += _record_section(rid, by_record.get(rid, []), failed.get(rid), figures.get(("record", rid)),
                               anchors[rid], friction=figures.get(("friction", rid)))
    out.append(f"<script>{_JS}</script></body></html>")
    return "\n".join(out) + "\n"


def figures_in(out, record_ids, plots: bool, names: dict) -> dict:
    """The figures of the run present in ``out``: ``names`` maps ``"summary"``, ``"suite"``,
    ``"fragility"`` to their paths; records' figures are ``plots/<record>.png``."""
    out = pathlib.Path(out)
    found = {}
    if not plots:
        return found
    for key, rel in names.items():
        if (out / rel).is_file():
            found[key] = rel
    for rid in record_ids:
        rel = outfiles.record_plot_name(rid)
        if (out / rel).is_file():
            found[("record", rid)] = rel
        rel = outfiles.record_friction_plot_name(rid)
        if (out / rel).is_file():
            found[("friction", rid)] = rel
    return found


def _validity_section(rows, figures) -> list[str]:
    """Where the model holds: the governing record's (the widest design width's) checks and the
    friction its responses need against time."""
    judged = [r for r in rows if r.get("validity")]
    if not judged:
        return []
    gov = max(judged, key=lambda r: _num(r.get("design_width_m")) or 0.0)   # first of the widest
    rid = gov["record"]
    out = ['<h2 id="validity">Where the rocking model holds</h2>',
           f"<p>Governing record {_e(rid)} (column {_e(gov.get('column'))}, the widest design "
           f"width, {_fixed(gov.get('design_width_m')) or '-'} m): {_e(gov['validity'])}.</p>"]
    failed = [r for r in judged if "FAILED" in str(r.get("validity"))]
    if failed:
        out.append(f"<p><b>{len(failed)} of {len(judged)} rows leave the model</b> (friction or "
                   "lift-off; their `validity` says which and when).</p>")
    if figures.get(("friction", rid)):
        out.append(f'<p><img src="{_href(figures[("friction", rid)])}" alt="{_e(rid)}: friction '
                   'needed against time"></p>')
    return out

