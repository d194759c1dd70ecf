"""Pulse shapes, accelerogram reading and pulse fitting (no dependency on ``rocking``)."""
from .errors import RecordError
from .record import G, Record
from .scenario import VP_TO_AP, design_pulse, pulse_period
from .io import read_record
from .sac import write_sac
from .fit import Candidate, FitError, PulseFit, fit_pulse
from .shapes import (
    BETA,
    SHAPES,
    AntisymmetricRicker,
    OneSine,
    Pulse,
    Rectangular,
    SymmetricRicker,
    make_pulse,
    shape_class,
)

__all__ = [
    "G", "Record", "BETA", "SHAPES", "Pulse", "Rectangular", "OneSine", "SymmetricRicker",
    "AntisymmetricRicker", "make_pulse", "shape_class",
    "RecordError", "read_record", "write_sac", "fit_pulse", "FitError", "PulseFit", "Candidate",
    "design_pulse", "pulse_period", "VP_TO_AP",
]

from .velocity import PulseCandidate, PulseClassification, classify_pulse
from .pairs import Pairing, check_pair, component, pair_files, read_pair, rotate_pair
from . import peer
from .peer import PeerDownload
from .triplets import check_triplet

__all__ += ["classify_pulse", "PulseClassification", "PulseCandidate", "read_pair", "check_pair",
            "component", "rotate_pair", "pair_files", "Pairing", "peer", "PeerDownload", "check_triplet"]
