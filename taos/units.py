"""Engineering units at the edges, SI floats inside.

One pint registry for the whole package. Model files, CLI options and reports carry
strings such as ``"115000 lbf/in"`` or ``"144000 in*lbf"``; :func:`to_si` turns them into
plain SI floats after checking their dimension, and :func:`from_si` formats SI floats
back into engineering units for reports.
"""

from __future__ import annotations

import math

import pint

from .errors import InputError

ureg = pint.UnitRegistry()
Q_ = ureg.Quantity

#: Named physical dimensions used by model-file fields: name -> (pint dimensionality
#: expressed by a reference unit, SI unit string, example shown in error messages).
DIMENSIONS: dict[str, tuple[str, str, str]] = {
    "length": ("m", "m", "'0.8 m'"),
    "mass": ("kg", "kg", "'3527 kg'"),
    "inertia": ("kg*m**2", "kg*m**2", "'12000 kg*m**2'"),
    "stiffness": ("N/m", "N/m", "'115000 lbf/in'"),
    "rotational_stiffness": ("N*m/rad", "N*m/rad", "'500000 N*m/rad'"),
    "torque": ("N*m", "N*m", "'144000 in*lbf'"),
    "force": ("N", "N", "'1860 kN'"),
    "pressure": ("Pa", "Pa", "'3000 psi'"),
    "area": ("m**2", "m**2", "'15 in**2'"),
    "volume": ("m**3", "m**3", "'200 in**3'"),
    "angle": ("rad", "rad", "'0.4 deg'"),
    "angular_velocity": ("rad/s", "rad/s", "'0.01 deg/s'"),
    "velocity": ("m/s", "m/s", "'0.01 m/s'"),
    "frequency": ("Hz", "Hz", "'120 Hz'"),
    "rate": ("1/s", "1/s", "'70 1/s'"),
    "time": ("s", "s", "'0.02 s'"),
    "damping": ("N*s/m", "N*s/m", "'20000 N*s/m'"),
    "rotational_damping": ("N*m*s/rad", "N*m*s/rad", "'1e6 N*m*s/rad'"),
    "flow_pressure": ("m**3/s/Pa", "m**3/s/Pa", "'1e-12 m**3/s/Pa'"),
    "velocity_per_pressure": ("m/s/Pa", "m/s/Pa", "'4e-8 m/s/Pa'"),
    "dimensionless": ("dimensionless", "1", "'0.95'"),
}


def _dimensionality(kind: str):
    return Q_(1.0, DIMENSIONS[kind][0]).dimensionality


def to_si(value: object, kind: str, *, source: str, field: str, positive: bool = False,
          nonnegative: bool = False) -> float:
    """Parse ``value`` (a string with unit, or a plain number for dimensionless fields) to SI.

    Parameters
    ----------
    value : str | float
        e.g. ``"115000 lbf/in"``. Plain numbers are accepted only for ``kind="dimensionless"``.
    kind : str
        A key of :data:`DIMENSIONS`.
    source, field : str
        Where the value came from, for the one-line error.
    positive, nonnegative : bool
        Extra range checks.

    Returns
    -------
    float
        The value in the SI unit of ``DIMENSIONS[kind][1]`` (angles in rad, frequencies in Hz).
    """
    ref, si_unit, example = DIMENSIONS[kind]
    expected = f"a {kind.replace('_', ' ')} with its unit, like {example}"
    if isinstance(value, bool):
        raise InputError(source, field, expected, got=repr(value))
    if isinstance(value, (int, float)):
        if kind != "dimensionless":
            raise InputError(source, field, expected, got=f"{value!r} (no unit)")
        q = Q_(float(value), "dimensionless")
    elif isinstance(value, str):
        try:
            q = Q_(value)
        except Exception:  # pint raises several error types for unparsable text
            raise InputError(source, field, expected, got=repr(value)) from None
        if not isinstance(q, pint.Quantity):
            q = Q_(float(q), "dimensionless")
    else:
        raise InputError(source, field, expected, got=repr(value))
    if q.dimensionality != _dimensionality(kind):
        raise InputError(source, field, expected, got=f"{value!r} ({q.dimensionality})")
    out = float(q.to(si_unit).magnitude)
    if not math.isfinite(out):
        raise InputError(source, field, expected + " (finite)", got=repr(value))
    if positive and not out > 0.0:
        raise InputError(source, field, f"a positive {kind.replace('_', ' ')}", got=repr(value))
    if nonnegative and out < 0.0:
        raise InputError(source, field, f"a non-negative {kind.replace('_', ' ')}", got=repr(value))
    return out


def from_si(value: float, si_unit: str, unit: str) -> float:
    """Convert an SI float to ``unit`` (e.g. ``from_si(k, 'N/m', 'lbf/in')``)."""
    return float(Q_(value, si_unit).to(unit).magnitude)

