"""Command profiles: engine-angle commands theta_c(t) [rad] for one or two axes.

Every profile is a frozen dataclass with ``duration_s`` and ``__call__(t) -> rad``. Two-axis
profiles (:class:`TwoAxis`, :class:`Circular`) return an array of shape (2, n) for
(pitch, yaw). Profiles load from TOML (``models/profiles/*.toml``) with units::

    name = "..."
    [pitch]                       # or a top-level type = "circular"
    type = "sine_dwell"           # step | multi_ramp | sine_dwell | sine_sweep | multisine | sequence
    amplitude = "0.4 deg"
    frequency = "1 Hz"
    cycles = 10

Schroeder phases for multisines: phi_k = -pi k (k - 1) / N (M. R. Schroeder, "Synthesis of
low-peak-factor signals and binary sequences with low autocorrelation", IEEE Trans. Inf.
Theory 16 (1970) 85-89).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

from .errors import InputError
from .units import to_si


class Profile(Protocol):
    """What every profile is (the classes below): its duration [s] and the command
    theta_c(t) [rad] at times ``t`` [s], shape (n,) (one axis) or (2, n) (pitch, yaw)."""

    @property
    def duration_s(self) -> float: ...

    def __call__(self, t: np.ndarray) -> np.ndarray: ...


@dataclass(frozen=True)
class Step:
    """theta_c = amplitude for t >= t0 (else 0). Duration ``t0 + hold``."""

    amplitude_rad: float
    t0_s: float = 0.5
    hold_s: float = 2.0

    @property
    def duration_s(self) -> float:
        return self.t0_s + self.hold_s

    def __call__(self, t):
        return np.where(np.asarray(t) >= self.t0_s, self.amplitude_rad, 0.0)


@dataclass(frozen=True)
class MultiRamp:
    """Piecewise-linear ramps through ``levels_rad`` at constant ``rate_rad_s``, holding each
    level ``hold_s`` (the MPTA-style multi-ramp used to measure Coulomb torque)."""

    levels_rad: tuple[float, ...]
    rate_rad_s: float
    hold_s: float = 1.0

    def _knots(self):
        t, y = [0.0], [0.0]
        for lv in self.levels_rad:
            t.append(t[-1] + abs(lv - y[-1]) / self.rate_rad_s)
            y.append(lv)
            t.append(t[-1] + self.hold_s)
            y.append(lv)
        return np.array(t), np.array(y)

    @property
    def duration_s(self) -> float:
        return float(self._knots()[0][-1])

    def __call__(self, t):
        tk, yk = self._knots()
        return np.interp(t, tk, yk)


@dataclass(frozen=True)
class SineDwell:
    """theta_c = A sin(2 pi f t) for a whole number of cycles."""

    amplitude_rad: float
    frequency_hz: float
    cycles: int = 10

    @property
    def duration_s(self) -> float:
        return self.cycles / self.frequency_hz

    def __call__(self, t):
        t = np.asarray(t, float)
        return np.where(t <= self.duration_s, self.amplitude_rad * np.sin(2 * np.pi * self.frequency_hz * t), 0.0)


@dataclass(frozen=True)
class SineSweep:
    """Logarithmic (or linear) sweep from f0 to f1 over ``duration_s``."""

    amplitude_rad: float
    f0_hz: float
    f1_hz: float
    duration_s: float
    logarithmic: bool = True

    def __call__(self, t):
        t = np.asarray(t, float)
        T = self.duration_s
        if self.logarithmic:
            k = math.log(self.f1_hz / self.f0_hz) / T
            ph = 2 * np.pi * self.f0_hz * (np.exp(k * t) - 1.0) / k
        else:
            ph = 2 * np.pi * (self.f0_hz * t + 0.5 * (self.f1_hz - self.f0_hz) / T * t * t)
        return np.where(t <= T, self.amplitude_rad * np.sin(ph), 0.0)


@dataclass(frozen=True)
class Multisine:
    """Schroeder-phased sum of sines at ``freqs_hz``, scaled to peak ``amplitude_rad``."""

    amplitude_rad: float
    freqs_hz: tuple[float, ...]
    duration_s: float

    def _phases(self):
        N = len(self.freqs_hz)
        return np.array([-math.pi * k * (k - 1) / N for k in range(1, N + 1)])

    def _raw(self, t):
        t = np.asarray(t, float)
        return sum(np.cos(2 * np.pi * f * t + p) for f, p in zip(self.freqs_hz, self._phases()))

    def __call__(self, t):
        t = np.asarray(t, float)
        period = 1.0 / min(self.freqs_hz)
        peak = np.max(np.abs(self._raw(np.linspace(0, period, 4096))))
        return np.where(t <= self.duration_s, self.amplitude_rad * self._raw(t) / peak, 0.0)


@dataclass(frozen=True)
class Sequence:
    """Profiles played one after another."""

    parts: tuple

    @property
    def duration_s(self) -> float:
        return float(sum(p.duration_s for p in self.parts))

    def __call__(self, t):
        t = np.asarray(t, float)
        out = np.zeros_like(t)
        t0 = 0.0
        for p in self.parts:
            m = (t >= t0) & (t < t0 + p.duration_s)
            out[m] = p(t[m] - t0)
            t0 += p.duration_s
        return out


@dataclass(frozen=True)
class TwoAxis:
    """Pitch and yaw commanded at the same time (Green Run vectoring)."""

    pitch: object
    yaw: object
    name: str = ""

    @property
    def duration_s(self) -> float:
        return max(self.pitch.duration_s, self.yaw.duration_s)

    def __call__(self, t):
        return np.vstack([self.pitch(t), self.yaw(t)])


@dataclass(frozen=True)
class Circular:
    """Circular gimbal motion: pitch = A sin(2 pi f t), yaw = A cos(2 pi f t) (ramped in over
    the first cycle so the yaw command starts at zero)."""

    amplitude_rad: float
    frequency_hz: float
    cycles: int = 10
    name: str = ""

    @property
    def duration_s(self) -> float:
        return self.cycles / self.frequency_hz

    def __call__(self, t):
        t = np.asarray(t, float)
        w = 2 * np.pi * self.frequency_hz
        ramp = np.clip(t * self.frequency_hz, 0.0, 1.0)
        on = t <= self.duration_s
        return np.vstack([np.where(on, self.amplitude_rad * np.sin(w * t), 0.0),
                          np.where(on, ramp * self.amplitude_rad * np.cos(w * t), 0.0)])


@dataclass(frozen=True, eq=False)
class Recorded:
    """A measured command record replayed: theta_c(t) by linear interpolation of the samples
    (``t_s`` from 0, ``command_rad``), zero outside the record."""

    t_s: np.ndarray
    command_rad: np.ndarray
    name: str = ""

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1])

    def __call__(self, t):
        return np.interp(np.asarray(t, float), self.t_s, self.command_rad, left=0.0, right=0.0)


def profile_from_record(data) -> "TwoAxis | Recorded":
    """The commands of a :class:`taos.identify.data.TestData` record as a profile (both axes
    as :class:`TwoAxis` when the record has yaw; time shifted to start at 0)."""
    t = np.asarray(data.t_s, float) - float(data.t_s[0])
    parts = {ax: Recorded(t, np.asarray(data.command_rad[i], float), f"{data.source} ({ax})")
             for i, ax in enumerate(data.axes)}
    name = f"recorded commands of {data.source}"
    if "yaw" in parts:
        return TwoAxis(parts.get("pitch", Step(0.0, 0.0, 1e-9)), parts["yaw"], name)
    return Recorded(t, parts["pitch"].command_rad, name)


def is_two_axis(profile) -> bool:
    return isinstance(profile, (TwoAxis, Circular))


# -- TOML loading -----------------------------------------------------------------------
#: keys of each profile type (unknown keys are refused with the nearest one suggested)
TYPE_KEYS = {
    "step": {"amplitude", "start", "hold"},
    "multi_ramp": {"levels", "rate", "hold"},
    "sine_dwell": {"amplitude", "frequency", "cycles"},
    "sine_sweep": {"amplitude", "start_frequency", "end_frequency", "duration", "logarithmic"},
    "multisine": {"amplitude", "frequencies", "duration"},
    "sequence": {"segments"},
    "circular": {"amplitude", "frequency", "cycles"},
}
_TOP = {"name", "description"}


def _angle(tab, key, src, sec, moving=True):
    """An angle within the gimbal range; ``moving`` (a sine, sweep, multisine, circle): above zero
    (:data:`taos.bounds.PROFILE_BOUNDS`)."""
    from .bounds import check_command_angle, check_profile_value

    if key not in tab:
        raise InputError(src, f"{sec}.{key}", "an angle with its unit, like '0.4 deg'", got="nothing (key missing)")
    v = check_command_angle(to_si(tab[key], "angle", source=src, field=f"{sec}.{key}"), src, f"{sec}.{key}")
    return check_profile_value("amplitude", v, src, f"{sec}.{key}") if moving else v


def _count(items: list, what: str, src: str, field: str) -> list:
    from .bounds import check_profile_value

    check_profile_value(f"number of {what}", len(items), src, field)
    return items


def _pos(tab, key, kind, src, sec, example):
    from .bounds import check_command_frequency, check_duration

    if key not in tab:
        raise InputError(src, f"{sec}.{key}", f"a {kind} with its unit, like {example}", got="nothing (key missing)")
    v = to_si(tab[key], kind, source=src, field=f"{sec}.{key}", positive=True)
    if kind == "frequency":
        check_command_frequency(v, src, f"{sec}.{key}")
    elif kind == "time":
        check_duration(v, src, f"{sec}.{key}")
    return v


def _ramp_rate(tab, src, sec):
    from .bounds import check_profile_value

    return check_profile_value("rate", _pos(tab, "rate", "angular_velocity", src, sec, "'0.5 deg/s'"), src, f"{sec}.rate")


def _time(tab, key, default, src, sec, **chk):
    from .bounds import check_duration

    return check_duration(to_si(tab.get(key, default), "time", source=src, field=f"{sec}.{key}", **chk),
                          src, f"{sec}.{key}")


def _int(tab, key, src, sec, default):
    from .bounds import check_cycles

    v = tab.get(key, default)
    if not isinstance(v, int) or isinstance(v, bool) or v < 1:
        raise InputError(src, f"{sec}.{key}", "a positive whole number", got=repr(v))
    return check_cycles(v, src, f"{sec}.{key}")


def _table(tab, src, sec, kind=None):
    from .errors import check_keys

    if not isinstance(tab, dict):
        raise InputError(src, sec, "a profile table with a type, like {type = 'sine_dwell', ...}", got=repr(tab)[:60])
    kind = tab.get("type") if kind is None else kind
    if isinstance(kind, str) and kind in TYPE_KEYS:
        check_keys(tab, TYPE_KEYS[kind] | {"type"} | (_TOP if sec in ("profile",) else set()), src, sec)
    return kind


def profile_from_table(tab: dict, src: str, sec: str):
    """One single-axis profile from a TOML table."""
    kind = _table(tab, src, sec)
    if kind == "step":
        return Step(_angle(tab, "amplitude", src, sec, moving=False), _time(tab, "start", "0.5 s", src, sec, nonnegative=True),
                    _time(tab, "hold", "2 s", src, sec, positive=True))
    if kind == "multi_ramp":
        from .bounds import check_command_angle

        levels = tab.get("levels")
        if not isinstance(levels, list) or not levels:
            raise InputError(src, f"{sec}.levels", "a list of angles like ['0.2 deg', '-0.2 deg']", got=repr(levels))
        _count(levels, "levels", src, f"{sec}.levels")
        return MultiRamp(tuple(check_command_angle(to_si(v, "angle", source=src, field=f"{sec}.levels[{i}]"), src,
                                                   f"{sec}.levels[{i}]") for i, v in enumerate(levels)),
                         _ramp_rate(tab, src, sec),
                         _time(tab, "hold", "1 s", src, sec, nonnegative=True))
    if kind == "sine_dwell":
        return SineDwell(_angle(tab, "amplitude", src, sec), _pos(tab, "frequency", "frequency", src, sec, "'1 Hz'"),
                         _int(tab, "cycles", src, sec, 10))
    if kind == "sine_sweep":
        log = tab.get("logarithmic", True)
        if not isinstance(log, bool):
            raise InputError(src, f"{sec}.logarithmic", "true or false", got=repr(log))
        f0, f1 = (_pos(tab, k, "frequency", src, sec, e) for k, e in (("start_frequency", "'0.1 Hz'"),
                                                                       ("end_frequency", "'10 Hz'")))
        if log and f0 == f1:   # k = ln(f1/f0)/T = 0: the logarithmic phase divides by it
            raise InputError(src, f"{sec}.end_frequency", "a frequency other than start_frequency for a logarithmic "
                             "sweep (a constant frequency is a sine_dwell)", got=f"{f1:g} Hz")
        return SineSweep(_angle(tab, "amplitude", src, sec), f0, f1, _pos(tab, "duration", "time", src, sec, "'60 s'"),
                         log)
    if kind == "multisine":
        from .bounds import check_command_frequency

        fr = tab.get("frequencies")
        if not isinstance(fr, list) or not fr:
            raise InputError(src, f"{sec}.frequencies", "a list of frequencies like ['0.5 Hz', '1 Hz']", got=repr(fr))
        _count(fr, "frequencies", src, f"{sec}.frequencies")
        freqs = tuple(check_command_frequency(to_si(v, "frequency", source=src, field=f"{sec}.frequencies[{i}]",
                                                    positive=True), src, f"{sec}.frequencies[{i}]")
                      for i, v in enumerate(fr))
        if len(set(freqs)) != len(freqs):   # Schroeder's phases are for distinct lines
            raise InputError(src, f"{sec}.frequencies", "distinct frequencies", got="a frequency given twice")
        return Multisine(_angle(tab, "amplitude", src, sec), freqs, _pos(tab, "duration", "time", src, sec, "'20 s'"))
    if kind == "sequence":
        segs = tab.get("segments")
        if not isinstance(segs, list) or not segs:
            raise InputError(src, f"{sec}.segments", "a list of profile tables ([[...segments]])", got=repr(segs)[:60])
        _count(segs, "segments", src, f"{sec}.segments")
        return Sequence(tuple(profile_from_table(s, src, f"{sec}.segments[{i}]") for i, s in enumerate(segs)))
    raise InputError(src, f"{sec}.type", "one of step, multi_ramp, sine_dwell, sine_sweep, multisine, sequence",
                     got=repr(kind))


def load_profile(path: str | Path) -> Profile:
    """Load a profile file: a top-level ``type`` (single axis, or ``circular``), or
    ``[pitch]`` and/or ``[yaw]`` tables (two-axis). (A measured record is replayed through
    :func:`profile_from_record`; the CLI reads it.) Every value is checked against the documented limits of
    :mod:`taos.bounds` (gimbal range, frequencies, durations, cycles)."""
    from .errors import check_keys
    from .bounds import check_duration
    from .model import read_toml
    from .shipped import resolve

    path = resolve(path, "profile")
    src = str(path)
    _, doc = read_toml(path, "a readable profile file")
    name = doc.get("name", Path(path).stem)
    if not isinstance(name, str):
        raise InputError(src, "name", "a text name", got=repr(name)[:60])
    if doc.get("type") == "circular":
        check_keys(doc, TYPE_KEYS["circular"] | {"type"} | _TOP, src)
        prof = Circular(_angle(doc, "amplitude", src, "profile"),
                        _pos(doc, "frequency", "frequency", src, "profile", "'1 Hz'"),
                        _int(doc, "cycles", src, "profile", 10), name)
    elif "pitch" in doc or "yaw" in doc:
        check_keys(doc, {"pitch", "yaw"} | _TOP, src)
        zero = Step(0.0, 0.0, 1e-9)
        pitch = profile_from_table(doc["pitch"], src, "pitch") if "pitch" in doc else zero
        yaw = profile_from_table(doc["yaw"], src, "yaw") if "yaw" in doc else zero
        prof = TwoAxis(pitch, yaw, name)
    else:
        if "type" not in doc:
            check_keys(doc, {"pitch", "yaw", "type"} | _TOP, src)
        prof = profile_from_table(doc, src, "profile")
    check_duration(prof.duration_s, src, "(total duration)")
    return prof


def dwell_segments(profile) -> list[tuple[float, SineDwell]]:
    """(start time [s], SineDwell) of each sine-dwell part of a single-axis profile."""
    parts = profile.parts if isinstance(profile, Sequence) else (profile,)
    out, t0 = [], 0.0
    for p in parts:
        if isinstance(p, SineDwell):
            out.append((t0, p))
        t0 += p.duration_s
    return out
