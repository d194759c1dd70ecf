"""Records from files and obspy streams: :func:`read_record`, :func:`read_pair`,
:func:`from_stream`, and PEER NGA-West2 downloads (:mod:`pulses.io.peer`).

This package stands on the record type (:class:`pulses.Record`) and on the formats
(:mod:`pulses.formats`: what a file states, one module a format); neither imports it.
"""
from .read import read_pair, read_record, record_from_reading, special_kind
from .streams import from_stream

__all__ = ["from_stream", "read_pair", "read_record", "record_from_reading", "special_kind"]
