"""The files ``pipeline run`` writes into ``--out``, named and listed once: the output checks, the
record ids (an id never names a file of the run's own), the lock on ``--log``, the clean-up of
temporaries and the HTML report's figures all read them here.
"""
from __future__ import annotations

#: the manifest in ``--out``: the files ``pipeline run`` wrote there, which alone it replaces or removes
MANIFEST = "pipeline-manifest.txt"
#: the resume journal in ``--out`` (:mod:`pipeline.batch.resume`): which records a later run may keep
RESUME = "pipeline-resume.txt"

SUMMARY, FAILURES, COLUMNS_MD = "summary.csv", "failures.csv", "columns.md"
SUMMARY_PLOT = "plots/summary.png"
#: the suite's tables and figures (pipeline.reports.suite: pairs, suite, fragility)
PAIRS_CSV, SUITE_CSV, FRAGILITY_CSV, FRAGILITY_CURVE_CSV = ("pairs.csv", "suite.csv", "fragility.csv",
                                                           "fragility_curve.csv")
SUITE_PLOT, FRAGILITY_PLOT = "plots/suite.png", "plots/fragility.png"


def record_csv_name(record_id: str) -> str:
    """Path of a record's report, relative to the output folder."""
    return f"{record_id}.csv"


def record_plot_name(record_id: str) -> str:
    """Path of a record's figure, relative to the output folder."""
    return f"plots/{record_id}.png"


def record_widths_plot_name(record_id: str) -> str:
    """Path of a record's barcode of the widths checked above its search width (a folder of
    its own: ``plots/<record>_widths.png`` could be another record's figure)."""
    return f"plots/widths/{record_id}.png"


def record_friction_plot_name(record_id: str) -> str:
    """Path of a record's figure of the friction its responses need (a folder of its own)."""
    return f"plots/friction/{record_id}.png"

#: the answer in view (pipeline.reports.design_table, pipeline.reports.html_report)
DESIGN_CSV, REPORT_HTML = "design.csv", "report.html"


def site_files(plots: bool, fragility: bool) -> list[str]:
    """The fixed files of the suite (pipeline.reports.suite): pairs, suite and, with ``--fragility``,
    the fragility tables; their figures with ``plots``."""
    files = [PAIRS_CSV, SUITE_CSV]
    if plots:
        files.append(SUITE_PLOT)
    if fragility:
        files += [FRAGILITY_CSV, FRAGILITY_CURVE_CSV] + ([FRAGILITY_PLOT] if plots else [])
    return files


def answer_files() -> list[str]:
    """The answer in view: ``design.csv`` and ``report.html``."""
    return [DESIGN_CSV, REPORT_HTML]


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
