"""The narrowest width that does not slide (docs/theory.md, "Friction"): a design width is valid
only where the column at that width rocks without sliding on its base.

The friction a column needs grows with its width, up to the ground's own ``max|ug''|/(g + uv'')``
for a column too wide to uplift: where that exceeds the base's ``mu`` widening rarely helps, and
:func:`sliding_width` says so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pulses import Record

from .friction import _Forcing, check_mu, friction_demand


@dataclass(frozen=True)
class SlidingWidth:
    """The narrowest width, from a given one up, at which a column does not slide (``mu``).

    ``width`` (m) is None where no width can help (``reason`` says why); ``demand`` is the largest
    demand there; ``given_slides`` whether the given width slides; ``runs``: responses computed.

    Examples
    --------
    >>> import pulses, rocking
    >>> pulse = pulses.OneSine(0.5 * pulses.G, 1.0)
    >>> sw = rocking.sliding_width(7.5, pulse, 1.8, 0.25)       # below the ground's 0.5 g at rest
    >>> sw.given_slides, sw.width, sw.reason[:14]
    (True, None, 'no width holds')
    """

    width: float | None
    mu: float
    demand: float
    given_slides: bool
    reason: str
    runs: int


def sliding_width(height, excitation, width, mu, *, body=None, cap_mass_ratio=0.0, eta=None,
                  vertical=None, n_scan: int = 24, rtol: float = 1e-3) -> SlidingWidth:
    """The narrowest width ``>= width`` (m) at which a column of ``height`` (m) does not slide
    under ``excitation`` with friction coefficient ``mu`` (docs/theory.md, "Friction").

    Wider than the no-uplift width ``H max|ug''|/(g + uv'')`` the column rests and needs
    ``max|ug''|/(g + uv'')``: where that exceeds ``mu`` no wide column holds, and only a rocking
    one might.  From ``width`` up to that width ``n_scan`` geometric widths are run; the first that
    does not slide is refined down to ``rtol`` (relative) against the widest sliding one below it.

    Examples
    --------
    >>> import pulses, rocking
    >>> pulse = pulses.OneSine(0.5 * pulses.G, 1.0)
    >>> sw = rocking.sliding_width(7.5, pulse, 1.8, 0.45)
    >>> sw.given_slides, sw.width
    (False, 1.8)
    """
    from .block import Block
    from .solver import simulate

    mu = check_mu(mu)
    forcing = _Forcing(excitation, vertical)
    times = excitation.time if isinstance(excitation, Record) else np.linspace(*excitation.support, 4001)
    static = float(np.max(np.abs(forcing.u(times)) / forcing.ge(times)))
    top = float(height) * static
    runs = [0]

    def verdict(w):
        """Whether the column ``w`` wide slides, and the largest demand."""
        if w >= top:
            return static > mu, static
        block = Block.from_dimensions(height, w, eta, cap_mass_ratio=cap_mass_ratio, body=body)
        runs[0] += 1
        need = friction_demand(simulate(block, excitation, vertical=vertical), excitation,
                               vertical=vertical)
        return need.judge(mu).slides, need.max_demand

    slides, first = verdict(float(width))
    if not slides:
        return SlidingWidth(float(width), mu, first, False, "", runs[0])
    grid = np.geomspace(float(width), max(top, float(width)) * (1.0 + 1e-9), n_scan + 1)[1:]
    lo = float(width)
    for w in grid.tolist():
        slides, d = verdict(w)
        if not slides:
            hi = w
            while hi - lo > rtol * hi:
                mid = 0.5 * (lo + hi)
                s_mid, d_mid = verdict(mid)
                if s_mid:
                    lo = mid
                else:
                    hi, d = mid, d_mid
            return SlidingWidth(hi, mu, d, True, "", runs[0])
        lo = w
    reason = (f"no width holds: at rest the column needs max|ug''|/(g + uv'') = {static:.4g} > "
              f"mu = {mu:g}, and every rocking width run from {width:.4g} m slides")
    return SlidingWidth(None, mu, static, True, reason, runs[0])

