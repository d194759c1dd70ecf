"""Section 5 of RESULTS.md: issue 4's design timings."""
from __future__ import annotations

import math

import numpy as np

from benchmarks.common import fmt_t, log, per_call, timed


def measure(quick):
    """Section 5: issue 4's design timings.  Returns plain data (a dict of times in s, medians as
    :class:`benchmarks.common.TStat`) for :func:`benchmarks.results.design_section`.
    """
    import rocking
    from pulses import G, make_pulse
    from rocking.spectrum import CHART_APG, CHART_PTP

    log("design: issue 4 timings")
    res = {}
    rinaldi = make_pulse("sine", 0.71 * G, 0.8)
    rocking.min_slenderness(rinaldi, 1.381)
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        pulse = make_pulse(shape, 0.71 * G, 0.8)
        res[f"min_slenderness {shape}"] = per_call(lambda: rocking.min_slenderness(pulse, 1.381), 0.5, 3)
        log(f"  min_slenderness {shape}: {fmt_t(res[f'min_slenderness {shape}'])}")
    from rocking import lanes

    threads = lanes.get_threads()
    try:
        lanes.set_threads(1)
        for shape in ("sine", "ricker-sym"):
            pulse = make_pulse(shape, 0.71 * G, 0.8)
            res[f"min_slenderness {shape} 1 thread"] = per_call(lambda: rocking.min_slenderness(pulse, 1.381), 0.5, 3)
            log(f"  min_slenderness {shape}, one thread: {fmt_t(res[f'min_slenderness {shape} 1 thread'])}")
    finally:
        lanes.set_threads(threads)
    alpha = math.radians(14.0)
    wp, ratio = np.linspace(0.5, 12, 200), np.linspace(1, 6, 200)
    for shape in (("sine",) if quick else ("sine", "ricker-sym")):
        res[f"spectrum 200x200 {shape}"] = timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
        log(f"  spectrum 200x200 {shape}: {res[f'spectrum 200x200 {shape}']:.2f} s")
    chart_shapes = ("sine",) if quick else ("rect", "sine", "ricker-sym", "ricker-anti")
    frame, sec = timed(lambda: rocking.slenderness_chart(chart_shapes, CHART_PTP, CHART_APG))
    res["chart"] = sec
    res["chart_shapes"] = len(chart_shapes)
    log(f"  chart ({len(chart_shapes)} shape(s) x 8 pTp x 20 ap/g): {sec:.1f} s")
    try:
        rw, sec_w = timed(lambda: rocking.required_width(7.5, rinaldi, rule="exact"))
        res["required_width exact (Rinaldi pulse)"] = sec_w
        res["_width"] = rw.width if hasattr(rw, "width") else None
    except Exception as exc:  # noqa: BLE001
        log(f"  required_width failed: {exc}")
    return res
