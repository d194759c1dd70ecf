"""The rows of the risk reports, made from a :class:`rocking.risk.RiskResult` in one place, with
their columns declared beside them (``(name, unit, meaning)``, as ``columns.md`` lists them)."""
from __future__ import annotations


class Columns:
    """Report columns ``(name, unit, meaning)``, in order; :meth:`row` orders a dict by them."""

    def __init__(self, *columns):
        self.columns = tuple(columns)
        self.names = tuple(c[0] for c in columns)

    def row(self, values: dict) -> dict:
        if set(values) != set(self.names):
            raise ValueError(f"risk row: undeclared {sorted(set(values) - set(self.names))}, "
                             f"missing {sorted(set(self.names) - set(values))}")
        return {n: values[n] for n in self.names}


RISK_COLUMNS = Columns(
    ("column", "-", "The column (`HxW`, or `H` where only the width for the target was asked)."),
    ("what", "-", "`as it stands`: the column's own width; `width for target`: the narrowest width "
                  "meeting the target rate."),
    ("mode", "-", "`overturning`, or `max theta/alpha > R` (`--limit` R)."),
    ("width_m", "m", "The width these numbers are for."),
    ("measure", "-", "The hazard curve's intensity measure (PGA, PGV or SA(T); SA 5 % damped)."),
    ("measure_units", "-", "Units of the measure: g, or cm/s for PGV."),
    ("rate_per_year", "1/yr", "Annual rate of failure: the fragility integrated against the hazard "
                              "curve (log-log interpolation, exact per interval); 0 where fewer "
                              "than two records fail up to the curve's last level."),
    ("rate_p5_per_year", "1/yr", "5th percentile of the rate over a bootstrap of the records "
                                 "(the suite's sampling uncertainty)."),
    ("rate_p95_per_year", "1/yr", "95th percentile of it."),
    ("return_period_years", "yr", "1 / rate."),
    ("years", "yr", "The time the next column is for (`--years`, default 50)."),
    ("probability_in_years", "-", "1 - exp(-rate years): probability of failing at least once in it."),
    ("age_years", "yr", "`--age`: the column's age; blank without it."),
    ("survival_over_age", "-", "exp(-rate age): probability of having stood that long."),
    ("below_first_share", "-", "Share of the rate from below the curve's first level (the rate held "
                               "at its first value there)."),
    ("above_last_per_year", "1/yr", "What the curve leaves out above its last level, at most "
                                    "(rate there x the fragility there; not in the rate)."),
    ("median", "measure", "Median of the lognormal fragility, in the measure's units."),
    ("beta", "-", "Its dispersion, with the restitution sampled per record from its band."),
    ("beta_eq5", "-", "The dispersion with Eq. 5's restitution for every record (no scatter of "
                      "the restitution)."),
    ("median_eq5", "measure", "The median with Eq. 5."),
    ("ks_statistic", "-", "Kolmogorov-Smirnov distance of the fit to the records' critical values."),
    ("ks_p_value", "-", "Its p-value by a parametric bootstrap (small: the lognormal fits badly)."),
    ("n_records", "-", "Records of the suite (a pair once)."),
    ("n_failed", "-", "Records that fail up to the curve's last level (the others are censored there)."),
    ("restitution", "-", "The restitution used: Eq. 5, or a band sampled per record (seeded)."),
    ("target_rate_per_year", "1/yr", "The target (`--target-rate`, or `--target-poe` P%/N as "
                                     "-ln(1 - P)/N); blank without one."),
    ("narrower_width_m", "m", "For the width for target: the width just narrower that was "
                              "computed, which does not meet the target."),
    ("narrower_rate_per_year", "1/yr", "Its rate."),
    ("widths_computed", "-", "Widths computed for the target (each one critical scale per record "
                             "and direction)."),
    ("note", "-", "Why a number is blank or bounded."),
)

RECORD_COLUMNS = Columns(
    ("column", "-", "The column."), ("mode", "-", "`overturning` or the level."),
    ("width_m", "m", "The width (as it stands, or the width for the target)."),
    ("record", "-", "The record (a pair once)."),
    ("intensity", "measure", "The record's measure, unscaled (RotD50 for a pair)."),
    ("critical_scale", "-", "Smallest factor that makes the record fail the column (weakest "
                            "direction); blank: none up to the curve's last level."),
    ("critical_intensity", "measure", "The critical scale times the measure: the fragility's data."),
    ("restitution_eta", "-", "The restitution (eta, velocity ratio) this record was computed with."),
)

WIDTH_COLUMNS = Columns(
    ("column", "-", "The column's height (`H`)."), ("width_m", "m", "A width computed."),
    ("rate_per_year", "1/yr", "Its annual rate of failure."),
    ("meets_target", "-", "At most the target."), ("median", "measure", "Fragility median."),
    ("beta", "-", "Fragility dispersion."), ("n_failed", "-", "Records failing up to the curve's last level."),
    ("stage", "-", "`scan` or `refine` (bisection of the crossing)."), ("note", "-", "Why the rate is 0."),
)

DISAGGREGATION_COLUMNS = Columns(
    ("column", "-", "The column."), ("mode", "-", "`overturning` or the level."),
    ("width_m", "m", "The width."),
    ("low", "measure", "Lower end of the band of the measure (blank: below the first level)."),
    ("high", "measure", "Upper end."), ("rate_per_year", "1/yr", "Rate contributed by the band."),
    ("share", "-", "Its share of the rate."),
)


