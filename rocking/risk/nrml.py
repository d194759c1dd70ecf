"""OpenQuake's NRML fragility models: a column's lognormal fragility written for OpenQuake's risk
calculators, and read back.

A ``fragilityFunction`` of ``format="continuous" shape="logncdf"`` carries, per limit state, the
``mean`` and ``stddev`` of the intensity measure itself (not of its log)::

    mean = theta exp(beta^2 / 2),    stddev = mean sqrt(exp(beta^2) - 1)

and OpenQuake evaluates ``lognorm.cdf(x, sigma, scale=mu)`` with ``sigma = sqrt(ln(1 +
stddev^2/mean^2))`` and ``mu = mean^2 / sqrt(stddev^2 + mean^2)``, which give ``beta`` and
``theta`` back; the levels are clamped to ``[minIML, maxIML]`` first (written here as the range the
fragility was examined over: below it nothing moves, above it the hazard curve stops).
Limit states go from the least to the most severe: a level ``max|theta|/alpha > R``
(``exceeds_R``) before ``overturns``.  A function's id is the column's label with the
characters OpenQuake does not accept in an id (anything but letters, digits, ``_ - :``) as ``_``:
``column_7_5x1_8``; it is the taxonomy an exposure model names.

Examples
--------
>>> from rocking.risk.nrml import FragilityFunction, nrml_text, read_nrml_text
>>> ff = FragilityFunction("7.5x1.8", "PGA", [("overturns", 0.5, 0.4)], 0.05, 4.0)
>>> back = read_nrml_text(nrml_text([ff]))[0]
>>> back.id, back.limit_states[0][0], round(back.limit_states[0][1], 9), round(back.probability(0.5), 9)
('column_7_5x1_8', 'overturns', 0.5, 0.5)
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from xml.etree import ElementTree as ET

import numpy as np

NAMESPACE = "http://openquake.org/xmlns/nrml/0.5"


def nrml_id(label: str) -> str:
    """``column_7_5x1_8``: an id OpenQuake accepts (``[\\w_\\-:]+``) for a column's label."""
    text = re.sub(r"[^\w\-:]", "_", str(label))
    return text if text.startswith("column") else f"column_{text}"


def mean_stddev(median: float, beta: float) -> tuple[float, float]:
    """OpenQuake's ``(mean, stddev)`` of the measure for the lognormal ``(theta, beta)``."""
    mean = median * math.exp(0.5 * beta * beta)
    return mean, mean * math.sqrt(math.expm1(beta * beta))


def median_beta(mean: float, stddev: float) -> tuple[float, float]:
    """The lognormal ``(theta, beta)`` of OpenQuake's ``(mean, stddev)``."""
    s2 = math.log1p((stddev / mean) ** 2)
    return mean / math.exp(0.5 * s2), math.sqrt(s2)


@dataclass
class FragilityFunction:
    """One column's fragility: ``id`` (its label, or an NRML id), the measure, ``limit_states``
    as ``(name, theta, beta)`` from the least severe, and the range ``[min_iml, max_iml]``."""

    id: str
    measure: str
    limit_states: list
    min_iml: float
    max_iml: float

    def probability(self, x, state=-1):
        """The probability of reaching ``limit_states[state]`` at ``x``, as OpenQuake evaluates
        it (``x`` clamped to the range)."""
        from scipy.special import ndtr

        _, theta, beta = self.limit_states[state]
        x = np.clip(np.asarray(x, dtype=float), self.min_iml, self.max_iml)
        out = ndtr(np.log(x / theta) / beta)
        return float(out) if out.ndim == 0 else out


def nrml_text(functions, model_id="rocking_columns", description="Rocking columns: lognormal "
              "fragility of each column (rocking-columns)") -> str:
    """The NRML 0.5 ``fragilityModel`` of ``functions`` (all with the same limit states)."""
    if not functions:
        raise ValueError("nrml: no fragility function to write")
    states = [s[0] for s in functions[0].limit_states]
    if any([s[0] for s in f.limit_states] != states for f in functions):
        raise ValueError("nrml: every function of a model has the same limit states")
    model = re.sub(r"[^\w\-:]", "_", model_id or "model")
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', f'<nrml xmlns="{NAMESPACE}">',
             f'<fragilityModel id="{model}" '
             'assetCategory="buildings" lossCategory="structural">',
             f"  <description>{_escape(description)}</description>",
             f"  <limitStates>{' '.join(states)}</limitStates>"]
    for f in functions:
        lines.append(f'  <fragilityFunction id="{nrml_id(f.id)}" format="continuous" shape="logncdf">')
        lines.append(f'    <imls imt="{f.measure}" noDamageLimit="0" minIML="{f.min_iml:.10g}" '
                     f'maxIML="{f.max_iml:.10g}"/>')
        for name, theta, beta in f.limit_states:
            mean, sd = mean_stddev(theta, beta)
            lines.append(f'    <params ls="{name}" mean="{mean:.12g}" stddev="{sd:.12g}"/>')
        lines.append("  </fragilityFunction>")
    lines += ["</fragilityModel>", "</nrml>"]
    return "\n".join(lines) + "\n"


def _escape(text):
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def read_nrml_text(text) -> list[FragilityFunction]:
    """The continuous ``logncdf`` functions of an NRML 0.5 fragility model (others refused)."""
    try:
        root = ET.fromstring(text.encode("utf-8") if isinstance(text, str) else text)
    except ET.ParseError as exc:
        raise ValueError(f"nrml: not XML ({exc})") from None
    ns = {"n": NAMESPACE}
    model = root.find("n:fragilityModel", ns)
    if model is None:
        raise ValueError("nrml: no fragilityModel (NRML 0.5) in it")
    out = []
    for ff in model.findall("n:fragilityFunction", ns):
        if ff.get("format") != "continuous" or ff.get("shape", "logncdf") != "logncdf":
            raise ValueError(f"nrml: fragilityFunction {ff.get('id')}: only continuous logncdf "
                             "functions are read")
        imls = ff.find("n:imls", ns)
        states = [(p.get("ls"), *median_beta(float(p.get("mean")), float(p.get("stddev"))))
                  for p in ff.findall("n:params", ns)]
        out.append(FragilityFunction(ff.get("id"), imls.get("imt"), states,
                                     float(imls.get("minIML", 0) or 0) or 1e-10,
                                     float(imls.get("maxIML", "inf"))))
    return out


def write_nrml(path, functions, **kw) -> None:
    """Write :func:`nrml_text` to ``path``."""
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(nrml_text(functions, **kw))


def read_nrml(path) -> list[FragilityFunction]:
    with open(path, "rb") as fh:
        return read_nrml_text(fh.read())


def functions_of(result, label=None) -> FragilityFunction | None:
    """The :class:`FragilityFunction` of a :class:`rocking.risk.RiskResult`'s column as it stands
    (its level first, then overturning), or None where no fragility could be fitted."""
    modes = [m for m in result.modes if m.fragility is not None]
    if not modes:
        return None
    modes.sort(key=lambda m: 0 if m.limit is not None else 1)
    states = [("overturns" if m.limit is None else f"exceeds_{m.limit:g}".replace(".", "_"),
               m.fragility.median, m.fragility.beta) for m in modes]
    lows = [float(np.nanmin(m.critical.intensities * np.array(
        [e.uplift_scale for e in m.critical.entries]))) for m in modes]
    top = float(result.curve.imls[result.curve.rates > 0][-1])
    return FragilityFunction(label or f"{result.height:g}x{result.width:g}", result.curve.measure,
                             states, max(min(lows), 1e-10), top)
