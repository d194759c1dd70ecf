"""A package's public names loaded from their modules on first use (PEP 562).

``import pulses`` and ``import rocking`` cost almost nothing: a program pays for scipy,
PyWavelets, obspy or the compiled core only when it uses a name whose module needs them.
"""
from __future__ import annotations

import importlib
import sys


def lazy_names(package: str, where: dict, modules=None):
    """The ``__getattr__`` and ``__dir__`` of a package whose names load on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    where : dict
        Public name -> the module of the package that defines it (``{"fit_pulse": "fit"}``).
    modules : dict, optional
        Submodules that are themselves public names of the package: public name -> the module of
        the package it is (``{"peer": "io.peer"}``).

    Returns
    -------
    (callable, callable)
        ``__getattr__(name)``: the name, imported from its module and kept in the package's
        namespace (so it is looked up once); AttributeError for a name the package does not have.
        ``__dir__()``: the package's names, loaded or not.
    """
    modules = dict(modules or {})
    public = set(where) | set(modules)

    def __getattr__(name):
        if name in modules:
            return importlib.import_module(f".{modules[name]}", package)
        module = where.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f".{module}", package), name)
        vars(sys.modules[package])[name] = value
        return value

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | public)

    return __getattr__, __dir__
