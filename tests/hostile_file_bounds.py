"""Hostile-input cases of the ``bounds`` group for campaign, ascent and profile files (issue 25):
every bound of :data:`taos.bounds.CAMPAIGN_BOUNDS`, :data:`~taos.bounds.ASCENT_BOUNDS` and
:data:`~taos.bounds.PROFILE_BOUNDS` crossed from below and above, and the cross-field checks.
Collected into :data:`tests.hostile_cases.CASES`; run by ``tests/test_hostile.py``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

from taos.bounds import ASCENT_BOUNDS, CAMPAIGN_BOUNDS

from .hostile_cases import AMBIENT, ASCENT, MODELS, Case, edited_toml, write

CAMPAIGN = MODELS / "montecarlo" / "post_separation.toml"


def _toml_copy(work: Path, src: Path, name: str, edit: Callable, paths: dict) -> Path:
    """``src`` with its relative paths (``paths``: text -> absolute) made absolute, edited through tomlkit."""
    text = src.read_text()
    for a, b in paths.items():
        text = text.replace(a, b)
    return write(work, name, edited_toml(text, edit))


def campaign_copy(work: Path, edit: Callable) -> Path:
    return _toml_copy(work, CAMPAIGN, "c.toml", edit, {'"../flight/ascent.toml"': f'"{MODELS}/flight/ascent.toml"'})


def ascent_copy(work: Path, edit: Callable) -> Path:
    return _toml_copy(work, ASCENT, "a.toml", edit, {'"core_stage.toml"': f'"{MODELS}/flight/core_stage.toml"',
                                                      '"../rs25_flight.toml"': f'"{MODELS}/rs25_flight.toml"'})


def _set(path: tuple, value):
    def edit(doc):
        t = doc
        for k in path[:-1]:
            t = t[k]
        t[path[-1]] = value
    return edit


def _mc(edit):
    return lambda w: ["montecarlo", campaign_copy(w, edit), "--runs", "1", "--out", w / "mc"]


DISP = ("dispersions", "coulomb_torque")
#: (bound, below/above, edit, the field the one line names: a duration below the shortest
#: analysis window is caught as the window's)
CAMPAIGN_ROWS = [
    ("seed", "below", _set(("seed",), -1), "seed"),
    ("seed", "above", _set(("seed",), 2 ** 63), "seed"),
    ("start", "below", _set(("start",), "-1 s"), "start"),
    ("start", "above", _set(("start",), "3000 s"), "start"),
    ("duration", "below", _set(("duration",), "5 s"), "analysis_window"),
    ("duration", "above", _set(("duration",), "3000 s"), "duration"),
    ("dt", "below", _set(("dt",), "1 ns"), "dt"),
    ("dt", "above", _set(("dt",), "20 ms"), "dt"),
    ("analysis_window", "below", _set(("analysis_window",), "1 s"), "analysis_window"),
    ("analysis_window", "above", _set(("analysis_window",), "300 s"), "analysis_window"),
    ("trace_interval", "below", _set(("trace_interval",), "1 us"), "trace_interval"),
    ("trace_interval", "above", _set(("trace_interval",), "100 s"), "trace_interval"),
    ("update_interval", "below", _set(("update_interval",), "1 ms"), "update_interval"),
    ("update_interval", "above", _set(("update_interval",), "1 min"), "update_interval"),
    ("dispersions.mean", "below", _set(DISP + ("mean",), 0.001), "dispersions.coulomb_torque.mean"),
    ("dispersions.mean", "above", _set(DISP + ("mean",), 1000.0), "dispersions.coulomb_torque.mean"),
    ("dispersions.std", "below", _set(DISP + ("std",), -0.1), "dispersions.coulomb_torque.std"),
    ("dispersions.std", "above", _set(DISP + ("std",), 5.0), "dispersions.coulomb_torque.std"),
    ("dispersions.low", "below", _set(DISP + ("low",), -1.0), "dispersions.coulomb_torque.low"),
    ("dispersions.low", "above", _set(("dispersions", "wind", "low"), 500.0), "dispersions.wind"),
    ("dispersions.high", "below", _set(("dispersions", "wind", "high"), 0.0), "dispersions.wind.high"),
    ("dispersions.high", "above", _set(DISP + ("high",), 1e6), "dispersions.coulomb_torque.high"),
    ("cases", "above", lambda d: d["cases"].update({f"c{i}": {} for i in range(70)}), "cases"),
]


def campaign_cases() -> list[Case]:
    assert {r[0] for r in CAMPAIGN_ROWS} == set(CAMPAIGN_BOUNDS)
    cases = [Case("bounds", f"campaign {fld} {label} its bound", _mc(edit), expect=(want,))
             for fld, label, edit, want in CAMPAIGN_ROWS]
    return cases + [
        Case("bounds", "campaign normal mean outside [low, high]", _mc(_set(DISP + ("mean",), 1.9)),
             expect=("dispersions.coulomb_torque.mean", "low")),
        Case("bounds", "campaign case override of 1e-300 lbf/in",
             _mc(_set(("cases", "soft", "load_stiffness"), "1e-300 lbf/in")), expect=("cases.soft.load_stiffness",)),
        Case("bounds", "campaign case override of 1e30 in*lbf",
             _mc(_set(("cases", "soft", "coulomb_torque"), "1e30 in*lbf")), expect=("cases.soft.coulomb_torque",)),
    ]


#: factor to SI of a trajectory column's unit in the shipped ascent file
_COLUMN_FACTOR = {"mass": 1e3, "core_thrust_per_engine": 1e3, "booster_thrust": 1e3, "dynamic_pressure": 1e3}
_TEXT_UNIT = {"rad/s": "deg/s", "rad": "deg"}


def _column_edit(col: str, si_value: float):
    """Trajectory column ``col`` rewritten in SI with one value (the last time, else the third
    value) replaced by ``si_value``."""
    def edit(doc):
        c = doc["trajectory"][col]
        vals = [float(v) * _COLUMN_FACTOR.get(col, 1.0) for v in c["values"]]
        vals[-1 if col == "time" else 2] = si_value
        doc["trajectory"][col] = {"unit": ASCENT_BOUNDS[f"trajectory.{col}"][2], "values": vals}
    return edit


def _text(si: float, unit: str) -> str:
    v = math.degrees(si) if unit in _TEXT_UNIT else si
    return f"{v:.6g} {_TEXT_UNIT.get(unit, unit)}"


def _ascent(edit):
    return lambda w: ["ascent", ascent_copy(w, edit), "--out", w / "asc"]


def ascent_cases() -> list[Case]:
    cases = []
    for fld, (lo, hi, unit, _why) in ASCENT_BOUNDS.items():
        below = lo / 100 if lo > 0 else (lo * 100 if lo < 0 else -1.0)
        for label, v in (("below", below), ("above", hi * 100)):
            sec, _, key = fld.partition(".")
            if sec == "trajectory":
                edit, want = _column_edit(key, v), fld
            elif sec == "pti":
                edit, want = _set(("pti", 0, key), _text(v, unit)), "pti[0]"
            else:
                edit, want = _set(tuple(fld.split(".")), _text(v, unit)), fld
            cases.append(Case("bounds", f"ascent {fld} {label} its bound", _ascent(edit), expect=(want,)))
    return cases + [
        Case("bounds", "ascent gust after the trajectory's end", _ascent(_set(("wind", "gust_time"), "1000 s")),
             expect=("wind.gust_time", "trajectory")),
        Case("bounds", "ascent PTI running past the trajectory's end", _ascent(_set(("pti", 3, "start"), "470 s")),
             expect=("pti", "trajectory")),
        Case("bounds", "ascent PTI multisine down to 1e-300 Hz", _ascent(_set(("pti", 0, "low_frequency"), "1e-300 Hz")),
             expect=("pti[0]",)),
    ]


def _profile(body: str):
    return lambda w: ["simulate", AMBIENT, "--profile", write(w, "p.toml", body), "--out", w / "o.h5"]


SINE = 'type = "sine_dwell"\nfrequency = "1 Hz"\ncycles = 2\n'
SWEEP = 'type = "sine_sweep"\nstart_frequency = "1 Hz"\n'
#: (the field the line names, label, profile file)
PROFILE_ROWS = [
    ("amplitude", "a sine of zero amplitude", SINE + 'amplitude = "0 deg"\n'),
    ("amplitude", "a sine of negative amplitude", SINE + 'amplitude = "-0.4 deg"\n'),
    ("amplitude", "a sine of 1e-300 deg", SINE + 'amplitude = "1e-300 deg"\n'),
    ("amplitude", "a circle of zero amplitude", 'type = "circular"\namplitude = "0 deg"\nfrequency = "1 Hz"\n'),
    ("amplitude", "a sweep of zero amplitude", SWEEP + 'amplitude = "0 deg"\nend_frequency = "2 Hz"\nduration = "2 s"\n'),
    ("amplitude", "a multisine of 20 deg", 'type = "multisine"\namplitude = "20 deg"\nfrequencies = ["1 Hz"]\n'
     'duration = "2 s"\n'),
    ("amplitude", "a step of -40 deg", 'type = "step"\namplitude = "-40 deg"\n'),
    ("levels[1]", "a ramp level of 40 deg", 'type = "multi_ramp"\nlevels = ["0.2 deg", "40 deg"]\nrate = "1 deg/s"\n'),
    ("rate", "a ramp at 1e6 deg/s", 'type = "multi_ramp"\nlevels = ["0.2 deg"]\nrate = "1e6 deg/s"\n'),
    ("rate", "a ramp at 1e-9 deg/s", 'type = "multi_ramp"\nlevels = ["0.2 deg"]\nrate = "1e-9 deg/s"\n'),
    ("frequency", "a sine at 1e-9 Hz", 'type = "sine_dwell"\namplitude = "0.4 deg"\nfrequency = "1e-9 Hz"\n'),
    ("cycles", "a sine of zero cycles", SINE.replace("cycles = 2", "cycles = 0") + 'amplitude = "0.4 deg"\n'),
    ("hold", "a step held -1 s", 'type = "step"\namplitude = "0.4 deg"\nhold = "-1 s"\n'),
    ("start", "a step starting after 1e5 s", 'type = "step"\namplitude = "0.4 deg"\nstart = "1e5 s"\n'),
    ("duration", "a sweep of 1e5 s", SWEEP + 'amplitude = "0.4 deg"\nend_frequency = "2 Hz"\nduration = "1e5 s"\n'),
    ("levels", "a ramp of 2000 levels", 'type = "multi_ramp"\nrate = "1 deg/s"\nlevels = [' + '"0.1 deg", ' * 2000
     + ']\n'),
    ("frequencies", "a multisine of 500 lines", 'type = "multisine"\namplitude = "0.4 deg"\nduration = "2 s"\n'
     'frequencies = [' + ", ".join(f'"{1 + i / 100:g} Hz"' for i in range(500)) + ']\n'),
    ("segments", "a sequence of 2000 segments", 'type = "sequence"\n' + '[[segments]]\ntype = "step"\n'
     'amplitude = "0.1 deg"\nhold = "1 ms"\n' * 2000),
    ("end_frequency", "a logarithmic sweep from 1 Hz to 1 Hz (ln 1 = 0 divides)",
     SWEEP + 'amplitude = "0.4 deg"\nend_frequency = "1 Hz"\nduration = "2 s"\n'),
    ("frequencies", "a multisine with a line given twice", 'type = "multisine"\namplitude = "0.4 deg"\n'
     'duration = "2 s"\nfrequencies = ["1 Hz", "2 Hz", "1 Hz"]\n'),
]


def profile_cases() -> list[Case]:
    return [Case("bounds", f"profile: {label}", _profile(body), expect=(want,)) for want, label, body in PROFILE_ROWS]


def file_bound_cases() -> list[Case]:
    return campaign_cases() + ascent_cases() + profile_cases()
