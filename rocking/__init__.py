"""Housner's rocking block: solvers (exact-where-possible, fast, reference) and design.

Names are loaded from their modules on first use (PEP 562, :mod:`pulses.lazy`): ``import
rocking`` costs almost nothing, and the compiled core, scipy and the design modules load when
first asked for.
"""
import sys
import types

from pulses.lazy import lazy_names

#: public name -> the module of this package that defines it
_WHERE = {
    "ALPHA_PLASTIC": "block", "Block": "block", "Restitution": "restitution", "Blocks": "block", "eta_housner": "block",
    "CriticalAmplitudes": "design", "MinSlenderness": "design", "RequiredWidth": "design",
    "critical_amplitudes": "design", "envelope_rule": "design", "eq20": "design", "eq31": "design",
    "min_slenderness": "design", "min_slenderness_batch": "design", "required_width": "design",
    "OverturningSpectrum": "spectrum", "overturning_spectrum": "spectrum", "plot_chart": "spectrum",
    "slenderness_chart": "spectrum",
    "BatchResult": "solver", "RockingResult": "solver", "linear_error_estimate": "solver",
    "simulate": "solver", "simulate_many": "solver",
    "VerticalRockingResult": "reference_vertical",
    "simulate_vertical_reference": "reference_vertical",
    "equivalent_size": "frame", "eta_frame": "frame", "frame_p": "frame",
    "CriticalScale": "fragility", "Fragility": "fragility", "critical_scale": "fragility",
    "fragility": "fragility",
    "risk": "risk", "HazardCurve": "risk", "read_hazard": "risk",
    "FIT_TOLERANCE": "governing", "GoverningPulse": "governing", "fitting_candidates": "governing",
    "governing_pulse": "governing",
    "FrictionCheck": "friction", "FrictionDemand": "friction", "friction_demand": "friction",
    "SlidingWidth": "sliding", "sliding_width": "sliding", "Body": "bodies", "RestitutionFit": "restitution_fit", "fit_restitution": "restitution_fit",
}

__all__ = sorted(_WHERE)


__getattr__, __dir__ = lazy_names(__name__, _WHERE)


class _Package(types.ModuleType):
    def __setattr__(self, name, value):
        # importing a submodule binds it to the package; where a public function has its module's
        # name (``fragility``), ``rocking.fragility`` stays the function, as the package documents
        if isinstance(value, types.ModuleType) and _WHERE.get(name) == name:
            value = getattr(value, name)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

