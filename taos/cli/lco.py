"""``taos lco``: describing-function limit-cycle prediction of the flight-control loop and its
time-domain confirmation (seed paper sections 3.1-3.2)."""

from __future__ import annotations

import dataclasses
import math
import sys

import numpy as np

from taos.cli import add_friction_option
from taos.errors import InputError
from taos.results import write_json

#: at most this many points in a verdict map
MAX_MAP_POINTS = 400


def check_lco_flags(args) -> None:
    """Flag combinations refused before any work: an empty grid option (it would silently mean
    the default grid), ``--td-start`` without ``--sweep``, one parameter swept twice."""
    for opt, v in (("--amplitudes-deg", args.amplitudes_deg), ("--freq-hz", args.freq_hz)):
        if v is not None and not v.replace(",", "").strip():
            raise InputError("command line", opt, "a comma-separated list of values (omit it for the default grid)",
                             got=repr(v))
    if args.td_start is not None and not args.sweep:
        raise InputError("command line", "--td-start", "--sweep too (it starts a verdict map's confirmation runs)",
                         got=args.td_start)
    names = [s.partition("=")[0].strip() for s in args.sweep or ()]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError("command line", "--sweep", "each parameter swept once", got=f"{dup[0]} twice")


def cmd_lco(args) -> int:
    from taos.flight.vehicle import load_flight
    from taos.flight.lco import analyse_lco
    from taos.model import load_model
    from taos.units import to_si

    check_lco_flags(args)
    flight = load_flight(args.flight)
    model = load_model(args.model, friction=args.friction)
    if args.load_stiffness:
        k = to_si(args.load_stiffness, "stiffness", source="command line", field="--load-stiffness", positive=True)
        model = model.with_values({"structure.load_stiffness": k})   # a variant: the file's damping ratio kept
    if not (args.duration > 0 and math.isfinite(args.duration)):
        raise InputError("command line", "--duration", "a positive time in seconds", got=repr(args.duration))
    from taos.cli.basic import parse_float_list

    amps = None if not args.amplitudes_deg else [math.radians(a) for a in
                                                 parse_float_list(args.amplitudes_deg, "--amplitudes-deg")]
    freqs = None if not args.freq_hz else parse_float_list(args.freq_hz, "--freq-hz")
    for name, v in (("--amplitudes-deg", amps), ("--freq-hz", freqs)):
        if v is not None and len(v) < 2:
            raise InputError("command line", name, "at least two values for the describing-function grid")
    if args.requirements:   # the flight sign-off (taos/cli/signoff.py), over the --sweep grid if given
        from taos.cli.signoff import run_signoff
        return run_signoff(args, flight, model, amps, freqs)
    if args.signoff:
        raise InputError("command line", "--signoff", "--requirements FILE with it", got="no --requirements")
    if args.sweep:
        return _sweep(args, flight, model, amps, freqs)
    for opt in ("out", "resume", "workers", "scheduler", "scheduler_file"):
        if getattr(args, opt):
            raise InputError("command line", "--" + opt.replace("_", "-"), "--sweep too (a stored map campaign)",
                             got=str(getattr(args, opt)))
    if args.plot_map:
        raise InputError("command line", "--plot-map", "--sweep too (the map is of a sweep)", got=args.plot_map)
    if args.plot_time and args.no_time_domain:
        raise InputError("command line", "--plot-time", "a time-domain run (not with --no-time-domain)",
                         got=args.plot_time)
    rep = analyse_lco(flight, model, axis=args.axis, duration_s=args.duration, avionics=args.avionics,
                      amplitudes_rad=amps, freq_hz=freqs,
                      window_s=min(120.0, 0.5 * args.duration), time_domain=not args.no_time_domain,
                      steady=args.steady)
    d = rep.to_dict()
    d["avionics"] = args.avionics
    if args.plot or args.plot_df or args.plot_time:
        from taos.plotting import describing, nichols, save
        if args.plot:
            save(nichols.plot_lco_nichols(rep.prediction), args.plot)
        if args.plot_df:
            save(describing.plot_df_map(rep.prediction.df), args.plot_df)
        if args.plot_time and rep.history is not None:
            save(nichols.plot_flight_histories([rep.history]), args.plot_time)
    if args.df_out:
        rep.prediction.df.to_hdf5(args.df_out)
    if args.json:
        from taos.results import output_provenance
        d.setdefault("provenance", {}).update(output_provenance([model], [("flight", flight.source)]))
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout   # the verdict is always shown
    td = d["time_domain"] or {}
    v = d["verdict"]
    print(v["text"], file=out)
    for w in d["grid_warnings"]:
        print(f"warning: a cycle may lie outside the describing-function map (after extending it): {w}",
              file=sys.stderr)
    if v["nearest_margin"]:
        print(f"margin meant: {v['margin_meaning']}", file=out)
    if td:
        if td["lco"]:
            print(f"time domain:   command {td['amplitude_deg']:.4f} deg (engine {td['engine_amplitude_deg']:.4f} deg) "
                  f"at {td['frequency_hz']:.4f} Hz", file=out)
        else:
            print(f"time domain:   no sustained oscillation (final {td['final_amplitude_deg']:.2g} deg)", file=out)
        if td.get("duty"):
            du = td["duty"]["axes"][d["axis"]]
            print(f"duty cycle:    peak flow {du['peak_flow_m3_s']:.3g} m^3/s, mean {du['mean_flow_m3_s']:.3g} m^3/s, "
                  f"supply power {du['mean_supply_power_W']:.3g} W, piston travel {du['piston_travel_m']:.3g} m, "
                  f"{du['reversals_per_s']:.3g} reversals/s over the last {td['window_s']:g} s", file=out)
    print("loop margins of L0 N(A, .) over the command amplitude A (low GM: how far the gain may fall):", file=out)
    print(rep.verdict().table_text(), file=out)
    return 0


