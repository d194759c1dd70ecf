"""Build of the compiled solver core (``rocking/_core.pyx``, Cython); everything else is in
pyproject.toml.

Flags (measured in docs/performance-build.md): ``-O3`` and ``-ffp-contract=off``: the compiler
may not fuse a multiply and an add (the steps compute exactly the operations written, in the
order written, on every machine: the generated steps are checked bit for bit against their
Python text); ``-fno-math-errno``: ``sqrt`` is the processor's instruction, which the compiler may
then vectorise (the lanes' events, ``rocking/_taylor_lanes.h``), instead of a call that could set
``errno`` (no result changes: the package never reads ``errno``).  ``ROCKING_NATIVE=1`` in the environment of a source build adds ``-march=native``
(instructions of the building machine only: never for a wheel that other machines install).
"""
import os
import sys

from Cython.Build import cythonize
from setuptools import Extension, setup


def _flags():
    if sys.platform == "win32":
        return ["/O2", "/fp:precise"]
    flags = ["-O3", "-ffp-contract=off", "-fno-math-errno"]
    if os.environ.get("ROCKING_NATIVE") == "1":
        flags.append("-march=native")
    return flags


core = Extension("rocking._core", ["rocking/_core.pyx"], extra_compile_args=_flags(),
                 define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")])

setup(ext_modules=cythonize([core], compiler_directives={"language_level": 3}, quiet=True))
