"""``taos pti``: what a flight's PTIs show (seed paper sec. 5): the flight-control open loop broken at
the PTI injection and the TVC command-to-piston response reconstructed from a flight record, the
model's linear and friction-degraded predictions overlaid, and whether friction is visible."""

from __future__ import annotations

import json
import math

from taos.cli import add_friction_option
from taos.errors import InputError
from taos.results import atomic_write, write_json


def cmd_pti(args) -> int:
    from taos.flight.ascent import load_ascent
    from taos.flight.lco import flown_model
    from taos.flight.pti import analyse_ptis
    from taos.flight.pti_record import load_flight_record
    from taos.model import load_model

    if not (math.isfinite(args.tail) and 1.0 <= args.tail <= 120.0):
        raise InputError("command line", "--tail", "a tail from 1 to 120 s", got=repr(args.tail))
    if not (math.isfinite(args.low_band) and args.low_band > 0):
        raise InputError("command line", "--low-band", "a positive frequency in Hz", got=repr(args.low_band))
    ascent = load_ascent(args.flight)
    rec = load_flight_record(args.record)
    tvc = args.model or ascent.tvc_model
    if not tvc:
        raise InputError(ascent.source, "tvc_model", "a TVC model (here or --model)", got="none")
    law = args.friction or rec.friction_model or None
    model = flown_model(load_model(tvc, friction=law), args.avionics)
    axes = None if args.axis == "all" else (args.axis,)
    out = None
    if args.out:
        from taos.cli.montecarlo import _out_folder
        out = _out_folder(args.out, ["pti.json", "pti.png"] + (["envelope.png"] if args.envelope else []))
    envs = {}
    if args.envelope:   # the record against a Monte Carlo campaign's envelopes (taos.montecarlo.envelope)
        from taos.montecarlo.envelope import record_against_campaign
        envs = record_against_campaign(rec, args.envelope)
    res = analyse_ptis(rec, ascent, model, axes=axes, tail_s=args.tail, describing=not args.no_df,
                       low_band_hz=args.low_band)
    summary = res.summary()
    if envs:
        summary["envelope"] = {"campaign": envs["command"][0].provenance,
                               **{q: (c.to_dict() if c is not None else {"quantity": q, "not_compared": why})
                                  for q, (_, c, why) in envs.items()}}
    text = json.dumps(summary, indent=1, allow_nan=False) + "\n"  # checked before anything is written
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        from taos.plotting import save
        from taos.plotting.pti import plot_pti
        save(plot_pti(res), out / "pti.png")
        if envs:
            from taos.plotting.envelope import plot_envelopes
            save(plot_envelopes([(e, c) for e, c, _ in envs.values() if e is not None]), out / "envelope.png")
        atomic_write(out / "pti.json", lambda p: p.write_text(text))
    if args.json:
        write_json(args.json, summary)
        return 0
    for r in res.responses:
        print(f"{r.axis:>5s} {r.kind:9s} {r.start_s:6.0f}-{r.end_s:4.0f} s, {r.amplitude_deg:.3f} deg: "
              f"{r.friction()['verdict']}")
    for q, (_, cmp, why) in envs.items():
        if cmp is None:
            print(f"{q}: not compared with the campaign ({why})")
            continue
        print(f"{q} outside the campaign's {cmp.band_percentiles[0]:g}-{cmp.band_percentiles[1]:g} % "
              f"envelope {100 * cmp.fraction_outside:.1f} % of the time ({cmp.t_s.size} samples)")
    if out is not None:
        print(f"PTI analysis written to {out}")
    return 0


def add_parsers(sub) -> None:
    p = sub.add_parser("pti", help="what flight shows: loop and TVC responses reconstructed at a flight's PTIs")
    p.add_argument("record", help="flight record: the HDF5 of taos ascent, or telemetry CSV/HDF5 "
                   "(taos.flight.pti_record: PTI, TVC command, piston, engine per axis)")
    p.add_argument("--flight", required=True, help="ascent file defining the PTIs and the flight loop, e.g. ascent")
    p.add_argument("--model", help="TVC model (default: the ascent file's tvc_model)")
    add_friction_option(p, "friction law of the model overlay (default: the record's, else the file's)")
    p.add_argument("--avionics", choices=("bounding", "model"), default="bounding",
                   help="avionics the record was flown with: bounding -1 dB gain (default, as taos ascent) or the file's")
    p.add_argument("--axis", choices=("pitch", "yaw", "all"), default="all", help="axes analysed (default: all recorded)")
    p.add_argument("--tail", type=float, default=20.0, help="seconds after each PTI in its window (default 20)")
    p.add_argument("--low-band", type=float, default=0.5, help="friction verdict band: lines up to this [Hz] (default 0.5)")
    p.add_argument("--no-df", action="store_true", help="no describing-function overlay (faster)")
    p.add_argument("--out", metavar="DIR", help="write DIR/pti.json and DIR/pti.png")
    p.add_argument("--json", metavar="PATH", help="write the analysis here ('-' for standard output)")
    p.add_argument("--envelope", metavar="CAMPAIGN_DIR", help="also the record's command and engine angle against "
                   "the 5/50/95 %% envelopes of a taos montecarlo campaign (its --out folder): fraction of time "
                   "outside, DIR/envelope.png")
    p.set_defaults(func=cmd_pti)
