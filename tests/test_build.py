"""The package as built: the solver's core is the compiled extension, and nothing imports numba."""
from __future__ import annotations

import importlib.machinery
import subprocess
import sys

import pytest


@pytest.mark.slow
def test_core_is_the_compiled_extension_and_numba_is_not_imported():
    code = ("import sys, pulses, rocking, pipeline, pipeline.cli, rocking._core as c; "
            "print(c.__file__); print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    path, numba = out.stdout.split()
    # a built module (.so / .pyd), not a source tree without it
    assert path.endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES)), path
    assert numba == "False"
