"""The API reference, written from each package's ``__all__`` when the build starts.

One page per package (``api/<package>.rst``) holds autosummary tables grouped by theme; the
autosummary extension then writes one page per name (``api/generated/<package>.<name>.rst``).
A name added to ``__all__`` appears with no edit here: names the theme lists below do not know
land in the package's last table.  Constants get a short entry on their package's page (their
docstring is the ``#:`` comment where they are defined; a float has none of its own).
"""
from __future__ import annotations

import importlib
import inspect
import pathlib

from sphinx.pycode import ModuleAnalyzer

#: package -> (title, [(theme, [names])]); a name of ``__all__`` missing here goes to "More"
THEMES = {
    "pulses": ("pulses: records, pulse shapes, fitting, classification", [
        ("Records", ["Record", "read_record", "write_sac", "RecordError", "read_pair", "pair_files",
                     "Pairing", "check_pair", "check_triplet", "rotate_pair", "component",
                     "PeerDownload", "peer", "from_stream", "UnitsWarning"]),
        ("Pulse shapes", ["Pulse", "Rectangular", "OneSine", "SymmetricRicker",
                          "AntisymmetricRicker", "make_pulse", "shape_class", "design_pulse",
                          "pulse_period"]),
        ("Fitting a pulse to a record", ["fit_pulse", "PulseFit", "Candidate", "FitError"]),
        ("Pulse-like records (Shahi & Baker)", ["classify_pulse", "PulseClassification",
                                                "PulseCandidate"]),
        ("Results as tables", ["to_frame"]),
    ]),
    "rocking": ("rocking: the block, the solvers, design", [
        ("The block", ["Block", "Restitution", "eta_housner", "linear_error_estimate"]),
        ("Simulation", ["simulate", "RockingResult", "simulate_many", "BatchResult",
                        "simulate_vertical_reference", "VerticalRockingResult"]),
        ("Design: the width a column needs", ["required_width", "RequiredWidth", "eq31", "eq20",
                                              "envelope_rule", "min_slenderness", "MinSlenderness",
                                              "min_slenderness_batch"]),
        ("The governing pulse of a record", ["governing_pulse", "GoverningPulse",
                                             "fitting_candidates"]),
        ("Charts and spectra", ["slenderness_chart", "plot_chart", "overturning_spectrum",
                                "OverturningSpectrum", "critical_amplitudes",
                                "CriticalAmplitudes"]),
        ("A site: scaled records and fragility", ["critical_scale", "CriticalScale", "fragility",
                                                  "Fragility"]),
        ("Rocking frames", ["frame_p", "eta_frame", "equivalent_size"]),
        ("Where the model holds: friction, bodies, a measured restitution",
         ["friction_demand", "FrictionDemand", "FrictionCheck", "sliding_width", "SlidingWidth",
          "Body", "fit_restitution",
          "RestitutionFit"]),
    ]),
    "pipeline": ("pipeline: the command line and batches from Python", [
        ("The batch from Python", ["design", "DesignRun"]),
        ("The command line", ["main"]),
    ]),
}


def _is_constant(obj) -> bool:
    return not (inspect.isclass(obj) or inspect.isroutine(obj) or inspect.ismodule(obj))


def _constant_doc(package, name: str) -> str:
    """The ``#:`` comment of a constant where its package's loader says it is defined."""
    where = getattr(package, "_WHERE", {}).get(name)
    modules = [f"{package.__name__}.{where}"] if where else []
    for modname in modules + [package.__name__]:
        try:
            docs = ModuleAnalyzer.for_module(modname).find_attr_docs()
        except Exception:  # a module without source (compiled): no comment to show
            continue
        lines = docs.get(("", name))
        if lines:
            return " ".join(line.strip() for line in lines if line.strip())
    return ""


def _table(names: list[str]) -> list[str]:
    return [".. autosummary::", "   :toctree: generated/", "   :nosignatures:", ""] + \
           [f"   {n}" for n in names] + [""]


def package_page(package_name: str) -> str:
    """The reST of one package's page: its tables by theme, then its constants."""
    package = importlib.import_module(package_name)
    title, themes = THEMES.get(package_name, (package_name, []))
    public = list(package.__all__)
    constants = [n for n in public if _is_constant(getattr(package, n))]
    placed = {n for _, names in themes for n in names}
    more = [n for n in public if n not in placed and n not in constants]
    lines = [title, "=" * len(title), "", f".. currentmodule:: {package_name}", ""]
    for theme, names in themes + ([("More", more)] if more else []):
        names = [n for n in names if n in public]
        if names:
            lines += [theme, "-" * len(theme), ""] + _table(names)
    if constants:
        lines += ["Constants", "---------", ""]
        for n in constants:
            value = getattr(package, n)
            shown = repr(value) if isinstance(value, (int, float)) else f"a {type(value).__name__}"
            lines += [f".. py:data:: {n}", f"   :value: {shown}", "", f"   {_constant_doc(package, n)}", ""]
    return "\n".join(lines) + "\n"


def write_pages(srcdir: pathlib.Path) -> None:
    """Write ``api/<package>.rst`` for each package, only where the text changed (so that an
    unchanged reference is not read again)."""
    folder = srcdir / "api"
    folder.mkdir(exist_ok=True)
    for name in THEMES:
        page = folder / f"{name}.rst"
        text = package_page(name)
        if not page.exists() or page.read_text(encoding="utf-8") != text:
            page.write_text(text, encoding="utf-8")


def _on_config_inited(app, config):
    write_pages(pathlib.Path(app.srcdir))


def setup(app):
    app.connect("config-inited", _on_config_inited)
    return {"parallel_read_safe": True}
