"""Re-derive the flight limit-cycle tables of benchmarks/RESULTS.md (paper figs. 7-8, F5/F6).

Run:  .venv/bin/python scripts/lco_tables.py [--no-map] [--out lco_tables.md]

Prints (and writes, with ``--out``) three markdown tables computed on the shipped files as they
are now (``models/rs25_flight.toml`` with its one servo parameter set and gimbal friction set,
``models/flight/core_stage.toml``):

1. F5/F6: per friction law and load stiffness (115,000 / 205,000 lbf/in, set through
   ``Structure(K_L)`` as tests/test_lco.py does), the describing-function prediction (command and
   engine amplitude, frequency, or the remaining margin) beside the time-domain run (160 s from a
   0.2 deg attitude error, last 60 s measured). The grid is the test grid: 8 command amplitudes
   0.01-1 deg x 6 frequencies 0.06-0.5 Hz; bounding -1 dB avionics.
2. The knife edge: Dahl, bristle stiffness x the flight loop's integral gain, both stiffnesses
   (prediction only, :func:`taos.flight.lco_map.lco_map`).
3. The loop's own low-frequency gain margin for each integral gain.

Nothing here is tuned: it reads the shipped files and reports what they give.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from taos.flight.lco import analyse_lco
from taos.flight.lco_map import SweepAxis, lco_map
from taos.flight.vehicle import load_flight
from taos.model import Structure, load_model
from taos.units import N_PER_M_PER_LBF_PER_IN as LBF_IN

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "models" / "rs25_flight.toml"
FLIGHT = ROOT / "models" / "flight" / "core_stage.toml"
DEG = math.pi / 180
AMPS = np.logspace(np.log10(0.01), 0.0, 8) * DEG
FREQ = np.logspace(np.log10(0.06), np.log10(0.5), 6)
LAWS = ("coulomb-switching", "coulomb-smooth", "dahl", "lugre", "modified-lugre")
STIFF = (115000, 205000)


def f5f6_rows() -> list[str]:
    fl = load_flight(FLIGHT)
    rows = ["| K_L [lbf/in] | law | prediction: command / engine [deg], f [Hz] or margin | "
            "time domain: command / engine [deg], f [Hz] | TD engine 3rd harmonic |",
            "|---|---|---|---|---|"]
    for kl in STIFF:
        for law in LAWS:
            m = load_model(MODEL, friction=law).replace(structure=Structure(kl * LBF_IN))
            t0 = time.perf_counter()
            d = analyse_lco(fl, m, amplitudes_rad=AMPS, freq_hz=FREQ, duration_s=160.0, window_s=60.0).to_dict()
            td = d["time_domain"]
            pred = (f"{d['amplitude_deg']:.3f} / {d['engine_amplitude_deg']:.3f}, {d['frequency_hz']:.3f}"
                    if d["lco"] else f"no LCO, margin {d['margin_db']:.2f} dB")
            tds = (f"{td['amplitude_deg']:.3f} / {td['engine_amplitude_deg']:.3f}, {td['frequency_hz']:.3f}"
                   if td["lco"] else "none")
            h3 = td.get("engine_third_harmonic")
            rows.append(f"| {kl:,} | {law} | {pred} | {tds} | {'-' if h3 is None else f'{h3:.3f}'} |")
            print(rows[-1], f"({time.perf_counter() - t0:.0f} s)", flush=True)
    return rows


def knife_edge_rows() -> list[str]:
    fl = load_flight(FLIGHT)
    s0 = SweepAxis("bristle_stiffness", (0.8e7, 1.3e7, 2.2e7))
    ki = SweepAxis("integral_gain", (0.6, 0.78, 0.9))
    rows: list[str] = []
    for kl in STIFF:
        m = load_model(MODEL, friction="dahl").replace(structure=Structure(kl * LBF_IN))
        mp = lco_map(fl, m, (s0, ki), amplitudes_rad=AMPS, freq_hz=FREQ)
        lgm = mp.loop_low_gain_margin_db
        head = " | ".join(f"{v} ({lgm[f'integral_gain={v:.6g}']:.2f} dB)" for v in ki.values)
        rows += [f"K_L {kl:,} lbf/in, Dahl:", "", f"| sigma_0 [N m/rad] \\ K_i [1/s] | {head} |",
                 "|---|---|---|---|"]
        for i, sv in enumerate(s0.values):
            cells = []
            for j in range(len(ki.values)):
                if mp.lco[i, j]:
                    cells.append(f"{mp.engine_amplitude_deg[i, j]:.3f} @ {mp.frequency_hz[i, j]:.3f}")
                else:
                    cells.append(f"none ({mp.margin_db[i, j]:.2f})")
            rows.append(f"| {sv:.2g} | " + " | ".join(cells) + " |")
        rows.append("")
        print("\n".join(rows[-6:]), flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-map", action="store_true", help="skip the knife-edge map")
    ap.add_argument("--out", type=Path, help="also write the tables (markdown) here")
    a = ap.parse_args()
    rows = f5f6_rows()
    if not a.no_map:
        rows += ["", *knife_edge_rows()]
    if a.out:
        a.out.write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
