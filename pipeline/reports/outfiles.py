"""The files ``pipeline run`` writes into ``--out``, listed once: the output checks, the record ids
(an id never names a file of the run's own), the lock on ``--log``, the clean-up of temporaries and
the HTML report's figures all read them here.
"""
from __future__ import annotations

from . import design_table, html_report
from .report import (COLUMNS_MD, FAILURES, FRAGILITY_CSV, FRAGILITY_CURVE_CSV, FRAGILITY_PLOT, MANIFEST,
                     PAIRS_CSV, RESUME, SUITE_CSV, SUITE_PLOT, SUMMARY, SUMMARY_PLOT, record_csv_name,
                     record_friction_plot_name, record_plot_name, record_widths_plot_name)


def site_files(plots: bool, fragility: bool) -> list[str]:
    """The fixed files of the site part (pipeline.batch.site): pairs, suite and, with ``--fragility``,
    the fragility tables; their figures with ``plots``."""
    files = [PAIRS_CSV, SUITE_CSV]
    if plots:
        files.append(SUITE_PLOT)
    if fragility:
        files += [FRAGILITY_CSV, FRAGILITY_CURVE_CSV] + ([FRAGILITY_PLOT] if plots else [])
    return files


def answer_files() -> list[str]:
    """The answer in view: ``design.csv`` and ``report.html``."""
    return [design_table.DESIGN_CSV] + html_report.output_files()


#: the files of ``--hazard`` (pipeline.batch.risk)
RISK_CSV, RISK_RECORDS_CSV, RISK_WIDTHS_CSV, RISK_DISAGG_CSV, FRAGILITY_XML = (
    "risk.csv", "risk_records.csv", "risk_widths.csv", "risk_disaggregation.csv", "fragility.xml")
RISK_WIDTHS_PLOT, RISK_DISAGG_PLOT = "plots/risk_widths.png", "plots/risk_disaggregation.png"


def risk_files(options, plots=None) -> list[str]:
    """The files of ``--hazard`` (pipeline.batch.risk), none without it."""
    if getattr(options, "risk", None) is None:
        return []
    plots = options.plots if plots is None else plots
    return ([RISK_CSV, RISK_RECORDS_CSV, RISK_WIDTHS_CSV, RISK_DISAGG_CSV, FRAGILITY_XML]
            + ([RISK_WIDTHS_PLOT, RISK_DISAGG_PLOT] if plots else []))


def fixed_files(options) -> list[str]:
    """The run's own files (not a record's) that a run with ``options`` writes (the manifest too)."""
    names = [SUMMARY, FAILURES, COLUMNS_MD, MANIFEST] + ([SUMMARY_PLOT] if options.plots else [])
    return names + site_files(options.plots, options.fragility) + risk_files(options) + answer_files()


def record_files(record_id: str, plots: bool = True) -> list[str]:
    """A record's own report, and with ``plots`` its figures."""
    names = [record_csv_name(record_id)]
    return names + ([record_plot_name(record_id), record_widths_plot_name(record_id),
                     record_friction_plot_name(record_id)] if plots else [])


def own_files(tasks, options) -> list[str]:
    """Every file a run of ``tasks`` may write into its output folder, whatever ``options.plots``
    (paths relative to it)."""
    names = [SUMMARY, FAILURES, COLUMNS_MD, SUMMARY_PLOT, MANIFEST, RESUME]
    names += site_files(options.plots, options.fragility) + risk_files(options, plots=True) + answer_files()
    return names + [n for t in tasks for n in record_files(t.record_id)]


#: record ids that would collide with the run's own files (their names without extension): a record
#: ``summary`` or ``design`` would otherwise write ``summary.csv`` or ``design.csv`` (and
#: ``plots/summary.png``) over the run's own
RESERVED_IDS = {name.rsplit("/", 1)[-1].rsplit(".", 1)[0] for name in
                [SUMMARY, FAILURES, COLUMNS_MD, MANIFEST, RESUME] + site_files(plots=False, fragility=True)
                + [RISK_CSV, RISK_RECORDS_CSV, RISK_WIDTHS_CSV, RISK_DISAGG_CSV, FRAGILITY_XML]
                + answer_files()}
