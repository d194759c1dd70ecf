"""Records from files: :func:`read_record`, and PEER NGA-West2 downloads (:mod:`pulses.io.peer`)."""
from .read import read_record, record_from_reading, special_kind

__all__ = ["read_record", "record_from_reading", "special_kind"]
