"""The figures of the reports, one module per figure's subject: a record with its pulses and
rotation histories and the batch's summary (:mod:`.record`), the suite and its fragility
(:mod:`.site`), the widths checked above a search width (:mod:`.widths`), the friction needed
(:mod:`.friction`), the risk at a site (:mod:`.risk`), the classification (:mod:`.classify`) and
the width chart (:mod:`.chart`).

A run's figures are asked for by name (:func:`draw`), so that the process asking need not import
matplotlib where they are drawn elsewhere (pipeline.batch.executors.renderer)."""
from __future__ import annotations


def draw(name: str, *args) -> bytes:
    """A run's figure: ``pipeline.reports.figures.<module>.<function>(*args)`` (its PNG bytes), ``name``
    ``"module:function"``.  Named, not passed as a function: the process that asks for a figure
    drawn elsewhere then never imports matplotlib (half a second, most of the main process's own
    CPU in a batch)."""
    import importlib

    module, function = name.split(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), function)(*args)
