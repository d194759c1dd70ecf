"""Designs over a restitution band (docs/design.md, "Choosing the restitution"): the band's
:data:`BAND_VALUES` values are each designed as a single restitution, and the answer covering the
band is the most demanding of them (the widest design width, the largest minimum slenderness,
overturning where any value overturns, the smallest critical scale).

Why a covering answer and not one at the band's middle: the restitution of a real interface is
known to a few percent, and the design width is not a smooth function of it (2.5 % more
restitution than Eq. 5 moves the overturning design width by a median 7 %, up to 63 %, on real
records; docs/slivers.md).  Why the interior is run and not only the ends: the design width
rises with the restitution on most records but not on all (docs/design.md has the measurement
that sized :data:`BAND_VALUES`).
"""
from __future__ import annotations

import dataclasses

from .restitution import Restitution

#: values a band runs, its ends included, evenly spaced (docs/design.md, "Choosing the
#: restitution": how often an interior value governed on real records)
BAND_VALUES = 5


def is_band(eta) -> bool:
    """Whether ``eta`` is a :class:`Restitution` band (``low < high``)."""
    return isinstance(eta, Restitution) and eta.is_band


def plain(eta):
    """``eta`` in the form a design keys its runs by (its check's seed, its kept searches): None
    for Eq. 5 itself (``Restitution(1.0)``: the same runs as no restitution given), the number
    for a single ``eta`` or ``r`` (the same at every width), else as given (a float, a factor of
    Eq. 5, a band)."""
    if not isinstance(eta, Restitution) or eta.is_band:
        return eta
    if eta.is_housner:
        return None
    if eta.kind == "factor":
        return eta
    return eta.eta_at(0.0)


def singles(eta, n: int | None = None) -> list:
    """The single restitutions a design with ``eta`` runs: ``n`` (default :data:`BAND_VALUES`)
    values of a band, ends included; ``[eta]`` for anything else (None: Eq. 5, a float, a single
    :class:`Restitution`)."""
    if not is_band(eta):
        return [eta]
    return eta.values(BAND_VALUES if n is None else int(n))


def governing_index(values) -> int:
    """The index of the largest of ``values`` (the first of equals: the lowest restitution)."""
    values = list(values)
    return max(range(len(values)), key=lambda i: (values[i], -i))


def band_width(design, band, n=None):
    """The design covering ``band``: ``design(value)`` (a :class:`rocking.widths.RequiredWidth`)
    for each of its :func:`singles`, the widest governing; its fields are the governing value's,
    with :attr:`~rocking.widths.RequiredWidth.eta` the band and the band's fields set (the values
    run, each one's width, the one that governed, each one's design)."""
    values = singles(band, n)
    designs = [design(v) for v in values]
    k = governing_index([d.width for d in designs])
    gov = designs[k]
    listed = ", ".join(f"{v} {d.width:.6g} m" for v, d in zip(values, designs))
    return dataclasses.replace(
        gov, eta=band, restitution_values=tuple(values),
        restitution_widths=tuple(float(d.width) for d in designs), restitution_governing=values[k],
        band_designs=tuple(designs),
        method=gov.method + f"; restitution band {band.describe()}: {len(values)} values run "
                            f"({listed}), {values[k]} governed")


def band_of(result, k):
    """The design of the ``k``-th value of a band design ``result`` (``result`` itself where it
    is no band design)."""
    designs = getattr(result, "band_designs", ()) or ()
    return designs[k] if designs else result


def band_slenderness(solve, band, n=None):
    """The minimum slenderness covering ``band`` at each point: ``solve(value)`` (a list of
    :class:`rocking.slenderness.MinSlenderness`, one per point) for each of its :func:`singles`;
    at each point the value with the largest ``tan_alpha`` governs (its answer, with ``.band``
    and ``.band_runs`` set; ``.eta`` is that value)."""
    values = singles(band, n)
    answers = [solve(v) for v in values]
    out = []
    for point in zip(*answers):
        gov = point[governing_index([a.tan_alpha for a in point])]
        out.append(dataclasses.replace(gov, band=band, band_runs=len(values),
                                       runs=sum(a.runs for a in point)))
    return out


def required_width(height, excitation, eta, band_values, horizontal, overturning, kw):
    """:func:`rocking.required_width` under the restitution band ``eta`` (:func:`band_width`):
    each value designed with its own horizontal answer and overturning design where given (those
    of the band designs ``horizontal`` and ``overturning``)."""
    from .widths import required_width as design

    index = {v: k for k, v in enumerate(singles(eta, band_values))}

    def one(v):
        over = overturning if overturning is None or overturning is True else band_of(overturning, index[v])
        hor = None if horizontal is None else band_of(horizontal, index[v])
        return design(height, excitation, eta=v, horizontal=hor, overturning=over, **kw)

    return band_width(one, eta, band_values)
