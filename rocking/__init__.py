"""Housner's rocking block: solvers (exact-where-possible, fast, reference) and design."""
from .block import ALPHA_PLASTIC, Block, eta_housner
from .design import (
    CriticalAmplitudes, MinSlenderness, RequiredWidth, critical_amplitudes, envelope_rule, eq20,
    eq31, min_slenderness, min_slenderness_batch, required_width,
)
from .spectrum import OverturningSpectrum, overturning_spectrum, plot_chart, slenderness_chart

__all__ = ["ALPHA_PLASTIC", "Block", "eta_housner"]
__all__ += [
    "eq31", "eq20", "envelope_rule", "min_slenderness", "min_slenderness_batch", "MinSlenderness",
    "critical_amplitudes", "CriticalAmplitudes", "required_width", "RequiredWidth",
    "overturning_spectrum", "OverturningSpectrum", "slenderness_chart", "plot_chart",
]
from .solver import BatchResult, RockingResult, linear_error_estimate, simulate, simulate_many

__all__ += ["BatchResult", "RockingResult", "linear_error_estimate", "simulate", "simulate_many"]
from .reference_vertical import VerticalRockingResult, simulate_vertical_reference

__all__ += ["VerticalRockingResult", "simulate_vertical_reference"]
from .frame import equivalent_size, eta_frame, frame_p

__all__ += ["equivalent_size", "eta_frame", "frame_p"]
from .fragility import CriticalScale, Fragility, critical_scale, fragility

__all__ += ["CriticalScale", "Fragility", "critical_scale", "fragility"]
