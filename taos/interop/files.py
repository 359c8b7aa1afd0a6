"""Linear models and responses exported for other tools: MATLAB ``.mat`` and CSV.

What is written, per axis (``pitch``, ``yaw``), from :func:`taos.planar.simplex.simplex_state_space`
(x' = A x + B u, y = C x + D u; SI states, inputs and outputs named) and
:func:`taos.planar.freqresp.linear_freqresp` (the project's conventions: piston x_p / (R theta_c),
phase continuous from low frequency):

* ``.mat`` (``scipy.io.savemat``): a struct per axis with ``A, B, C, D``, ``states``,
  ``inputs``, ``outputs`` (cell arrays of names), ``freq_hz``, complex ``piston`` and
  ``engine``, ``piston_gain_db``, ``piston_phase_deg``, ``engine_gain_db``,
  ``engine_phase_deg``, and the model's provenance (file, SHA-256, moment arm);
  ``ss(A, B, C, D)`` in MATLAB rebuilds the model.
* CSV: a folder with ``<axis>_A.csv``, ``_B.csv``, ``_C.csv``, ``_D.csv`` (header row and
  first column name the signals) and ``<axis>_freqresp.csv`` (freq_hz, gains, phases).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..model import TvcModel
from ..results import atomic_write
from taos.results import model_provenance

AXES = ("pitch", "yaw")


def linear_export_data(model: TvcModel, freq_hz) -> dict:
    """{axis: dict of arrays} as written by :func:`export_mat` / :func:`export_csv`."""
    from ..planar.freqresp import linear_freqresp
    from ..linear import gain_db
    from ..planar.simplex import simplex_state_space

    out = {}
    for ax in AXES:
        ss = simplex_state_space(model, ax)
        fr = linear_freqresp(model, freq_hz, ax)
        out[ax] = {"A": ss.A, "B": ss.B, "C": ss.C, "D": ss.D, "states": list(ss.states),
                   "inputs": list(ss.inputs), "outputs": list(ss.outputs), "freq_hz": fr.freq_hz,
                   "piston": fr.piston, "engine": fr.engine, "piston_gain_db": gain_db(fr.piston),
                   "piston_phase_deg": fr.piston_phase_deg(), "engine_gain_db": gain_db(fr.engine),
                   "engine_phase_deg": fr.engine_phase_deg(),
                   "piston_definition": "x_p/(R theta_c), phase continuous from low frequency",
                   **model_provenance(model),
                   "moment_arm_m": model.actuator.moment_arm_m}
    return out


def export_mat(model: TvcModel, path, freq_hz) -> None:
    """Write the ``.mat`` file (module docstring) atomically."""
    import scipy.io

    data = linear_export_data(model, freq_hz)
    mat = {ax: {k: (np.array(v, dtype=object) if isinstance(v, list) else v) for k, v in d.items()}
           for ax, d in data.items()}
    atomic_write(path, lambda p: scipy.io.savemat(str(p), mat, do_compression=True))


def _matrix_csv(M, rows, cols) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow([""] + list(cols))
    for name, r in zip(rows, np.asarray(M, float)):
        w.writerow([name] + [repr(float(x)) for x in r])
    return buf.getvalue()


def export_csv(model: TvcModel, folder, freq_hz) -> list[Path]:
    """Write the CSV files (module docstring) into ``folder``; returns their paths."""
    data = linear_export_data(model, freq_hz)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for ax, d in data.items():
        for name, rows, cols in (("A", d["states"], d["states"]), ("B", d["states"], d["inputs"]),
                                 ("C", d["outputs"], d["states"]), ("D", d["outputs"], d["inputs"])):
            p = folder / f"{ax}_{name}.csv"
            text = _matrix_csv(d[name], rows, cols)
            atomic_write(p, lambda q, text=text: q.write_text(text))
            written.append(p)
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["freq_hz", "piston_gain_db", "piston_phase_deg", "engine_gain_db", "engine_phase_deg"])
        for row in zip(d["freq_hz"], d["piston_gain_db"], d["piston_phase_deg"], d["engine_gain_db"],
                       d["engine_phase_deg"]):
            w.writerow([repr(float(x)) for x in row])
        p = folder / f"{ax}_freqresp.csv"
        text = f"# {d['piston_definition']}; model {d['model_file']}\n" + buf.getvalue()
        atomic_write(p, lambda q, text=text: q.write_text(text))
        written.append(p)
    return written
