"""Design of free-standing rocking columns (docs/theory.md section 5; Makris & Vassiliou 2012, Section 5).

One module per idea, gathered here:

:mod:`rocking.closed_forms`
    :func:`eq31` (the paper's design rule), :func:`eq20` (the dimensional-argument form) and
    :func:`envelope_rule` (a conservative closed form derived here from the exact answers).
:mod:`rocking.search`
    What the exact searches share: :class:`SearchSettings` (their settings, a value), the batch
    solver call and the scan-and-refine transition finder.
:mod:`rocking.slenderness`
    Searches over pulses: :func:`min_slenderness` (Fig. 8) and :func:`critical_amplitudes` (the
    overturning intervals and safe islands of Fig. 5).
:mod:`rocking.widths`
    :func:`required_width`: sizing a column of given height by a closed form or by time-history
    analysis under a pulse or a whole record (the design width).
"""
from .closed_forms import ENVELOPE, ENVELOPE_RANGE, envelope_rule, eq20, eq31
from .search import CRITERIA, DEFAULT_SETTINGS, SearchSettings
from .slenderness import (CriticalAmplitudes, MinSlenderness, critical_amplitudes,
                          min_slenderness, min_slenderness_batch)
from .widths import RULES, RequiredWidth, required_width

__all__ = [
    "ENVELOPE", "ENVELOPE_RANGE", "envelope_rule", "eq20", "eq31", "CRITERIA", "DEFAULT_SETTINGS",
    "SearchSettings", "CriticalAmplitudes", "MinSlenderness", "critical_amplitudes",
    "min_slenderness", "min_slenderness_batch", "RULES", "RequiredWidth", "required_width",
]