def _label(res):
    return f"{res.height:g}x{res.width:g}" if res.width is not None else f"{res.height:g}"


def _eta(rest, res, width):
    from ..block import Block

    return Block.from_dimensions(res.height, width, rest, body=res.body).eta


def risk_rows(res) -> list[dict]:
    from .rate import probability_in, return_period, survival

    out = []
    for m in res.modes:
        f, r = m.fragility, m.rate
        rate = 0.0 if r is None else r.rate
        out.append(RISK_COLUMNS.row({
            "column": _label(res), "what": "as it stands", "mode": m.mode, "width_m": res.width,
            "measure": res.curve.measure, "measure_units": res.curve.units, "rate_per_year": rate,
            "rate_p5_per_year": m.band[0], "rate_p95_per_year": m.band[1],
            "return_period_years": return_period(rate), "years": res.years,
            "probability_in_years": probability_in(rate, res.years), "age_years": res.age,
            "survival_over_age": None if res.age is None else survival(rate, res.age),
            "below_first_share": None if r is None else r.below_first_share,
            "above_last_per_year": None if r is None else r.above_last,
            "median": None if f is None else f.median, "beta": None if f is None else f.beta,
            "beta_eq5": None if m.fragility_eq5 is None else m.fragility_eq5.beta,
            "median_eq5": None if m.fragility_eq5 is None else m.fragility_eq5.median,
            "ks_statistic": None if m.fit is None else m.fit.ks,
            "ks_p_value": None if m.fit is None else m.fit.p_value,
            "n_records": len(m.critical.entries), "n_failed": m.critical.n_failed,
            "restitution": res.restitution, "target_rate_per_year": None, "narrower_width_m": None,
            "narrower_rate_per_year": None, "widths_computed": None,
            "note": "" if f is not None else "fewer than two records fail up to the curve's last level"}))
    if res.target is not None:
        out.append(_target_row(res))
    return out


def _target_row(res) -> dict:
    from .rate import probability_in, return_period, survival

    t = res.target
    at = next((w for w in t.widths if t.width is not None and w.width == t.width), None)
    f = None if at is None else at.fragility
    rate = t.rate
    mode = "overturning" if res.limit is None else f"max theta/alpha > {res.limit:g}"
    return RISK_COLUMNS.row({
        "column": _label(res), "what": "width for target", "mode": mode, "width_m": t.width,
        "measure": res.curve.measure, "measure_units": res.curve.units, "rate_per_year": rate,
        "rate_p5_per_year": None, "rate_p95_per_year": None,
        "return_period_years": None if rate is None else return_period(rate), "years": res.years,
        "probability_in_years": None if rate is None else probability_in(rate, res.years),
        "age_years": res.age,
        "survival_over_age": None if (rate is None or res.age is None) else survival(rate, res.age),
        "below_first_share": None, "above_last_per_year": None,
        "median": None if f is None else f.median, "beta": None if f is None else f.beta,
        "beta_eq5": None, "median_eq5": None, "ks_statistic": None, "ks_p_value": None,
        "n_records": len(res.names), "n_failed": None if at is None else at.critical.n_failed,
        "restitution": res.restitution, "target_rate_per_year": t.target_rate,
        "narrower_width_m": t.narrower_width, "narrower_rate_per_year": t.narrower_rate,
        "widths_computed": len(t.widths), "note": t.note or (at.note if at is not None else "")})


def record_rows(res) -> list[dict]:
    out = []
    sets = [(m.mode, res.width, m.critical) for m in res.modes]
    t = res.target
    if t is not None and t.width is not None:
        at = next(w for w in t.widths if w.width == t.width)
        sets.append(("width for target", t.width, at.critical))
    for mode, width, cs in sets:
        for name, e, im, rest in zip(res.names, cs.entries, cs.intensities, cs.restitutions):
            out.append(RECORD_COLUMNS.row({
                "column": _label(res), "mode": mode, "width_m": width, "record": name,
                "intensity": float(im), "critical_scale": e.scale,
                "critical_intensity": None if e.scale is None else e.scale * float(im),
                "restitution_eta": _eta(rest, res, width)}))
    return out


def width_rows(res) -> list[dict]:
    t = res.target
    if t is None:
        return []
    return [WIDTH_COLUMNS.row({
        "column": f"{res.height:g}", "width_m": w.width, "rate_per_year": w.rate,
        "meets_target": w.rate <= t.target_rate,
        "median": None if w.fragility is None else w.fragility.median,
        "beta": None if w.fragility is None else w.fragility.beta,
        "n_failed": w.critical.n_failed, "stage": w.stage, "note": w.note}) for w in t.sorted()]


def disaggregation_rows(res) -> list[dict]:
    out = []
    for m in res.modes:
        r = m.rate
        if r is None or not r.rate > 0:
            continue
        base = {"column": _label(res), "mode": m.mode, "width_m": res.width}
        out.append(DISAGGREGATION_COLUMNS.row({**base, "low": None, "high": float(r.lows[0]),
                                               "rate_per_year": r.below_first,
                                               "share": r.below_first / r.rate}))
        for lo, hi, c in zip(r.lows, r.highs, r.contributions):
            out.append(DISAGGREGATION_COLUMNS.row({**base, "low": float(lo), "high": float(hi),
                                                   "rate_per_year": float(c), "share": float(c) / r.rate}))
    return out

