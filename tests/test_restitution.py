"""The restitution as a design input: parsing, the three ways of stating it, bands, blocks."""
import math

import numpy as np
import pytest

import rocking
from rocking.restitution import Restitution


def _housner(alpha):
    # Eq. 5 written out here, independently of rocking.eta_housner
    return 1.0 - 1.5 * math.sin(alpha) ** 2


@pytest.mark.parametrize("text, kind, low, high", [
    ("1.025", "factor", 1.025, 1.025), ("0.95:1.05", "factor", 0.95, 1.05),
    ("eta=0.9", "eta", 0.9, 0.9), ("ETA = 0.85:0.93", "eta", 0.85, 0.93),
    ("r=0.7:0.85", "r", 0.7, 0.85), (" 0.67 ", "factor", 0.67, 0.67)])
def test_parse(text, kind, low, high):
    value = Restitution.parse(text)
    assert (value.kind, value.low, value.high) == (kind, low, high)
    assert Restitution.parse(str(value)) == value            # str reads back


@pytest.mark.parametrize("text", ["", "abc", "1:2:3", "eta=1.2", "r=-0.1", "1.1:0.9", "mu=0.5",
                                  "nan", "eta=0.9:inf"])
def test_parse_refuses_in_one_line(text):
    with pytest.raises(ValueError) as err:
        Restitution.parse(text)
    assert "\n" not in str(err.value) and "restitution" in str(err.value)


def test_eta_at_each_kind():
    alpha = math.atan(1.8 / 7.5)
    assert Restitution(1.0).eta_at(alpha) == pytest.approx(_housner(alpha), rel=1e-15)
    assert Restitution(0.97).eta_at(alpha) == pytest.approx(0.97 * _housner(alpha), rel=1e-15)
    assert Restitution(0.9, kind="eta").eta_at(alpha) == 0.9
    assert Restitution(0.81, kind="r").eta_at(alpha) == pytest.approx(0.9, rel=1e-15)
    # a factor above 1 saturates at a perfectly elastic impact (no energy created)
    assert Restitution(1.5).eta_at(0.05) == 1.0
    with pytest.raises(ValueError, match="band"):
        Restitution(0.9, 1.1).eta_at(alpha)


def test_values_and_sample():
    band = Restitution.parse("0.9:1.1")
    assert [v.low for v in band.values(5)] == pytest.approx([0.9, 0.95, 1.0, 1.05, 1.1], abs=1e-15)
    assert band.values(5)[-1].low == 1.1                      # the ends exactly
    draws = band.sample(np.random.default_rng(3), 200)
    lows = np.array([d.low for d in draws])
    assert lows.min() >= 0.9 and lows.max() <= 1.1 and not any(d.is_band for d in draws)
    assert [d.low for d in band.sample(np.random.default_rng(3), 200)] == lows.tolist()  # seeded
    assert Restitution(0.95).values(7) == [Restitution(0.95)]


def test_blocks_take_a_restitution():
    heights, widths = 7.5, [1.2, 1.8, 2.4]
    factor = Restitution(0.95)
    many = rocking.Blocks.from_dimensions(heights, widths, factor)
    for w, eta in zip(widths, many.eta):
        alpha = math.atan(w / heights)
        assert eta == pytest.approx(0.95 * _housner(alpha), rel=1e-15)
        one = rocking.Block.from_dimensions(heights, w, factor)
        assert one.eta == eta and one == rocking.Block.from_dimensions(heights, w, eta)
    assert (rocking.Blocks.from_dimensions(heights, widths, Restitution(1.0)).eta
            == rocking.Blocks.from_dimensions(heights, widths).eta).all()
    with pytest.raises(ValueError, match="band"):
        rocking.Block.from_dimensions(heights, 1.8, Restitution(0.9, 1.0))


def test_describe():
    assert Restitution(1.0).describe() == "Eq. 5"
    assert Restitution(0.95, 1.05).describe() == "0.95-1.05 x Eq. 5"
    assert Restitution(0.9, kind="eta").describe() == "eta 0.9"
