#!/usr/bin/env python
"""Build the notional "local modes in the actuator band" thrust structure for MASV (issue 24.7,
finding F12): fem_data/thrust_structure_modes_local.npz and its provenance .toml.

Why: the paper (sec. 1) says MASV confirmed that the engine-section local modes, *despite their
frequency density near the actuator bandwidth*, do not couple adversely with the actuator
position loops, and that engine-to-engine coupling exists but is small. The shipped notional
frame (fem_data/thrust_structure_modes.npz) has its lowest mode at 14.5 Hz, well above the
actuator band (hot-fire engine -3 dB bandwidth 6.3 Hz with models/actuators/tvc_actuator.toml),
so that claim is never exercised there. The real engine section's modes are
not public.

What: the same notional frame (taos.fem.thrust_structure), same geometry and mass, with every
member's elastic moduli multiplied by one stiffness scale chosen so that the lowest mode lands at
``--lowest-hz`` (5.0 Hz by default: three modes 5.0, 5.0, 7.4 Hz inside the 3-9 Hz actuator band,
a fourth at 9.7 Hz, a fifth at 14.9 Hz: the nominal file's five modes, the frame's cut-off
frequency scaled with them). The scale is notional: it stands for a softer engine section (skin-stringer
panels, joints and fittings the frame idealises as stiff), not a design. Because the mass is
unchanged the mass-normalised shapes are the nominal ones and every frequency scales by
sqrt(scale); the static flexibility the modes add to the actuators' load path grows by 1/scale
(still under 1 % of 1/K_L, see `masv modes`). Damping: 0.5 % on every mode (paper sec. 3.3),
set again by the MASV configuration.

Usage: python scripts/build_local_modes.py [--lowest-hz 5.0] [--out fem_data]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from taos.fem.build import write_thrust_structure_modes  # noqa: E402
from taos.fem.thrust_structure import ThrustStructureSpec, thrust_structure_modes  # noqa: E402

GENERATOR = "scripts/build_local_modes.py (taos.fem.build.write_thrust_structure_modes)"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lowest-hz", type=float, default=5.0, help="lowest mode of the softened frame [Hz]")
    ap.add_argument("--out", type=Path, default=ROOT / "fem_data", help="output directory")
    a = ap.parse_args(argv)
    nominal = ThrustStructureSpec()
    f1 = float(thrust_structure_modes(nominal).freq_hz[0])
    scale = round((a.lowest_hz / f1) ** 2, 6)
    # the same modes as the nominal file: its cut-off scaled with the frequencies
    spec = dataclasses.replace(nominal, stiffness_scale=scale, f_max_hz=round(nominal.f_max_hz * scale ** 0.5, 6))
    modes = write_thrust_structure_modes(a.out / "thrust_structure_modes_local", spec, GENERATOR, {
        "purpose": "notional: engine-section local modes inside the 3-9 Hz actuator band (paper sec. 1, MASV; "
                   "issue 24.7, finding F12)",
        "notional": f"every elastic modulus of the nominal frame x {scale} (lowest mode {f1:.3f} -> "
                    f"{a.lowest_hz:g} Hz); geometry and mass unchanged, so the mass-normalised shapes are the "
                    "nominal ones and frequencies scale by sqrt(stiffness_scale)",
        "nominal_lowest_mode_hz": round(f1, 4)})
    print(f"stiffness scale {scale} (nominal lowest mode {f1:.3f} Hz); modes "
          f"{[round(float(f), 2) for f in modes.freq_hz]} Hz -> {a.out / 'thrust_structure_modes_local.npz'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
