"""``taos sweep``: figures of merit and the LCO verdict over any model-file keys, run through the
Monte Carlo engine (:mod:`taos.montecarlo.sweep`)."""

from __future__ import annotations

import sys

from taos.cli import add_friction_option
from taos.errors import InputError
from taos.results import write_json

#: most rows printed as a table (all of them are in --json)
MAX_ROWS = 60


def _metric_list() -> str:
    from taos.montecarlo.sweep_metrics import METRICS
    return "\n".join(f"  {m.name:<28s} {m.family:<7s} {m.meaning}" for m in METRICS.values())


def _definition(args):
    from taos.montecarlo.sweep import SweepDefinition
    from taos.montecarlo.sweep_define import make_design, parse_set
    from taos.units import parse_float_list

    if not args.set:
        raise InputError("command line", "--set", "at least one --set section.key=V1,V2,...", got="none")
    if not args.metric:
        raise InputError("command line", "--metric", "at least one metric (taos sweep --list-metrics)", got="none")
    keys = [parse_set(s) for s in args.set]
    design = make_design(keys, args.samples, args.seed, args.sensitivity)
    metrics = tuple(m.strip() for m in ",".join(args.metric).split(","))
    amps = None if args.amplitudes_deg is None else tuple(parse_float_list(args.amplitudes_deg, "--amplitudes-deg"))
    freqs = None if args.freq_hz is None else tuple(parse_float_list(args.freq_hz, "--freq-hz"))
    for name, v in (("--amplitudes-deg", amps), ("--freq-hz", freqs)):
        if v is not None and not 2 <= len(v) <= 40:
            raise InputError("command line", name, "2 to 40 values for the describing-function grid", got=str(len(v)))
        if v is not None and args.flight is None:
            raise InputError("command line", name, "--flight too (it sets the LCO metrics' grid)", got="no --flight")
    return SweepDefinition(args.model, design, metrics, axis=args.axis, friction=args.friction,
                           flight_file=args.flight, avionics=args.avionics, amplitudes_deg=amps, freq_hz=freqs)


def _where(texts: dict) -> str:
    return ", ".join(f"{k}={v}" for k, v in texts.items())


def _table(res) -> None:
    from taos.montecarlo.sweep_metrics import METRICS

    d = res.definition
    keys = [k.key for k in d.design.keys]
    head = keys + list(d.metrics) + ["status"]
    w = [max(12, len(h)) for h in head]
    print("  ".join(h.rjust(n) for h, n in zip(head, w)))
    for i in range(min(d.design.n, MAX_ROWS)):
        cells = [d.design.texts[i][k] for k in keys]
        st = res.status_name(i)
        for m in d.metrics:
            v = res.values[m][i]
            cells.append("-" if st != "ok" or v != v else (("yes" if v else "no") if METRICS[m].flag else f"{v:.5g}"))
        cells.append(st)
        print("  ".join(c.rjust(n) for c, n in zip(cells, w)))
    if d.design.n > MAX_ROWS:
        print(f"... {d.design.n - MAX_ROWS} more points (all of them in --json)")


def cmd_sweep(args) -> int:
    if args.list_metrics:
        print(_metric_list())
        return 0
    if args.model is None:
        raise InputError("command line", "MODEL", "a model file to sweep, e.g. models/rs25_ambient.toml", got="none")
    from taos.cli.montecarlo import KeptStore, cluster_address
    scheduler = cluster_address(args)   # the forms Dask accepts, one line if not
    defn = _definition(args)
    if args.plot and len(defn.design.keys) > 2:
        raise InputError("command line", "--plot", "a sweep of one or two keys (a metric over them)",
                         got=f"{len(defn.design.keys)} keys")
    from taos.montecarlo.engine import CampaignStopped
    from taos.montecarlo.sweep import MANIFEST, STORE, run_sweep
    kept = None if args.out is None else KeptStore(args.out, MANIFEST, STORE, "points", resume_command(args),
                                                    args.resume)
    if kept is not None:
        kept.watch()   # a signal from here on: the stored points and the resume line
    workers = 1 if args.workers is None else args.workers
    try:
        res = run_sweep(defn, args.out, workers=workers, scheduler=scheduler, resume=args.resume,
                        progress=not args.no_progress and sys.stderr.isatty(), batch=args.batch,
                        connect_timeout_s=args.connect_timeout)
    except CampaignStopped as e:   # (without --out run_sweep says itself that nothing is kept)
        if kept is None:
            raise
        raise kept.stopped(e) from None
    if args.plot:
        from taos.plotting import save
        from taos.plotting.sweep import plot_sweep
        save(plot_sweep(res), args.plot)
    d = res.to_dict()
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    c = d["counts"]
    if args.json != "-":
        _table(res)
    print(f"{c['points']} points: {c['ok']} ok, {c['unstable']} unstable, {c['failed']} failed "
          f"({d['timing']['points_executed']} computed now, {d['timing']['executor']})", file=out)
    for m, sens in (d.get("sensitivity") or {}).items():
        if sens["indices"]:
            print(f"{m}: " + ", ".join(f"{r['parameter']} S1 {r['S1']:.2f} +- {r['S1_conf']:.2f}, ST {r['ST']:.2f} "
                                        f"+- {r['ST_conf']:.2f}" for r in sens["indices"]), file=out)
            for w in sens.get("warnings", []):
                print(f"warning: {m}: {w}", file=out)
        else:
            print(f"{m}: no Sobol' indices ({sens['error']})", file=out)
    for u in d["unstable"][:5]:
        print(f"unstable at {_where(u['set'])}: {u['reason']}", file=out)
    for f in d["failed"][:5]:
        print(f"failed at {_where(f['set'])}: {f['reason']}", file=out)
    return 0


