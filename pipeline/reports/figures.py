"""A run's figures asked for by name (:func:`draw`), so that the process asking need not import
matplotlib where they are drawn elsewhere (pipeline.batch.executors.renderer)."""
from __future__ import annotations


def draw(name: str, *args) -> bytes:
    """A run's figure: ``pipeline.reports.<module>.<function>(*args)`` (its PNG bytes), ``name``
    ``"module:function"``.  Named, not passed as a function: the process that asks for a figure
    drawn elsewhere then never imports matplotlib (half a second, most of the main process's own
    CPU in a batch)."""
    import importlib

    module, function = name.split(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), function)(*args)
