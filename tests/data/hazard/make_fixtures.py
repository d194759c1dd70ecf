"""Writes the hazard-curve fixtures of this folder, each laid out as its program writes it
(header lines, columns, number formats), with values of this package's own making: power laws
``lambda = k0 x^-k`` tabulated at each program's levels.  Run from this folder; the files are
committed, so the tests do not run this."""
import json
import math
import os

import numpy as np

OQ_LEVELS = [0.005, 0.0075, 0.0113, 0.0169, 0.0253, 0.038, 0.057, 0.0854, 0.128, 0.192, 0.288,
             0.432, 0.649, 0.973, 1.46, 2.19, 3.28, 4.92, 7.38]
NSHMP_PGA = [0.005, 0.007, 0.0098, 0.0137, 0.0192, 0.0269, 0.0376, 0.0527, 0.0738, 0.103, 0.145,
             0.203, 0.284, 0.397, 0.556, 0.778, 1.09, 1.52, 2.2, 3.3]


def rates(levels, k0, k, cut=1e-10):
    y = k0 * np.asarray(levels) ** -k
    return np.where(y < cut, 0.0, np.minimum(y, 0.05))


def poe(rate, time):
    return -np.expm1(-rate * time)


def openquake_current():
    sites = [(-122.4, 37.75, 2e-4, 2.2), (-118.25, 34.05, 4e-4, 2.0), (-142.3, 58.8, 0.0, 2.0),
             (23.7, 37.97, 1e-4, 2.6)]
    head = ('#,,,,,,,,,,,,,,,,,,,,,"generated_by=\'OpenQuake engine 3.18.0\', start_date=\'2024-03-07T08:54:45\', '
            "checksum=1900910711, kind='mean', investigation_time=50.0, imt='SA(1.0)'\"")
    cols = "lon,lat,depth," + ",".join(f"poe-{x:.7f}" for x in OQ_LEVELS)
    lines = [head, cols]
    for lon, lat, k0, k in sites:
        p = poe(rates(OQ_LEVELS, k0, k), 50.0) if k0 else np.zeros(len(OQ_LEVELS))
        lines.append(f"{lon:.5f},{lat:.5f},0.00000," + ",".join(f"{v:.6E}" for v in p))
    with open("hazard_curve-mean-SA(1.0)_42.csv", "w") as fh:
        fh.write("\n".join(lines) + "\n")


def openquake_older():
    levels = [0.1, 0.4, 0.6]
    head = "# source_model_tree_path=('b1',), gsim_tree_path=('b1',), investigation_time=1.0,imt=\"PGA\""
    p = poe(rates(levels, 6e-3, 2.0), 1.0)
    with open("hazard_curve-PGA.csv", "w") as fh:
        fh.write(head + "\nlon,lat,depth," + ",".join(f"poe-{x:g}" for x in levels) + "\n"
                 + "0.00000,0.00000,-0.10000," + ",".join(f"{v:.6E}" for v in p) + "\n")


def nshmp():
    sites = [("Concord CA", -122.0, 37.95, 3e-4, 2.4), ("Oakland CA", -122.25, 37.8, 1.5e-4, 2.8),
             ("San Jose CA", -121.9, 37.35, 6e-5, 3.1)]
    for imt, levels in (("PGA", NSHMP_PGA), ("SA1P0", [x / 2 for x in NSHMP_PGA])):
        os.makedirs(f"nshmp/curves/{imt}", exist_ok=True)
        lines = ["name,lon,lat," + ",".join(f"{x:g}" for x in levels)]
        for name, lon, lat, k0, k in sites:
            y = rates(levels, k0, k, cut=2e-6)
            lines.append(f"{name},{lon:.5f},{lat:.5f}," + ",".join("0.0" if v == 0 else f"{v:.8e}" for v in y))
        with open(f"nshmp/curves/{imt}/total.csv", "w") as fh:
            fh.write("\n".join(lines) + "\n")


def usgs_json():
    xs = [0.0025, 0.0045, 0.0075, 0.0113, 0.0169, 0.0253, 0.038, 0.057, 0.0854, 0.128, 0.192,
          0.288, 0.432, 0.649, 0.973, 1.46, 2.19, 3.28, 4.92, 7.38]
    response = []
    for value, display, k0, k in (("PGA", "Peak Ground Acceleration", 3e-4, 2.3),
                                  ("SA1P0", "1.00 Second Spectral Acceleration", 1.2e-4, 2.1)):
        total = rates(xs, k0, k, cut=1e-12)
        response.append({
            "metadata": {"edition": {"id": 1, "value": "E2014", "display": "Dynamic: Conterminous U.S. 2014 (v4.1.1)"},
                         "region": {"id": 1, "value": "COUS", "display": "Conterminous U.S."},
                         "latitude": 34.05, "longitude": -118.25,
                         "imt": {"id": 1, "value": value, "display": display},
                         "vs30": {"id": 1, "value": "760", "display": "760 m/s (B/C boundary)"},
                         "xlabel": "Ground Motion (g)", "ylabel": "Annual Frequency of Exceedence",
                         "xvalues": xs},
            "data": [{"component": "Total", "yvalues": [float(v) for v in total]},
                     {"component": "Fault", "yvalues": [float(0.7 * v) for v in total]},
                     {"component": "Grid", "yvalues": [float(0.3 * v) for v in total]}]})
    doc = {"status": "success", "date": "2024-03-07T08:54:45-07:00",
           "url": "https://earthquake.usgs.gov/nshmp-haz-ws/hazard/E2014/COUS/-118.25/34.05/any/760",
           "server": {"name": "nshmp-haz-ws", "version": "1.1.4"}, "response": response}
    with open("usgs_hazard.json", "w") as fh:
        json.dump(doc, fh, indent=2)


def plain():
    x = np.geomspace(0.02, 3.0, 25)
    with open("plain_pga.csv", "w") as fh:
        fh.write("# site: Temple column, a curve made for the docs\n# measure: PGA\n# units: g\n"
                 "iml,rate\n" + "".join(f"{a:.6g},{b:.6e}\n" for a, b in zip(x, rates(x, 2e-4, 2.5))))
    with open("plain_unstated.csv", "w") as fh:
        fh.write("".join(f"{a:.6g},{b:.6e}\n" for a, b in zip(x, rates(x, 2e-4, 2.5))))


if __name__ == "__main__":
    openquake_current()
    openquake_older()
    nshmp()
    usgs_json()
    plain()
