"""The command line ``pipeline`` and the batch from Python: :func:`design` runs what ``pipeline run``
runs and returns its tables as DataFrames (:class:`DesignRun`).  Names load on first use: ``import
pipeline`` imports neither numpy nor pandas."""
from .cli import main

__all__ = ["main", "design", "DesignRun"]

_WHERE = {"design": "api", "DesignRun": "api"}


def __getattr__(name):
    if name in _WHERE:
        import importlib

        value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
