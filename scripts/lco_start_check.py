"""Does starting the time-domain confirmation on the predicted cycle change any verdict?

Run:  PYTHONPATH=. .venv/bin/python scripts/lco_start_check.py [--out check.md]

Every case is a verdict map (:func:`taos.flight.lco_map.lco_map`) run twice, with the
confirmation started on the describing function's periodic solution and from rest (0.2 deg
attitude error, 300 s, the last 120 s measured: the ``taos lco`` run), on the shipped files:

* the knife-edge map of benchmarks/RESULTS.md: Dahl, bristle stiffness 0.8e7, 1.3e7, 2.2e7 N m/rad
  x integral gain 0.6, 0.78, 0.9 1/s, at 115,000 and 205,000 lbf/in (test grid: 8 amplitudes
  0.01-1 deg x 6 frequencies 0.06-0.5 Hz);
* the cases of tests/test_lco*.py: F5/F6 (five laws x two stiffnesses, test grid), the verdict
  tests' grid (Coulomb soft, Dahl stiff), the flown quantiser (no friction and Dahl, stiff,
  ``--avionics model``).

Prints one row per point: both verdicts, the confirmed command and engine amplitudes and
frequencies, and their ratios; then the largest differences.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from taos.flight.lco_map import SweepAxis, lco_map
from taos.flight.vehicle import load_flight
from taos.model import Structure, load_model
from taos.units import N_PER_M_PER_LBF_PER_IN as LBF_IN

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "rs25_flight.toml"
FLIGHT = ROOT / "models" / "flight" / "core_stage.toml"
DEG = math.pi / 180
AMPS = tuple(np.logspace(np.log10(0.01), 0.0, 8) * DEG)
FREQ = tuple(np.logspace(np.log10(0.06), np.log10(0.5), 6))
GRID_A = tuple(np.array([0.02, 0.05, 0.1, 0.2, 0.5]) * DEG)
GRID_F = (0.05, 0.08, 0.12, 0.2, 0.3)
LAWS = ("coulomb-switching", "coulomb-smooth", "dahl", "lugre", "modified-lugre")


def cases():
    """(label, model, axes, lco_map keywords)."""
    for kl in (115000, 205000):
        m = load_model(MODEL, friction="dahl").replace(structure=Structure(kl * LBF_IN))
        yield (f"knife edge, dahl, {kl} lbf/in", m,
               (SweepAxis("bristle_stiffness", (0.8e7, 1.3e7, 2.2e7)), SweepAxis("integral_gain", (0.6, 0.78, 0.9))),
               {"amplitudes_rad": AMPS, "freq_hz": FREQ})
    for law in LAWS:
        yield (f"F5/F6, {law}", load_model(MODEL, friction=law),
               (SweepAxis("load_stiffness", (115000 * LBF_IN, 205000 * LBF_IN)),), {"amplitudes_rad": AMPS,
                                                                                    "freq_hz": FREQ})
    yield ("verdict test, coulomb-switching soft", load_model(MODEL, friction="coulomb-switching"),
           (SweepAxis("integral_gain", (0.78,)),), {"amplitudes_rad": GRID_A, "freq_hz": GRID_F})
    yield ("verdict test, dahl stiff", load_model(MODEL, friction="dahl"),
           (SweepAxis("load_stiffness", (205000 * LBF_IN,)),), {"amplitudes_rad": GRID_A, "freq_hz": GRID_F})
    for law in ("none", "dahl"):
        yield (f"quantiser, {law}, stiff, flown avionics", load_model(MODEL, friction=law),
               (SweepAxis("load_stiffness", (205000 * LBF_IN,)),), {"freq_hz": FREQ, "avionics": "model"})


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out")
    a = ap.parse_args()
    fl = load_flight(FLIGHT)
    rows = ["| case | point | verdict predicted-start / from-rest | command [deg] | engine [deg] | f [Hz] | "
            "simulated [s] |", "|---|---|---|---|---|---|---|"]
    worst = {"amplitude": 0.0, "engine": 0.0, "frequency": 0.0}
    differ = 0
    for label, m, axes, kw in cases():
        t0 = time.perf_counter()
        p = lco_map(fl, m, axes, time_domain=True, start="predicted", **kw)
        t1 = time.perf_counter()
        r = lco_map(fl, m, axes, time_domain=True, start="rest", **kw)
        t2 = time.perf_counter()
        print(f"{label}: {t1 - t0:.1f} s predicted start, {t2 - t1:.1f} s from rest", flush=True)
        for idx in np.ndindex(p.lco.shape):
            where = ", ".join(f"{x.name}={x.values[i]:.4g}" for x, i in zip(axes, idx))
            same = bool(p.lco[idx]) == bool(r.lco[idx])
            differ += not same
            v = f"{'LCO' if p.lco[idx] else 'none'} / {'LCO' if r.lco[idx] else 'none'}" + ("" if same else " DIFFER")
            cells = []
            for key, name in (("td_amplitude_deg", "amplitude"), ("td_engine_amplitude_deg", "engine"),
                              ("td_frequency_hz", "frequency")):
                x, y = p.td[key][idx], r.td[key][idx]
                if p.lco[idx] and r.lco[idx]:
                    worst[name] = max(worst[name], abs(x / y - 1))
                    cells.append(f"{x:.4g} / {y:.4g} ({x / y - 1:+.2%})")
                else:
                    cells.append("-")
            rows.append(f"| {label} | {where} | {v} | {' | '.join(cells)} | "
                        f"{p.td['td_simulated_s'][idx]:.0f} / {r.td['td_simulated_s'][idx]:.0f} |")
    rows.append("")
    rows.append(f"verdicts that differ: {differ}; largest relative differences of the confirmed cycles: "
                + ", ".join(f"{k} {v:.2%}" for k, v in worst.items()))
    text = "\n".join(rows)
    print(text)
    if a.out:
        Path(a.out).write_text(text + "\n")


if __name__ == "__main__":
    main()
