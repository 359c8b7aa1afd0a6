"""A measured record replayed through the model: how far the model's piston and engine
angle are from the test's, sample by sample.

The record's commands drive the model (:func:`taos.profiles.profile_from_record`,
:func:`taos.planar.simulate.simulate`); the simulated signals are interpolated onto the record's
time stamps and compared: RMS of (model - test) for the piston [m] and for the engine angle
[rad] (its mean difference removed when the record's engine angles are relative, the
string pots' unknown offset), each also relative to the RMS of the test signal."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..units import M_PER_IN


#: file suffixes read as measured records (:func:`taos.identify.data.load_test_data`)
RECORD_SUFFIXES = (".csv", ".txt", ".h5", ".hdf5")


def load_command_source(path):
    """A command profile from ``path``: :func:`taos.profiles.load_profile` for a profile file (or
    shipped name), or for a measured record (``.csv``/``.txt``/``.h5``/``.hdf5``,
    :func:`taos.identify.data.load_test_data`) the profile replaying its commands
    (:func:`taos.profiles.profile_from_record`)."""
    from pathlib import Path

    from taos import profiles

    if Path(str(path)).suffix.lower() in RECORD_SUFFIXES:
        from taos.identify.data import load_test_data
        return profiles.profile_from_record(load_test_data(path))
    return profiles.load_profile(path)


@dataclass(frozen=True)
class AxisReplay:
    axis: str
    piston_rms_error_m: float
    piston_rms_m: float
    engine_rms_error_rad: float | None
    engine_rms_rad: float | None

    def to_dict(self) -> dict:
        return {"axis": self.axis, "piston_rms_error_in": self.piston_rms_error_m / M_PER_IN,
                "piston_relative_rms_error": self.piston_rms_error_m / max(self.piston_rms_m, 1e-300),
                "engine_rms_error_deg": None if self.engine_rms_error_rad is None
                else math.degrees(self.engine_rms_error_rad),
                "engine_relative_rms_error": None if self.engine_rms_error_rad is None
                else self.engine_rms_error_rad / max(self.engine_rms_rad, 1e-300)}


def compare_replay(data, th) -> tuple[AxisReplay, ...]:
    """Model run ``th`` (a :class:`taos.planar.simulate.TimeHistory` of the replayed record) against
    the record ``data`` (:class:`taos.identify.data.TestData`)."""
    t = np.asarray(data.t_s, float) - float(data.t_s[0])
    out = []
    for i, ax in enumerate(data.axes):
        k = th.axes.index(ax)
        xp = np.interp(t, th.t_s, th.piston_m[k]) - data.piston_m[i]
        er = eref = None
        if data.engine_rad is not None:
            e = np.interp(t, th.t_s, th.engine_rad[k]) - data.engine_rad[i]
            if not data.engine_absolute:
                e = e - e.mean()
            er = float(np.sqrt(np.mean(e ** 2)))
            eref = float(np.sqrt(np.mean((data.engine_rad[i] - data.engine_rad[i].mean()) ** 2)))
        out.append(AxisReplay(ax, float(np.sqrt(np.mean(xp ** 2))),
                              float(np.sqrt(np.mean((data.piston_m[i] - data.piston_m[i].mean()) ** 2))), er, eref))
    return tuple(out)
