"""The unit table of :mod:`taos.units`: every hand-written conversion factor is defined there once,
checked against pint's definitions and the exact ones, and written nowhere else in the packages
or the scripts (issue 38, point 6)."""

from __future__ import annotations

import math
import re
from fractions import Fraction
from pathlib import Path

import pytest

from taos import units

ROOT = Path(__file__).resolve().parents[1]

#: name -> (pint unit it converts to SI, SI unit, exact value as a decimal fraction)
LBF, INCH = Fraction("4.4482216152605"), Fraction("0.0254")
TABLE = {
    "N_PER_LBF": ("lbf", "N", LBF),
    "M_PER_IN": ("in", "m", INCH),
    "N_PER_M_PER_LBF_PER_IN": ("lbf/in", "N/m", LBF / INCH),
    "NM_PER_IN_LBF": ("in*lbf", "N*m", LBF * INCH),
    "PA_PER_PSI": ("psi", "Pa", LBF / INCH ** 2),
}


@pytest.mark.parametrize("name", sorted(TABLE))
def test_each_constant_matches_pint_and_the_exact_definition(name):
    unit, si, exact = TABLE[name]
    value = getattr(units, name)
    assert value == pytest.approx(units.ureg.Quantity(1.0, unit).to(si).magnitude, rel=1e-15, abs=0.0)
    assert abs(value - float(exact)) <= 2 * math.ulp(value), (value, float(exact))


def test_the_factors_are_written_nowhere_else():
    """No source file of taos/, masv/ or scripts/ types the factors by hand (the digits of
    lbf/in -> N/m, in*lbf -> N m, psi -> Pa, lbf -> N, or an inch of 0.0254 m)."""
    typed = re.compile(r"(?<![\w.])(175\.126|0\.11298|6894\.75|4\.448|0\.0254\b)")
    offenders = []
    for folder in ("taos", "masv", "scripts"):
        for p in sorted((ROOT / folder).rglob("*.py")):
            if p == ROOT / "taos" / "units.py" or "__pycache__" in p.parts:
                continue
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1):
                if typed.search(line):
                    offenders.append(f"{p.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not offenders, "\n".join(offenders)
