"""Pulse shapes, accelerogram reading and pulse fitting (no dependency on ``rocking``).

The rooms, from the ground up: units and errors; :mod:`pulses.formats` (what a file or a trace
states, one module a format, registered once); the record type (:mod:`pulses.record`); the pulse
shapes (:mod:`pulses.shapes`, one class a shape), pairs and triplets of components; and on them
:mod:`pulses.io` (records from files and PEER downloads), :mod:`pulses.fit` (pulse fitting) and
:mod:`pulses.velocity` (Shahi & Baker's classification).  No module imports one above it.

Names are loaded from their modules on first use (PEP 562, :mod:`pulses.lazy`), so that
``import pulses`` costs almost nothing and a program pays for scipy, PyWavelets or obspy only
when it reads records, fits pulses or classifies them.
"""
from .lazy import lazy_names

#: public name -> the module of this package that defines it
_WHERE = {
    "RecordError": "errors", "UnitsWarning": "errors",
    "G": "units", "Record": "record",
    "VP_TO_AP": "scenario", "design_pulse": "scenario", "pulse_period": "scenario",
    "read_record": "io", "read_pair": "io", "from_stream": "io",
    "write_sac": "formats.sac",
    "Candidate": "fit", "FitError": "fit", "PulseFit": "fit", "fit_pulse": "fit",
    "BETA": "shapes", "SHAPES": "shapes", "AntisymmetricRicker": "shapes", "OneSine": "shapes",
    "Pulse": "shapes", "Rectangular": "shapes", "SymmetricRicker": "shapes", "make_pulse": "shapes",
    "shape_class": "shapes",
    "PulseCandidate": "velocity", "PulseClassification": "velocity", "classify_pulse": "velocity",
    "Pairing": "pairs", "check_pair": "pairs", "component": "pairs", "pair_files": "pairs",
    "rotate_pair": "pairs",
    "PeerDownload": "io.peer",
    "check_triplet": "triplets",
    "to_frame": "export",
}
#: submodules that are part of the public namespace: public name -> the module
_MODULES = {"peer": "io.peer"}

__all__ = sorted(_WHERE) + list(_MODULES)


__getattr__, __dir__ = lazy_names(__name__, _WHERE, _MODULES)
