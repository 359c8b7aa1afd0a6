"""``taos reduce FITTED.toml --out PLANAR.toml``: the planar (simplex) model whose friction
reproduces the 3-D model's low-frequency engine response, for the flight loop (``taos lco``)
(:mod:`taos.identify.reduce`; seed paper sec. 4, issue 39.4).

A reduction outside the acceptance tolerance (0.5 dB / 5 deg on any fit- or check-grid dwell) is
refused: one line on standard error naming the worst point, exit status 4 (as ``taos fit
--strict`` when the model cannot explain the data: the input was good, the result does not meet
its acceptance), nothing written. ``--allow-outside`` writes it anyway (its head and the
printed summary say NOT within, a WARNING line on standard error), exit 0."""

from __future__ import annotations

import sys

from taos.errors import InputError


def cmd_reduce(args) -> int:
    from taos.identify.reduce import (
        DEFAULT_AMPLITUDES_DEG,
        DEFAULT_CHECK_AMPLITUDES_DEG,
        DEFAULT_CHECK_FREQ_HZ,
        DEFAULT_FREQ_HZ,
        TOLERANCE_DB,
        TOLERANCE_DEG,
        reduce_to_planar,
    )
    from taos.model import load_model
    from taos.results import check_output_file, write_json
    from taos.units import parse_float_list

    check_output_file(args.out, "--out", (".toml",), inputs=[args.model, *(args.records or [])])  # before any work
    freqs = parse_float_list(args.freq_hz, "--freq-hz") if args.freq_hz else DEFAULT_FREQ_HZ
    amps = parse_float_list(args.amplitudes_deg, "--amplitudes-deg") if args.amplitudes_deg else DEFAULT_AMPLITUDES_DEG
    cfreqs = parse_float_list(args.check_freq_hz, "--check-freq-hz") if args.check_freq_hz else DEFAULT_CHECK_FREQ_HZ
    camps = (parse_float_list(args.check_amplitudes_deg, "--check-amplitudes-deg") if args.check_amplitudes_deg
             else DEFAULT_CHECK_AMPLITUDES_DEG)
    for name, v, lo, hi, unit in (("--freq-hz", freqs, 1e-3, 50.0, "Hz"), ("--amplitudes-deg", amps, 1e-4, 5.0, "deg"),
                                  ("--check-freq-hz", cfreqs, 1e-3, 50.0, "Hz"),
                                  ("--check-amplitudes-deg", camps, 1e-4, 5.0, "deg")):
        if not all(lo <= x <= hi for x in v):
            raise InputError("command line", name, f"values from {lo:g} to {hi:g} {unit}", got=",".join(map(str, v)))
    free = None
    if args.free:
        free = [k.strip() if "." in k else f"friction.{k.strip()}" for k in args.free.split(",")]
        if any(not k.partition(".")[2] for k in free):
            raise InputError("command line", "--free", "keys like coulomb_torque,bristle_stiffness", got=args.free)
    axes = ("pitch", "yaw") if args.axis == "both" else (args.axis,)
    model = load_model(args.model)
    if "gimbal" not in model.extra or "geometry" not in model.extra:
        raise InputError(model.source, "[gimbal]", "a 3-D model file (with [gimbal] and [geometry]) to reduce",
                         got="a planar model file")
    try:
        res = reduce_to_planar(model, freq_hz=freqs, amplitudes_deg=amps, axes=axes, free=free,
                               records=args.records or (), check_freq_hz=cfreqs, check_amplitudes_deg=camps)
    except InputError as e:
        if e.source == "argument":   # the library's argument names -> the command line's options
            opt = {"free": "--free", "freq_hz": "--freq-hz", "amplitudes_deg": "--amplitudes-deg",
                   "check_freq_hz": "--check-freq-hz", "check_amplitudes_deg": "--check-amplitudes-deg",
                   "check_freq_hz x check_amplitudes_deg": "--check-freq-hz x --check-amplitudes-deg",
                   "freq_hz x amplitudes_deg": "--freq-hz x --amplitudes-deg"}.get(e.field, e.field)
            raise InputError("command line", opt, e.expected, got=e.got) from None
        raise
    if not res.within_tolerance and not args.allow_outside:
        print(f"taos reduce: the reduction of {args.model} is NOT within {TOLERANCE_DB:g} dB / {TOLERANCE_DEG:g} deg: "
              f"worst {res.worst_text}; nothing written (--allow-outside writes it anyway; try --free with more "
              "keys or a modified-LuGre 3-D model)", file=sys.stderr)
        return 4
    res.write_model(args.out)
    out = sys.stderr if args.json == "-" else sys.stdout
    if args.json:
        d = res.to_dict()
        d["planar_model_file"] = str(args.out)
        write_json(args.json, d)
    for line in res.summary_lines():
        print(line, file=out)
    print(f"wrote {args.out} ({res.nfev} planar evaluations, {res.wall_s:.1f} s)", file=out)
    if not res.within_tolerance:
        print(f"WARNING: written with --allow-outside, NOT within {TOLERANCE_DB:g} dB / {TOLERANCE_DEG:g} deg: worst "
              f"{res.worst_text}", file=sys.stderr)
    return 0


def add_parsers(sub) -> None:
    p = sub.add_parser("reduce", help="the planar-equivalent friction of a 3-D model, for the flight loop (taos lco)")
    p.add_argument("model", help="3-D model file (with [gimbal] and [geometry]), e.g. a 3-D fit's --out-model or "
                   "models/rs25_hotfire.toml")
    p.add_argument("--out", required=True, metavar="PLANAR.toml", help="the reduced planar model file to write")
    p.add_argument("--axis", choices=("pitch", "yaw", "both"), default="pitch",
                   help="axes whose engine dwells are matched (default pitch)")
    p.add_argument("--freq-hz", help="fit frequencies (default 0.05,0.1,0.2,0.5,1,2)")
    p.add_argument("--amplitudes-deg", help="fit command amplitudes (default 0.01,0.02,0.05,0.1,0.2,0.5)")
    p.add_argument("--check-freq-hz", help="check frequencies, both axes (default the acceptance grid: 9 from 0.1 to "
                   "2 Hz)")
    p.add_argument("--check-amplitudes-deg", help="check command amplitudes (default 9 from 0.02 to 0.5 deg)")
    p.add_argument("--allow-outside", action="store_true",
                   help="write the reduced model even when a fit- or check-grid dwell is outside 0.5 dB / 5 deg "
                   "(default: refuse, exit 4, one line naming the worst point, nothing written)")
    p.add_argument("--free", help="friction keys reduced (default coulomb_torque,bristle_stiffness,bristle_damping,"
                   "vibration_velocity, those the law has; also damping_decay_velocity, stribeck_velocity, "
                   "structure.load_stiffness)")
    p.add_argument("--records", nargs="+", metavar="RECORD", help="the test records the 3-D model was fitted to "
                   "(named with their SHA-256 in the written file)")
    p.add_argument("--json", metavar="PATH", help="write the match tables and provenance as JSON ('-' for standard "
                   "output)")
    p.set_defaults(func=cmd_reduce)
