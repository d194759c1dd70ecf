"""Risk at a site in ``pipeline run``: ``--hazard FILE`` and its options, and the risk files.

After the batch, each column's suite (every record with results; a pair by the directions the run
designed for, measured by its RotD50) is assessed against the site's hazard curve by
:func:`rocking.risk.site.assess`: the annual rate of overturning of each ``--block`` column as it
stands (and of the level a ``--limit R`` names, as ``--fragility``'s), and with ``--target-rate`` or ``--target-poe`` the width
for the target of every column.  Files: ``risk.csv``, ``risk_records.csv``, ``risk_widths.csv``,
``risk_disaggregation.csv``, ``fragility.xml`` (OpenQuake NRML) and with plots
``plots/risk_widths.png`` and ``plots/risk_disaggregation.png``.  The hazard file is read and
checked with the arguments: a bad curve is a one-line argument error before any work.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..values import ArgumentError, as_number, as_whole
from ..reports.outfiles import (FRAGILITY_XML, RISK_CSV, RISK_DISAGG_CSV, RISK_DISAGG_PLOT,  # noqa: F401
                                RISK_RECORDS_CSV, RISK_WIDTHS_CSV, RISK_WIDTHS_PLOT)


@dataclass(frozen=True)
class RiskOptions:
    """``--hazard`` and its options, checked: the site's curve, the target (annual rate, and as
    given), ``--years``, ``--age``, the restitution and its seed."""

    path: str
    curve: object
    target_rate: float | None = None
    target_text: str | None = None
    years: float = 50.0
    age: float | None = None
    restitution: object = None
    seed: int = 0


def _positive(value, what):
    """``value`` (a number, or text read as one) if positive and finite, else an ArgumentError."""
    try:
        v = as_number(value)
    except ValueError:
        raise ArgumentError(f"{what}: expected a number, got {value!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise ArgumentError(f"{what} must be a positive number, got {value!r}")
    return v


def risk_options(hazard, *, site=None, site_row=None, imt=None, units=None, years=50, age=None,
                 target_rate=None, target_poe=None, restitution=None, seed=0) -> RiskOptions:
    """:class:`RiskOptions` from values (``pipeline.design(..., hazard=)`` and the command line);
    :class:`pipeline.values.ArgumentError` in one line for anything wrong, the curve included."""
    from rocking.restitution import Restitution
    from rocking.risk import HazardError, read_hazard
    from rocking.risk.curve import HazardCurve
    from rocking.risk.rate import parse_poe, rate_for

    if site_row is not None:
        try:
            site_row = as_whole(site_row)
        except ValueError:
            raise ArgumentError(f"--site-row: expected a whole number from 1, got {site_row!r}") from None
    try:
        curve = hazard if isinstance(hazard, HazardCurve) else read_hazard(
            hazard, site=site, site_row=site_row, imt=imt, units=units)
        rest = None if restitution is None else Restitution.parse(restitution)
        rate, text = None, None
        if target_rate is not None and target_poe is not None:
            raise ValueError("give --target-rate or --target-poe, not both")
        if target_rate is not None:
            rate = _positive(target_rate, "--target-rate")
            text = f"{rate:g}/yr"
        elif target_poe is not None:
            p, n = parse_poe(target_poe)
            rate, text = rate_for(p, n), f"{100 * p:g}% in {n:g} years"
        seed = as_whole(seed)
    except (HazardError, ValueError) as exc:
        raise ArgumentError(str(exc)) from None
    return RiskOptions(str(getattr(curve, "source", "") if isinstance(hazard, HazardCurve) else hazard),
                       curve, rate, text, _positive(years, "--years"),
                       None if age is None else _positive(age, "--age"), rest, seed)


# -- after the run: each column's suite against the curve -------------------------------------------
def suite_of(tasks, rows, measure, say):
    """``(members, skipped)``: one :class:`rocking.risk.suite.Member` per record (pair) of the run
    with results, its components the directions designed for; a pair measured by the RotD50 of two
    of its directions 90 deg apart (the pair's own, whichever two)."""
    from pulses.intensity import intensity, rotd
    from rocking.risk.suite import Member

    from . import site
    from .read import horizontal_only, read_task

    done = {r["record"] for r in rows}
    groups = {}
    for t in tasks:
        if t.record_id in done:
            groups.setdefault(site.pair_of(t), []).append(t)
    members, skipped = [], []
    for pair, ts in groups.items():
        try:
            comps = [read_task(horizontal_only(t))[0] for t in ts]
            if ts[0].direction is None:
                im = intensity(comps[0], measure)
            else:
                by_angle = {round(t.direction % 180.0, 6): c for t, c in zip(ts, comps)}
                a = next((d for d in by_angle if round((d + 90.0) % 180.0, 6) in by_angle), None)
                if a is None:
                    raise ValueError("no two directions 90 deg apart to measure the pair's RotD50")
                im = rotd(by_angle[a], by_angle[round((a + 90.0) % 180.0, 6)], measure)
            members.append(Member(pair, tuple(comps), im))
        except Exception as exc:  # a record read once already: say why it is left out, go on
            skipped.append((pair, str(exc)))
            say(f"pipeline run: --hazard: {pair} left out of the risk: {exc}")
    return members, skipped


def assess_columns(tasks, rows, options, jobs, say):
    """``{column label: RiskResult or error text}`` for every column of the run."""
    from rocking.risk.site import assess

    ro = options.risk
    suite, _ = suite_of(tasks, rows, ro.curve.measure, say)
    out = {}
    columns = tasks[0].columns if tasks else ()
    for col in columns:
        try:
            if len(suite) < 2:
                raise ValueError(f"{len(suite)} record(s) with results; a fragility needs at least two")
            if col.width is None and ro.target_rate is None:
                raise ValueError("a column given by its height only: give --target-rate or --target-poe")
            out[col.label] = assess(suite, ro.curve, height=col.height, width=col.width,
                                    target_rate=ro.target_rate, years=ro.years, age=ro.age,
                                    limit=options.fragility_limit, restitution=ro.restitution, seed=ro.seed,
                                    cap_mass_ratio=options.cap_mass_ratio, jobs=jobs or 1, body=col.body)
        except ValueError as exc:
            out[col.label] = str(exc)
            say(f"pipeline run: --hazard: column {col.label}: {exc}")
    return out


def write_outputs(outputs, tasks, rows, options, render=None, jobs=1, say=print):
    """Write the risk files (nothing without ``--hazard``); return ``({column: answer}, rows of
    risk.csv)``: the answers for design.csv and the printed answer (:func:`answer_fields`)."""
    from rocking.risk import nrml, rows as risk_rows

    from ..reports import columns
    from ..reports.figures import draw

    if getattr(options, "risk", None) is None:
        return {}, []
    render = render or draw
    results = assess_columns(tasks, rows, options, jobs, say) if rows else {}
    done = [r for r in results.values() if not isinstance(r, str)]
    tables = {RISK_CSV: (risk_rows.RISK_COLUMNS, lambda r: r.rows()),
              RISK_RECORDS_CSV: (risk_rows.RECORD_COLUMNS, lambda r: r.record_rows()),
              RISK_WIDTHS_CSV: (risk_rows.WIDTH_COLUMNS, lambda r: r.width_rows()),
              RISK_DISAGG_CSV: (risk_rows.DISAGGREGATION_COLUMNS, lambda r: r.disaggregation_rows())}
    made = {}
    for name, (cols, make) in tables.items():
        made[name] = [row for r in done for row in make(r)]
        if name == RISK_CSV:
            made[name] += [_error_row(label, text, options) for label, text in results.items()
                           if isinstance(text, str)]
        outputs.write(name, columns.csv_text(list(cols.names), made[name]))
    functions = [f for f in (nrml.functions_of(r, label) for label, r in results.items()
                             if not isinstance(r, str) and r.width is not None) if f is not None]
    if functions:
        outputs.write(FRAGILITY_XML, nrml.nrml_text(functions))
    elif outputs.owned(FRAGILITY_XML):
        outputs.remove(FRAGILITY_XML)
    if options.plots:
        outputs.write(RISK_WIDTHS_PLOT, render("risk:widths_figure_png", made[RISK_WIDTHS_CSV],
                                               made[RISK_CSV]))
        c = options.risk.curve
        outputs.write(RISK_DISAGG_PLOT, render("risk:disaggregation_figure_png",
                                               made[RISK_DISAGG_CSV], f"{c.measure} ({c.units})"))
    return {label: answer_fields(r, options) for label, r in results.items()}, made[RISK_CSV]


def _error_row(label, text, options):
    from rocking.risk.rows import RISK_COLUMNS

    row = dict.fromkeys(RISK_COLUMNS.names)
    row.update({"column": label, "what": "error", "measure": options.risk.curve.measure,
                "note": text})
    return row


def answer_fields(result, options) -> dict:
    """The risk columns of design.csv (pipeline.reports.design_table.RISK_COLUMNS) of one column,
    and the words of the printed answer (``text``)."""
    if isinstance(result, str):
        return {"site_rate_per_year": None, "target_width_m": None, "text": f"risk: {result}"}
    mode = result.modes[-1] if result.modes else None
    rate = None if mode is None else (0.0 if mode.rate is None else mode.rate.rate)
    t = result.target
    parts = []
    if rate is not None:
        from rocking.risk.rate import probability_in

        words = "overturns" if mode.limit is None else f"exceeds max theta/alpha = {mode.limit:g}"
        parts.append(f"at the site ({result.curve.measure}) it {words} "
                     f"at {rate:.2e}/yr ({100 * probability_in(rate, result.years):.2g} % in "
                     f"{result.years:g} years)")
    if t is not None:
        target = options.risk.target_text or f"{t.target_rate:g}/yr"
        parts.append(f"the width for the target {target} is "
                     + (f"{t.width:.3f} m" if t.width is not None else f"not found ({t.note})"))
    return {"site_rate_per_year": rate, "target_width_m": None if t is None else t.width,
            "text": "; ".join(parts)}