def _sweep(args, flight, model, amps, freqs) -> int:
    """``taos lco --sweep NAME=V1,V2 [--sweep NAME2=...]``: the verdict map, each point confirmed in
    the time domain (unless ``--no-time-domain``); with ``--out DIR`` run as a stored, resumable
    campaign on the Monte Carlo engine."""
    from taos.flight.lco_map import MapSettings, check_axes, lco_map, parse_sweep
    for opt in ("plot", "plot_df", "plot_time", "df_out"):   # these would be ignored: one map for all points
        if getattr(args, opt):
            raise InputError("command line", "--" + opt.replace("_", "-"), "not with --sweep (a verdict map; its "
                             "plot is --plot-map)", got=getattr(args, opt))
    if len(args.sweep) > 2:
        raise InputError("command line", "--sweep", "one or two sweeps", got=f"{len(args.sweep)}")
    axes = check_axes(parse_sweep(s) for s in args.sweep)
    n = int(np.prod([len(a.values) for a in axes]))
    if n > MAX_MAP_POINTS:
        raise InputError("command line", "--sweep", f"at most {MAX_MAP_POINTS} map points", got=f"{n} points")
    if args.axis:
        flight = dataclasses.replace(flight, axis=args.axis)
    settings = MapSettings(None if amps is None else tuple(amps), None if freqs is None else tuple(freqs),
                           args.avionics, not args.no_time_domain, args.td_start or "predicted", args.duration,
                           min(120.0, 0.5 * args.duration))
    failed = []
    if args.out:
        import json as _json

        from taos.flight.lco_campaign import FORMAT, run_map_campaign
        from taos.flight.vehicle import load_flight
        from taos.model import load_model
        from taos.cli.montecarlo import KeptStore, cluster_address
        from taos.flight.lco_campaign import MANIFEST, STORE
        from taos.montecarlo.engine import CampaignStopped
        from taos.montecarlo.inputs import digest, recording
        scheduler = cluster_address(args)
        with recording() as input_files:   # every file a load of the inputs reads (the map's inputs hash)
            load_flight(args.flight)
            load_model(args.model, friction=args.friction)
        if args.workers is not None and not 0 <= args.workers <= 64:
            raise InputError("command line", "--workers", "0 to 64 workers", got=str(args.workers))
        text = _json.dumps({"format": FORMAT, "settings": dataclasses.asdict(settings), "axis": flight.axis,
                            "friction": args.friction, "load_stiffness": args.load_stiffness}, sort_keys=True)
        sha, table = digest(input_files, text)
        kept = KeptStore(args.out, MANIFEST, STORE, "points", resume_command(args), args.resume)
        kept.watch()   # a signal from here on: the stored points and the resume line
        try:
            m, failed = run_map_campaign(flight, model, axes, settings, args.out, inputs_sha256=sha,
                                         input_files=table, workers=args.workers or 0, resume=args.resume,
                                         scheduler=scheduler, progress=args.json != "-" and sys.stderr.isatty())
        except CampaignStopped as e:
            raise kept.stopped(e) from None
    else:
        for opt in ("resume", "workers", "scheduler", "scheduler_file"):
            if getattr(args, opt):
                raise InputError("command line", "--" + opt.replace("_", "-"), "--out DIR too (a stored campaign)",
                                 got=str(getattr(args, opt)))
        m = lco_map(flight, model, axes, amplitudes_rad=amps, freq_hz=freqs, avionics=args.avionics,
                    time_domain=settings.time_domain, start=settings.start, duration_s=settings.duration_s,
                    window_s=settings.window_s)
    if args.plot_map:
        from taos.plotting import save
        from taos.plotting.lco_map import plot_lco_map
        save(plot_lco_map(m), args.plot_map)
    d = {"sweep": m.to_dict(), "avionics": args.avionics}
    if failed:
        d["sweep"]["failed"] = failed
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    td = d["sweep"]["time_domain"]
    for k, idx in enumerate(np.ndindex(m.lco.shape)):
        where = ", ".join(f"{a.name} = {a.values[i]:.4g} {a.unit}" for a, i in zip(m.axes, idx))
        pred = (f"LCO engine {m.engine_amplitude_deg[idx]:.4f} deg at {m.frequency_hz[idx]:.3f} Hz"
                if (m.prediction_lco[idx] if m.prediction_lco is not None else m.lco[idx])
                else f"no LCO, margin {m.margin_db[idx]:.2f} dB")
        if m.grid_may_miss_cycle is not None and m.grid_may_miss_cycle[idx]:
            pred += " (WARNING: a cycle may lie outside the describing-function map)"
        if td is None:
            print(f"{where}: {pred}", file=out)
            continue
        g = lambda key: np.ravel(np.array(td[key], dtype=object))[k]  # noqa: E731
        conf = (f"LCO engine {g('engine_amplitude_deg'):.4f} deg at {g('frequency_hz'):.3f} Hz" if g("lco") else
                f"no LCO ({g('outcome') or 'not run'})")
        print(f"{where}: {conf} (time domain, {g('simulated_s') or 0:.0f} s); predicted {pred}", file=out)
    for f in failed:
        print(f"failed: {f['at']}: {f['error']}", file=sys.stderr)
    return 3 if failed else 0


