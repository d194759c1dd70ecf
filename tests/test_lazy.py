"""The packages' names load on first use (:mod:`pulses.lazy`): ``import rocking`` and ``import
pulses`` load neither numpy nor scipy, every public name resolves to its module's object, and
``rocking.fragility`` stays the function when its module is imported."""
from __future__ import annotations

import subprocess
import sys
import types

import pytest

import pulses
import rocking
from pulses.lazy import lazy_names


@pytest.mark.parametrize("package", [pulses, rocking])
def test_every_public_name_is_its_modules_object(package):
    import importlib

    for name in package.__all__:
        value = getattr(package, name)
        module = package._WHERE.get(name)
        if module is None:  # a public submodule
            where = f"{package.__name__}.{package._MODULES[name]}"
            assert isinstance(value, types.ModuleType) and value.__name__ == where
        else:
            assert value is getattr(importlib.import_module(f"{package.__name__}.{module}"), name)
        assert name in dir(package)
    with pytest.raises(AttributeError, match=f"module '{package.__name__}' has no attribute 'no_such_name'"):
        package.no_such_name  # noqa: B018


def test_a_name_is_looked_up_once_and_kept():
    getattr_, dir_ = lazy_names("pulses", {"G": "units"})
    vars(pulses).pop("G", None)
    assert "G" not in vars(pulses) and "G" in dir_()
    from pulses.units import G

    assert getattr_("G") == G and vars(pulses)["G"] == G
    with pytest.raises(AttributeError):
        getattr_("Record")  # not in this table


def test_rocking_fragility_stays_the_function():
    import importlib

    module = importlib.import_module("rocking.fragility")  # binds the module to the package
    assert isinstance(module, types.ModuleType)
    assert rocking.fragility is module.fragility and callable(rocking.fragility)


@pytest.mark.slow
def test_importing_the_packages_loads_no_numerics():
    code = "import sys, pulses, rocking; print(sorted(m for m in ('numpy', 'scipy') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.parametrize("given", [None, "3"])
def test_the_command_runs_one_blas_thread_unless_told_otherwise(given):
    # numpy is imported by the command itself, after the setting, so numpy's BLAS and the worker
    # processes the command starts see it; a value the user set stays
    import os

    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    code = ("import os, sys\nfrom pipeline.cli import main\nassert 'numpy' not in sys.modules\n"
            "main(['design', '--block', '7.5x1.8', '--pulse', 'sine', '--ap', '0.5g', '--tp', '1'])\n"
            "assert 'numpy' in sys.modules\n"
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['MKL_NUM_THREADS'])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.split()[-2:] == [given or "1", "1"]
