"""The command line ``pipeline`` and the batch from Python: :func:`design` runs what ``pipeline run``
runs and returns its tables as DataFrames (:class:`DesignRun`).  Names load on first use
(:mod:`pulses.lazy`): ``import pipeline`` imports neither numpy nor pandas."""
from pulses.lazy import lazy_names

from .cli import main

#: public name -> the module of this package that defines it
_WHERE = {"design": "api", "DesignRun": "api"}

__all__ = ["main", *sorted(_WHERE)]

__getattr__, __dir__ = lazy_names(__name__, _WHERE)
