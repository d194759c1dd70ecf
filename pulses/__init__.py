"""Pulse shapes, accelerogram reading and pulse fitting (no dependency on ``rocking``)."""
from .record import G, Record
from .shapes import (
    BETA,
    SHAPES,
    AntisymmetricRicker,
    OneSine,
    Pulse,
    Rectangular,
    SymmetricRicker,
    make_pulse,
)

__all__ = [
    "G", "Record", "BETA", "SHAPES", "Pulse", "Rectangular", "OneSine", "SymmetricRicker",
    "AntisymmetricRicker", "make_pulse",
]
