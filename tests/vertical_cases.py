"""Cases shared by the tests of the vertical ground motion (docs/theory.md section 10)."""
from __future__ import annotations

import numpy as np

import pulses
import rocking
from pulses import G

from .conftest import SHARED_RECORDS

#: the real PEER download with vertical components (../shared beside the checkout)
DOWNLOAD = SHARED_RECORDS.parent / "peer_download"

#: a slender column that overturns, one that rocks, one that stands tall
BLOCKS = [rocking.Block.from_dimensions(3.0, 0.6), rocking.Block.from_dimensions(3.0, 0.9),
          rocking.Block.from_dimensions(7.5, 1.8)]
IDS = ["overturns", "rocks", "stands-tall"]


def record(seed=0, ap_g=0.35, tp=1.0, dt=0.01, duration=6.0):
    """A one-sine pulse with a little high-frequency motion: uplift, impacts, free rocking."""
    t = np.arange(0.0, duration, dt)
    rng = np.random.default_rng(seed)
    acc = pulses.make_pulse("sine", ap_g * G, tp, 0.5)(t) + 0.02 * G * np.sin(7 * t + rng.uniform(0, 6))
    return pulses.Record(acc, dt)
