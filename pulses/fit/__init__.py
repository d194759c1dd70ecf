"""Fitting acceleration pulses to a record: :func:`fit_pulse` and what it returns.

The method is described where it is run (:mod:`pulses.fit.fitter`); its parts, each in its own
module: the coarse search by wavelet matching (:mod:`~pulses.fit.matching`), the plain least
squares near the match (:mod:`~pulses.fit.plain`, the rectangle's edges in
:mod:`~pulses.fit.edges`, the windows in :mod:`~pulses.fit.windows`, the solver in
:mod:`~pulses.fit.lsq`), the background's spectrum (:mod:`~pulses.fit.background`) and the least
squares weighted by it (:mod:`~pulses.fit.weighted`), the results (:mod:`~pulses.fit.results`)
and the record's PGV and duration (:mod:`~pulses.fit.baseline`).  :mod:`pulses.fit.synthetic`
makes records with a known pulse, to measure the fitter.
"""
from .fitter import DEFAULT_SHAPES, FitError, default_tp_range, fit_pulse
from .results import Candidate, PulseFit

__all__ = ["DEFAULT_SHAPES", "Candidate", "FitError", "PulseFit", "default_tp_range", "fit_pulse"]
