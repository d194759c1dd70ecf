"""Every public result object exports: ``as_dict()`` gives plain numbers that :func:`json.dumps`
writes as they are (no NaN), ``to_frame()`` rows where rows make sense, and
:func:`pulses.to_frame` makes one DataFrame of a list of results."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

import pulses
import rocking
from pulses.export import plain

SINE = pulses.make_pulse("sine", 0.4 * pulses.G, 1.0, 1.0)
BLOCK = rocking.Block.from_dimensions(7.5, 1.2)


def _json_round_trip(d):
    """``d`` is plain data: JSON writes it strictly (no NaN) and reads back the same."""
    assert json.loads(json.dumps(d, allow_nan=False)) == d
    return d


def test_plain_turns_numpy_and_nan_into_json_data():
    d = plain({"a": np.float32(0.5), "b": np.array([1, 2]), "c": math.inf, 1: (np.bool_(False), None)})
    assert d == {"a": 0.5, "b": [1, 2], "c": None, "1": [False, None]}
    assert type(d["b"][0]) is int


def test_rocking_result_as_dict_and_history_frame():
    res = rocking.simulate(BLOCK, SINE)
    d = _json_round_trip(res.as_dict())
    assert d["overturned"] == res.overturned and d["max_rotation_ratio"] == res.max_rotation_ratio
    assert d["p_rad_s"] == BLOCK.p and d["model"] == res.model
    df = res.to_frame()
    assert list(df.columns) == ["t_s", "theta_rad", "omega_rad_s"] and len(df) == res.t.size
    assert np.array_equal(df["theta_rad"], res.theta) and np.array_equal(df["t_s"], res.t)
    assert df["theta_rad"].abs().max() <= res.max_rotation  # the peak is between nodes, or after


def test_batch_result_frame_has_a_row_per_run():
    blocks = [rocking.Block.from_dimensions(7.5, w) for w in (0.6, 1.2, 2.4)]
    many = rocking.simulate_many(blocks, SINE)
    df = many.to_frame()
    assert len(df) == 3 and list(df["overturned"]) == list(many.overturned)
    assert _json_round_trip(many.as_dict())["overturned"] == [bool(x) for x in many.overturned]


def test_required_width_min_slenderness_and_governing_pulse_as_dict():
    w = rocking.required_width(7.5, SINE, rule="eq31")
    d = _json_round_trip(w.as_dict())
    assert d["width"] == w.width and d["tan_alpha"] == w.tan_alpha and "check_widths" not in d
    assert w.to_frame().empty  # no check for a closed-form rule
    m = rocking.min_slenderness(SINE, p=BLOCK.p)
    dm = _json_round_trip(m.as_dict())
    assert dm["tan_alpha"] == m.tan_alpha and dm["transitions"] == list(m.transitions)
    t = np.arange(0.0, 8.0, 0.01)
    fit = pulses.fit_pulse(pulses.Record(SINE(t), 0.01), shapes=["sine", "ricker-sym"])
    g = _json_round_trip(rocking.governing_pulse(fit, 7.5).as_dict())
    assert g["eq31_width_m"] == max(g["widths_m"].values())


def test_classification_spectrum_fragility_critical_amplitudes():
    t = np.arange(0.0, 20.0, 0.01)
    rec = pulses.Record(pulses.make_pulse("sine", 4.0, 1.5, 5.0)(t), 0.01)
    c = pulses.classify_pulse(rec)
    _json_round_trip(c.as_dict())
    df = c.to_frame()
    assert len(df) == len(c.candidates) and df["chosen"].sum() == 1
    assert df.loc[df["chosen"], "tp"].item() == c.tp
    spec = rocking.overturning_spectrum(0.2, "sine", [2.0, 4.0], [1.0, 3.0])
    assert _json_round_trip(spec.as_dict())["overturned"] == spec.overturned.tolist()
    f = rocking.fragility([1.2, 1.5, 2.0, None], up_to=3.0)
    df_ = _json_round_trip(f.as_dict())
    assert df_["median"] == f.median and df_["values"][-1] is None  # inf (censored) as None
    amps = rocking.critical_amplitudes(BLOCK, "sine", 1.0)
    _json_round_trip(amps.as_dict())
    assert len(amps.to_frame()) == len(amps)


def test_a_list_of_results_is_one_frame():
    results = [rocking.required_width(h, SINE, rule="eq31") for h in (5.0, 7.5, 10.0)]
    df = pulses.to_frame(results)
    assert list(df["height"]) == [5.0, 7.5, 10.0] and list(df["width"]) == [r.width for r in results]
    with pytest.raises(TypeError, match="as_dict"):
        pulses.to_frame([1.0])


@pytest.mark.parametrize("module", ["pulses.export", "pulses.io.streams", "pulses.record", "pulses.shapes",
                                    "pulses.velocity", "pulses.scenario", "pulses.fit.fitter", "pulses.fit.results", "pulses.pairs",
                                    "pulses.formats.sac", "pulses.io.read", "rocking.governing", "rocking.widths", "rocking._common",
                                    "rocking.slenderness", "rocking.block", "rocking.closed_forms", "rocking.frame",
                                    "rocking.solver", "rocking.fragility", "rocking.spectrum",
                                    "rocking.reference_vertical", "pulses.errors", "pipeline.api"])
def test_the_examples_of_the_docstrings_run(module):
    """The Examples sections of the export, obspy, governing-pulse and batch docstrings (the API
    pages show them)."""
    import doctest
    import importlib

    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted > 0, module