def resume_command(args) -> str:
    """The command that continues this map campaign (the same map, ``--resume`` on ``--out``)."""
    from taos.cli.montecarlo import command_line
    return command_line(["taos", "lco", args.model], [
        ("--flight", args.flight), ("--friction", args.friction), ("--axis", args.axis),
        ("--load-stiffness", args.load_stiffness), ("--avionics", args.avionics),
        ("--amplitudes-deg", args.amplitudes_deg), ("--freq-hz", args.freq_hz), ("--duration", args.duration),
        ("--no-time-domain", args.no_time_domain), ("--steady", args.steady), ("--sweep", args.sweep),
        ("--td-start", args.td_start), ("--workers", args.workers), ("--scheduler", args.scheduler),
        ("--scheduler-file", args.scheduler_file), ("--json", args.json), ("--plot-map", args.plot_map),
        ("--out", args.out)])


def add_parsers(sub) -> None:
    p = sub.add_parser("lco", help="flight-control limit cycle: describing-function prediction and time domain")
    p.add_argument("model", help="TVC model file, e.g. models/rs25_flight.toml")
    p.add_argument("--flight", required=True, help="flight file, e.g. models/flight/core_stage.toml")
    add_friction_option(p)
    p.add_argument("--axis", choices=("pitch", "yaw"), help="vehicle axis (default: the flight file's)")
    p.add_argument("--load-stiffness", help="override the load stiffness, e.g. '205000 lbf/in'")
    p.add_argument("--avionics", choices=("bounding", "model"), default="bounding",
                   help="bounding: the paper's -1 dB gain (default); model: the file's quantisation and crossover curve")
    p.add_argument("--amplitudes-deg", help="describing-function command amplitudes, e.g. 0.01,0.03,0.1,0.3,1 "
                   "(default 11 from 0.01 to 1 deg)")
    p.add_argument("--freq-hz", help="describing-function frequencies (default 10 from 0.03 to 2 Hz)")
    p.add_argument("--duration", type=float, default=300.0, help="time-domain run [s] (default 300)")
    p.add_argument("--no-time-domain", action="store_true", help="prediction only")
    p.add_argument("--steady", choices=("settle", "shoot"), default="settle",
                   help="describing-function dwells settled from rest (default) or on the periodic steady state "
                   "found by shooting")
    p.add_argument("--json", metavar="PATH", help="write JSON here ('-' for standard output)")
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="Nichols chart with the predicted LCO")
    p.add_argument("--plot-df", metavar="PNG_OR_SVG", help="describing-function gain/phase families")
    p.add_argument("--plot-time", metavar="PNG_OR_SVG", help="engine-angle time history")
    p.add_argument("--df-out", metavar="HDF5", help="save the describing-function map")
    p.add_argument("--sweep", action="append", metavar="NAME=V1,V2,...",
                   help="verdict map over one or two parameters (repeat for two), each point confirmed in the time "
                   "domain unless --no-time-domain: bristle_stiffness, coulomb_torque, load_stiffness, integral_gain, "
                   "attitude_gain, rate_gain; values in SI or each with its unit")
    p.add_argument("--td-start", choices=("predicted", "rest"), default=None,
                   help="with --sweep: start each confirmation run on the describing function's periodic solution "
                   "(default; a few cycles decide) or from rest as the single analysis does (--duration long)")
    p.add_argument("--out", metavar="DIR", help="with --sweep: run the map as a stored campaign (DIR/map.json, "
                   "DIR/map.zarr) on the Monte Carlo engine")
    p.add_argument("--resume", action="store_true", help="with --out: run the map points not yet stored")
    p.add_argument("--workers", type=int, help="with --out: local Dask worker processes (default 0: this process, "
                   "both cores, no Dask start-up)")
    p.add_argument("--scheduler", help="with --out: an existing Dask scheduler, e.g. tcp://127.0.0.1:8786")
    p.add_argument("--scheduler-file", metavar="PATH", help="with --out: the scheduler's address from a Dask "
                   "scheduler file (dask scheduler --scheduler-file PATH; dask-jobqueue)")
    p.add_argument("--plot-map", metavar="PNG_OR_SVG", help="with --sweep: the verdict map")
    p.add_argument("--requirements", metavar="TOML", help="flight sign-off: check the stated limits (gain and phase "
                   "margins, LCO amplitude and frequency band) over the nominal case or every --sweep point; "
                   "e.g. models/specs/flight_signoff_notional.toml")
    p.add_argument("--signoff", metavar="DIR", help="with --requirements: write DIR/signoff.json and DIR/signoff.html")
    p.set_defaults(func=cmd_lco)
