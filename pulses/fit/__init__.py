"""Fitting acceleration pulses to a record: :func:`fit_pulse` (the method: :mod:`pulses.fit.fitter`)."""
from .fitter import DEFAULT_SHAPES, Candidate, FitError, PulseFit, default_tp_range, fit_pulse

__all__ = ["DEFAULT_SHAPES", "Candidate", "FitError", "PulseFit", "default_tp_range", "fit_pulse"]