def resume_command(args) -> str:
    """The command that continues this sweep (the same definition, ``--resume`` on ``--out``)."""
    from taos.cli.montecarlo import command_line
    return command_line(["taos", "sweep", args.model], [
        ("--set", args.set), ("--metric", args.metric), ("--samples", args.samples),
        ("--sensitivity", args.sensitivity), ("--seed", args.seed or None), ("--axis", args.axis),
        ("--friction", args.friction), ("--flight", args.flight), ("--avionics", args.avionics),
        ("--amplitudes-deg", args.amplitudes_deg), ("--freq-hz", args.freq_hz), ("--workers", args.workers),
        ("--scheduler", args.scheduler), ("--scheduler-file", args.scheduler_file), ("--batch", args.batch),
        ("--json", args.json), ("--plot", args.plot), ("--out", args.out)])


def _whole(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise InputError("command line", "--samples/--workers/--batch/--seed", "a whole number",
                         got=repr(text)) from None


def add_parsers(sub) -> None:
    import argparse

    p = sub.add_parser(
        "sweep", help="figures of merit and the LCO verdict over any model-file keys (grid or Latin hypercube)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Sweep model-file keys and report figures per point, run through the Monte Carlo engine "
        "(stored, resumable, parallel).\n\n"
        "  grid:            --set structure.load_stiffness='100000 lbf/in,115000 lbf/in,130000 lbf/in'\n"
        "                   every combination of the listed values of each --set\n"
        "  Latin hypercube: --samples 50 --set 'structure.load_stiffness=80000 lbf/in:200000 lbf/in'\n"
        "                   LO:HI is a range sampled uniformly (whole numbers when both ends are);\n"
        "                   a listed key is sampled among its values\n"
        "  Sobol' indices:  --sensitivity sobol --samples 64 with every --set a range LO:HI\n\n"
        "Values are written as in the model file (a number with its unit, a plain number, or a word)\n"
        "and checked exactly as the model loader checks the file. Unstable variants are results\n"
        "(listed apart), not errors. Metrics: taos sweep --list-metrics.")
    p.add_argument("model", nargs="?", help="model file, e.g. models/rs25_ambient.toml")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=V1,V2,...|LO:HI",
                   help="a swept model-file key and its values (repeat for more keys)")
    p.add_argument("--metric", action="append", metavar="NAME[,NAME]",
                   help="figures per point, e.g. load_resonance_hz,engine_peaking_db,phase_margin_deg,lco")
    p.add_argument("--list-metrics", action="store_true", help="list the metrics and exit")
    p.add_argument("--samples", type=_whole, help="a Latin hypercube of N points instead of the grid")
    p.add_argument("--sensitivity", choices=("sobol",), help="Sobol' indices of every metric: Saltelli's design "
                   "over the --set ranges, --samples N base points (a power of two; N (k + 2) points)")
    p.add_argument("--seed", type=_whole, default=0, help="seed of the Latin hypercube (default 0)")
    p.add_argument("--axis", choices=("pitch", "yaw"), default="pitch", help="axis of the figures (default pitch)")
    add_friction_option(p)
    p.add_argument("--flight", help="flight file for the LCO metrics, e.g. models/flight/core_stage.toml")
    p.add_argument("--avionics", choices=("bounding", "model"), default="bounding",
                   help="LCO metrics: bounding (the paper's -1 dB gain, default) or the file's quantiser")
    p.add_argument("--amplitudes-deg", help="LCO metrics: describing-function command amplitudes (default taos lco's)")
    p.add_argument("--freq-hz", help="LCO metrics: describing-function frequencies (default taos lco's)")
    p.add_argument("--out", help="folder of the stored sweep (sweep.json, sweep.zarr), needed for --resume; "
                   "default: a temporary folder")
    p.add_argument("--resume", action="store_true", help="continue the sweep stored in --out")
    p.add_argument("--workers", type=_whole, help="1: in this process (default); K: a local Dask cluster of K workers")
    p.add_argument("--scheduler", help="an existing Dask scheduler: tcp://HOST:PORT, tls://HOST:PORT, HOST:PORT or "
                   "tcp://[IPv6]:PORT")
    p.add_argument("--scheduler-file", metavar="PATH", help="the scheduler's address from a Dask scheduler file "
                   "(dask scheduler --scheduler-file PATH; dask-jobqueue)")
    p.add_argument("--batch", type=_whole, help="points per task (default from the metrics' cost)")
    p.add_argument("--connect-timeout", type=float, default=20.0,
                   help="seconds to wait for --scheduler to answer, or for a lost one to come back (default 20)")
    p.add_argument("--json", metavar="PATH", help="write the grid, every metric per point, the failed and "
                   "unstable points and the provenance here ('-' for standard output)")
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="each metric over the one or two swept keys")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)
