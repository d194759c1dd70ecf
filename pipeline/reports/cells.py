"""One cell of a report: :func:`fmt` turns a value into the text a CSV file holds (floats with 6
significant digits, booleans as ``True``/``False``, None and NaN blank, text in one line and never
a spreadsheet formula), and :func:`display` shows any file name as printable text.  The CSV writer
(:func:`pipeline.reports.columns.csv_text`) and the printed and HTML reports format through here.
"""
from __future__ import annotations

import math

def fmt(value) -> str:
    """One cell: floats with 6 significant digits, booleans as True/False, None/NaN blank."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "True" if value else "False"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        text = f"{value:.6g}"
        return "0" if text == "-0" else text
    try:  # numpy scalars
        import numpy as np

        if isinstance(value, np.bool_):
            return fmt(bool(value))
        if isinstance(value, np.integer):
            return str(int(value))
        if isinstance(value, np.floating):
            return fmt(float(value))
    except ImportError:  # pragma: no cover
        pass
    return text_cell(value)


#: first characters that make a spreadsheet read a text cell as a formula
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def text_cell(value) -> str:
    """A text cell: one line, any bytes of a file name shown (``\\xff``), and never a formula.

    A text starting with ``= + - @``, tab or carriage return is read as a formula by spreadsheets
    (CSV injection): it gets a leading apostrophe, which they show as text.  Numbers are written by
    :func:`fmt` and never pass here.
    """
    text = " ".join(display(value).split())
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def display(value) -> str:
    """``value`` as printable text: bytes of a file name that are not UTF-8 (which Python keeps as
    lone surrogates) written as ``\\xff``."""
    text = str(value)
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        try:
            raw = text.encode("utf-8", "surrogateescape")
        except UnicodeEncodeError:
            raw = text.encode("utf-8", "backslashreplace")
        return raw.decode("utf-8", "backslashreplace")
