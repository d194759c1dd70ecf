"""Results as plain data: :func:`plain` (JSON-safe numbers) and :func:`to_frame` (a list of
results as one DataFrame).  Every public result object's ``as_dict()`` goes through :func:`plain`."""
from __future__ import annotations

import dataclasses
import math


def plain(value):
    """``value`` with numpy scalars and arrays as Python numbers and lists, tuples as lists, dict
    keys as text and NaN or infinities as None: what :func:`json.dumps` writes without complaint.

    Examples
    --------
    >>> import numpy as np
    >>> from pulses.export import plain
    >>> plain({"w": np.float64(1.5), "ok": np.bool_(True), "nan": float("nan"), "t": (1, np.int64(2))})
    {'w': 1.5, 'ok': True, 'nan': None, 't': [1, 2]}
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "tolist") and hasattr(value, "dtype"):  # numpy arrays and scalars
        return plain(value.tolist())
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value) if math.isfinite(value) else None
    if hasattr(value, "as_dict"):
        return plain(value.as_dict())
    return str(value)


def fields_dict(obj, *, skip=(), properties=()) -> dict:
    """A dataclass result's fields (not those hidden from its repr: histories, arrays, the
    excitation) and ``properties``, through :func:`plain`."""
    out = {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj) if f.repr and f.name not in skip}
    out.update((name, getattr(obj, name)) for name in properties)
    return plain(out)


def to_frame(results):
    """A list of results (anything with ``as_dict()``: fits, widths, simulations, classifications
    ...) as one DataFrame, a row per result; nested values (lists, dicts) stay in their cell.

    Parameters
    ----------
    results : iterable
        Objects with an ``as_dict()`` method, or dicts.

    Returns
    -------
    pandas.DataFrame

    Examples
    --------
    >>> import rocking, pulses
    >>> blocks = [rocking.Block.from_dimensions(7.5, w) for w in (1.0, 2.0)]
    >>> sine = pulses.make_pulse("sine", 0.5 * pulses.G, 1.0)
    >>> df = pulses.to_frame([rocking.simulate(b, sine) for b in blocks])
    >>> df[["overturned", "model"]].shape
    (2, 2)
    """
    import pandas as pd

    rows = []
    for r in results:
        if isinstance(r, dict):
            rows.append(plain(r))
        elif hasattr(r, "as_dict"):
            rows.append(r.as_dict())
        else:
            raise TypeError(f"to_frame: expected results with as_dict() (or dicts), got {type(r).__name__}")
    return pd.DataFrame(rows)
