"""``taos estimate``, ``taos fit`` and ``taos compare``: the test-data workflow (seed paper
secs. 2.2 and 4): estimate responses from vectoring records, fit model parameters with
CasADi, and compare two conditions (ambient vs hot fire) side by side."""

from __future__ import annotations

import math
import sys

from taos.cli import add_friction_option
from taos.cli._fit_args import _free, _outputs, _parse_bounds, _parse_start
from taos.errors import InputError
from taos.results import write_json

AXES = ("pitch", "yaw")


def _estimate(path, args):
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate

    if getattr(args, "nperseg", None) is not None and args.method == "dwell":
        raise InputError("command line", "--nperseg", "--method h1 or auto (a sine-dwell correlation has no "
                         "segments)", got="--method dwell")
    data = load_test_data(path)
    axes = None if args.axis in (None, "both") else (args.axis,)
    if axes and axes[0] not in data.axes:
        raise InputError(str(path), f"{axes[0]}_command", f"a {axes[0]} axis in the data", got=", ".join(data.axes))
    kw = {"axes": axes}
    if getattr(args, "nperseg", None) is not None:
        from taos.bounds import NPERSEG_MIN
        if not NPERSEG_MIN <= args.nperseg <= data.t_s.size:
            raise InputError("command line", "--nperseg", f"a segment length from {NPERSEG_MIN} to the "
                             f"{data.t_s.size} samples of {path}", got=str(args.nperseg))
        kw["nperseg"] = args.nperseg
    return data, estimate(data, method=args.method, **kw)


def cmd_estimate(args) -> int:
    _outputs(args, "json")
    model = None
    if getattr(args, "model", None):
        from taos.model import load_model
        model = load_model(args.model)
    data, responses = _estimate(args.data, args)
    d = {"source": data.source, "condition": data.condition, "synthetic": data.synthetic,
         "sample_rate_hz": data.sample_rate_hz, "resampled": data.resampled,
         "engine_dc_observable": data.engine_absolute, "responses": [r.to_dict(model=model) for r in responses]}
    if args.method == "auto":  # every segment of every axis, estimated or not (taos.identify.segments)
        from taos.identify.segments import segment_record
        used = {(r.axis, s["index"]) for r in responses for s in r.meta.get("segments") or () if s["used"]}
        d["segments"] = [{**s.to_dict(), "used": (ax, s.index) in used}
                         for ax, ss in segment_record(data).items() for s in ss]
    from taos.results import output_provenance
    d["provenance"] = {**output_provenance([model] if model is not None else [], inputs=[("data", args.data)]),
                       "method": args.method, "nperseg": args.nperseg, "seeds": "none (deterministic)"}
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    if not args.json or args.json == "-":
        if d.get("segments"):
            print(_segment_table(d["segments"]), file=out)
        for r, rd in zip(responses, d["responses"]):
            ex = rd.get("excitation") or {}
            forced = " (forced by --method)" if r.meta.get("method_forced") else ""
            print(f"{r.axis}: {ex.get('kind', '?')} -- {ex.get('reason', '')}", file=out)
            print(f"{r.axis} ({r.method}{forced}), {len(r)} points", file=out)
            pk = "piston" if rd["piston"] else "piston_in_per_deg"
            pl = "x_p/(R theta_c)" if rd["piston"] else "x_p/theta_c in/deg"
            hdr = f"{'freq_hz':>9} {'amp_deg':>8} {'piston dB':>10} {'deg':>8} {'coh':>6}"
            if rd["engine"]:
                hdr += f" {'engine dB':>10} {'deg':>8} {'coh':>6}"
            print(hdr + f"   (piston {pl}; phase continuous from low frequency)", file=out)
            for k in range(len(r)):
                row = (f"{r.freq_hz[k]:9.4g} {math.degrees(r.amplitude_rad[k]):8.3g} {rd[pk]['gain_db'][k]:10.3f} "
                       f"{rd[pk]['phase_deg'][k]:8.2f} {r.coherence_piston[k]:6.3f}")
                if rd["engine"]:
                    row += (f" {rd['engine']['gain_db'][k]:10.3f} {rd['engine']['phase_deg'][k]:8.2f} "
                            f"{r.coherence_engine[k]:6.3f}")
                print(row, file=out)
    return 0


def _segment_table(segments: list[dict]) -> str:
    """The excitation segments as text: axis, index, kind, time span, frequencies, amplitude, use."""
    lines = [f"{'axis':5s} {'#':>2s} {'excitation':10s} {'from_s':>8s} {'to_s':>8s} {'freq_hz':>13s} "
             f"{'amp_deg':>8s}  used"]
    for s in segments:
        f0, f1 = s["freq_range_hz"]
        fr = "-" if f0 is None else (f"{f0:.3g}" if abs(f1 - f0) <= 1e-4 * f0 else f"{f0:.3g}-{f1:.3g}")
        a = "-" if s["amplitude_deg"] is None else f"{s['amplitude_deg']:.3g}"
        lines.append(f"{s['axis']:5s} {s['index']:2d} {s['kind']:10s} {s['t0_s']:8.2f} {s['t1_s']:8.2f} {fr:>13s} "
                     f"{a:>8s}  {'yes' if s['used'] else 'no'}")
    return "\n".join(lines)


def cmd_fit(args) -> int:
    if getattr(args, "engine", "simplex") == "taos":
        from taos.cli.identify3d import cmd_fit3d
        return cmd_fit3d(args)
    if args.allow_unidentifiable:
        raise InputError("command line", "--allow-unidentifiable", "--engine taos", got="--engine simplex")
    from taos.identify.fit import fit_frequency_response
    from taos.model import load_model

    from taos.bounds import MAX_STARTS

    _outputs(args, "json", "plot", "out_model")
    args.starts = 3 if args.starts is None else args.starts   # the planar fit's default
    if not 1 <= args.starts <= MAX_STARTS:
        raise InputError("command line", "--starts", f"a number of starts from 1 to {MAX_STARTS}", got=str(args.starts))
    if not 0.0 <= args.min_coherence <= 1.0:
        raise InputError("command line", "--min-coherence", "a coherence from 0 to 1", got=repr(args.min_coherence))
    model = load_model(args.model, friction=args.friction)
    free = _free(args.free)
    from taos.identify.surrogate import PARAMETERS

    start = _parse_start(args.start, PARAMETERS)
    bounds = _parse_bounds(args.bounds)
    responses, labels = [], []
    for path in args.data:                       # read and validate everything before any output
        _, rs = _estimate(path, args)
        responses += rs
        labels.append(str(path))
    res = fit_frequency_response(model, responses, free, start=start, starts=args.starts,
                                 use_engine=not args.no_engine, min_coherence=args.min_coherence,
                                 correct=None if not args.no_correction else False, bounds=bounds)
    d = res.to_dict()
    adequacy = res.adequacy()
    d["model_file"] = model.source
    from taos.results import output_provenance
    d["provenance"] = {**output_provenance([model], [("data", p) for p in args.data]), "starts": args.starts,
                       "seeds": "none (deterministic starts)"}
    if args.out_model:
        res.write_model(args.out_model, data_label=", ".join(labels))
        d["fitted_model_file"] = str(args.out_model)
    if args.plot:
        from taos.identify.fit import fitted_linear_curves
        from taos.plotting import fit as pf
        from taos.plotting import save
        save(pf.plot_fit(res, fitted_linear_curves(res)), args.plot)
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    table = res.table()
    if not adequacy.ok:  # the warning once, on standard error (the table's last line is the same message)
        table = table.rsplit("\n", 1)[0]
    print(table, file=out)
    if args.out_model:
        print(f"wrote {args.out_model}", file=out)
    if not adequacy.ok:
        print(adequacy.message(), file=sys.stderr)
        if args.strict:
            return 4
    return 0


def write_comparison(cmp, out_dir, json_path: str | None = None):
    """Write ``table.txt``, ``comparison.json``, ``piston_side_by_side.png`` (paper fig. 2) and
    ``bode_overlay.png`` (fig. 11 style) of a :class:`taos.identify.compare.Comparison` into
    ``out_dir`` through :func:`taos.results.write_output_folder` (only its own files, each
    complete or not at all; foreign files in ``out_dir`` are left alone). Returns the folder."""
    import json

    import matplotlib.pyplot as plt

    from taos.identify.compare import comparison_curves
    from taos.plotting import fit as pf
    from taos.plotting._common import freeze_layout
    from taos.results import output_provenance, write_output_folder

    curves = comparison_curves(cmp)

    def fig_writer(make):
        def write(p):
            fig = make(curves)
            try:
                freeze_layout(fig)   # one draw on save
                fig.savefig(p, dpi=120, format="png")
            finally:
                plt.close(fig)
        return write

    payload = {**cmp.to_dict(), "provenance": output_provenance(list(cmp.models))}
    text = json.dumps(payload, indent=2, allow_nan=False) + "\n"
    out = write_output_folder(out_dir, {
        "table.txt": lambda p: p.write_text(cmp.table() + "\n"),
        "comparison.json": lambda p: p.write_text(text),
        "piston_side_by_side.png": fig_writer(pf.plot_compare_side_by_side),
        "bode_overlay.png": fig_writer(pf.plot_compare_overlay),
    })
    if json_path:
        write_json(json_path, payload)
    return out


SERIES_FILES = ("series_table.txt", "series.json", "responses_overlay.png", "trend.png")


def write_series(series, out_dir, json_path: str | None = None, model_path=None, record_paths=()):
    """Write ``series_table.txt``, ``series.json``, ``responses_overlay.png`` and ``trend.png`` of
    a :class:`taos.identify.series.RecordSeries` into ``out_dir`` (each complete or not at all;
    foreign files left alone), and the JSON also to ``json_path``. Returns the folder."""
    import json

    import matplotlib.pyplot as plt

    from taos.identify.series import series_curves
    from taos.plotting import series as ps
    from taos.results import output_provenance, write_output_folder

    curves = series_curves(series)

    def fig_writer(make, *a):
        def write(p):
            fig = make(series, *a)
            try:
                fig.savefig(p, dpi=120, format="png")
            finally:
                plt.close(fig)
        return write

    payload = {**series.to_dict(), "provenance": output_provenance([series.model], [("data", p) for p in record_paths])}
    text = json.dumps(payload, indent=2, allow_nan=False, default=str) + "\n"
    out = write_output_folder(out_dir, {
        "series_table.txt": lambda p: p.write_text(series.table() + "\n"),
        "series.json": lambda p: p.write_text(text),
        "responses_overlay.png": fig_writer(ps.plot_series_responses, curves),
        "trend.png": fig_writer(ps.plot_series_trend),
    })
    if json_path:
        write_json(json_path, json.loads(text))
    return out


def _cmd_compare_series(args) -> int:
    """``taos compare --model MODEL --records R1 R2 ... --out DIR``: a test series fitted record by
    record and its trend (:mod:`taos.identify.series`)."""
    from taos.identify.series import MAX_RECORDS, MIN_RECORDS, fit_series
    from taos.model import load_model
    from taos.results import check_output_folder

    if args.model_a is not None or args.model_b is not None:
        raise InputError("command line", "MODEL_A MODEL_B", "either two models (MODEL_A MODEL_B) or --model MODEL "
                         "--records R1 R2 ..., not both", got=" ".join(x for x in (args.model_a, args.model_b) if x))
    if args.data:
        raise InputError("command line", "--data", "no --data with --records (each record is fitted from --model)",
                         got=" ".join(args.data))
    if not args.model:
        raise InputError("command line", "--model", "a start model for the series (--model MODEL --records ...)",
                         got="none")
    if not MIN_RECORDS <= len(args.records) <= MAX_RECORDS:
        raise InputError("command line", "--records", f"{MIN_RECORDS} to {MAX_RECORDS} record files",
                         got=str(len(args.records)))
    from taos.bounds import MAX_STARTS
    args.starts = 1 if args.starts is None else args.starts   # the series' default
    if not 1 <= args.starts <= MAX_STARTS:
        raise InputError("command line", "--starts", f"a number of starts from 1 to {MAX_STARTS}", got=str(args.starts))
    check_output_folder(args.out, SERIES_FILES)
    _outputs(args, "json")
    free = _free(args.free, "load_stiffness,coulomb_torque")
    labels = [x.strip() for x in args.labels.split(",")] if args.labels is not None else None
    model = load_model(args.model)
    from taos.identify.data import load_test_data
    from taos.identify.surrogate import check_free
    check_free(model, free)
    datas = [load_test_data(p) for p in args.records]          # every record read and validated first
    axes = None if args.axis in (None, "both") else (args.axis,)
    for p, d in zip(args.records, datas):
        if axes and axes[0] not in d.axes:
            raise InputError(str(p), f"{axes[0]}_command", f"a {axes[0]} axis in the data", got=", ".join(d.axes))
    series = fit_series(model, datas, free, labels=labels, method=args.method, axes=axes, nperseg=args.nperseg,
                        starts=args.starts, progress=not args.json == "-")
    out = write_series(series, args.out, json_path=args.json, record_paths=args.records)
    stream = sys.stderr if args.json == "-" else sys.stdout
    print(series.table(), file=stream)
    print(f"wrote {out}/ ({', '.join(SERIES_FILES)})", file=stream)
    return 0


def cmd_compare(args) -> int:
    if getattr(args, "engine", "simplex") == "taos":
        from taos.cli.identify3d import cmd_compare3d
        return cmd_compare3d(args)
    if args.records:
        return _cmd_compare_series(args)
    if args.model is not None or args.free is not None:
        raise InputError("command line", "--model" if args.model is not None else "--free",
                         "--records R1 R2 ... with it (series mode), or two models MODEL_A MODEL_B", got="no --records")
    if args.model_a is None or args.model_b is None:
        raise InputError("command line", "MODEL_A MODEL_B", "two models (or --model MODEL --records R1 R2 ...)",
                         got=" ".join(x for x in (args.model_a, args.model_b) if x) or "none")
    from taos.identify.compare import compare_models
    from taos.model import load_model

    from taos.results import check_output_folder

    check_output_folder(args.out, ("table.txt", "comparison.json", "piston_side_by_side.png", "bode_overlay.png"))
    _outputs(args, "json")
    ma = load_model(args.model_a)
    mb = load_model(args.model_b)
    da, db = (), ()
    if args.data:
        _, da = _estimate(args.data[0], args)
        _, db = _estimate(args.data[1], args)
    labels = tuple(x.strip() for x in args.labels.split(",")) if args.labels is not None else None
    if labels is not None and (len(labels) != 2 or not all(labels)):
        raise InputError("command line", "--labels", "two labels like ambient,'hot fire'", got=args.labels)
    cmp = compare_models(ma, mb, da, db, labels)
    out = write_comparison(cmp, args.out, json_path=args.json)
    stream = sys.stderr if args.json == "-" else sys.stdout
    print(cmp.table(), file=stream)
    from taos.fem.shift import DEFAULT_PATH, fem_shift_share
    if DEFAULT_PATH.is_file():  # the gimbal FEM's part in an ambient -> hot-fire K_L change, with its range
        print(fem_shift_share().text(), file=stream)
    print(f"wrote {out}/ (table.txt, comparison.json, piston_side_by_side.png, bode_overlay.png)", file=stream)
    return 0


def add_parsers(sub) -> None:
    def est_opts(p):
        p.add_argument("--method", choices=("auto", "dwell", "h1"), default="auto",
                       help="sine-dwell correlation or H1 (Welch) estimate; auto: classify each command (dwell, sweep, "
                       "multisine), say why, and refuse when unsure")
        p.add_argument("--axis", choices=AXES + ("both",), default="both")
        p.add_argument("--nperseg", type=int, help="H1 segment length in samples")

    p = sub.add_parser("estimate", help="frequency responses estimated from a vectoring record (CSV/HDF5)")
    p.add_argument("data", help="time-history file (.csv with 'signal [unit]' header or sidecar .toml, or .h5)")
    p.add_argument("--model", help="model file: its moment arm gives the piston as x_p/(R theta_c) and its linear "
                   "phase the branch of each point (phase continuous from low frequency)")
    est_opts(p)
    p.add_argument("--json", metavar="PATH", help="write JSON here ('-' for standard output)")
    p.set_defaults(func=cmd_estimate)

    p = sub.add_parser("fit", help="fit model parameters to test data (CasADi/IPOPT)")
    p.add_argument("data", nargs="+", help="time-history file(s), e.g. models/data/greenrun_hotfire_synthetic.csv")
    p.add_argument("--model", required=True, help="model file whose other values are held")
    p.add_argument("--free", required=True, help="comma-separated parameters, e.g. load_stiffness,coulomb_torque")
    add_friction_option(p, "swap the friction law before fitting (keeps the file's torque levels)")
    p.add_argument("--start", action="append", metavar="NAME=VALUE",
                   help="start value with unit, e.g. --start 'load_stiffness=150000 lbf/in' (repeatable)")
    p.add_argument("--starts", type=int, default=None,
                   help="number of IPOPT starts (default 3): the best of the start values and the local minima of "
                        "a describing-function grid over load_stiffness and coulomb_torque when either is free; "
                        "--engine taos: local stages from the start and the STARTS-1 best cells of its global grid "
                        "(default: the start, and the best cell when better)")
    p.add_argument("--no-engine", action="store_true", help="fit the piston responses only")
    p.add_argument("--no-correction", action="store_true", help="skip the time-domain defect correction (the planar "
                   "fit's; refused with --engine taos, which replays the nonlinear model and has none)")
    p.add_argument("--min-coherence", type=float, default=0.5)
    p.add_argument("--bounds", action="append", metavar="NAME=LOW:HIGH",
                   help="bounds with units, e.g. --bounds 'load_stiffness=50000 lbf/in:400000 lbf/in' (repeatable; "
                        "default: physical ranges, the load resonance within the measured band and the friction "
                        "torque up to the actuator's stall torque, else 0.05 to 20 times the start; see the JSON "
                        "'bounds' and 'bounds_basis')")
    p.add_argument("--strict", action="store_true",
                   help="exit 4 when the model cannot explain the data (verdict 'inadequate'); without it the "
                        "verdict is a WARNING in the text and 'adequacy' in the JSON")
    p.add_argument("--out-model", metavar="TOML", help="write the fitted model file here")
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="save data vs fit and residuals")
    p.add_argument("--json", metavar="PATH", help="write JSON here ('-' for standard output)")
    p.add_argument("--engine", choices=("simplex", "taos"), default="simplex",
                   help="taos: fit the 3-D model (two-axis records replayed; taos.identify.fit3d)")
    p.add_argument("--allow-unidentifiable", action="store_true",
                   help="--engine taos: report parameters the record does not identify (flagged) instead of "
                        "refusing (exit 2)")
    est_opts(p)
    p.set_defaults(func=cmd_fit)

    p = sub.add_parser("compare", help="two model conditions side by side (e.g. ambient vs hot fire), or a series "
                       "of test records fitted one by one with the trend of K_L, notch and friction level")
    p.add_argument("model_a", nargs="?", help="model of condition A (two-model mode)")
    p.add_argument("model_b", nargs="?", help="model of condition B (two-model mode)")
    p.add_argument("--data", nargs=2, metavar=("A_DATA", "B_DATA"), help="test data of each condition")
    p.add_argument("--model", help="series mode: the start model every record is fitted from")
    p.add_argument("--records", nargs="+", metavar="RECORD", help="series mode: two or more test records (.csv/.h5), "
                   "in test order (or sorted by their test_date metadata when every record carries one)")
    p.add_argument("--free", help="series mode: fitted parameters (default load_stiffness,coulomb_torque)")
    p.add_argument("--starts", type=int, default=None, help="series mode: starts per fit (default 1); --engine taos: "
                   "local stages per fit from the start and the STARTS-1 best global-grid cells")
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--labels", help="labels, comma-separated: two (default the model names), or one per record "
                   "(default the file names)")
    p.add_argument("--json", metavar="PATH", help="also write the comparison JSON here ('-' for standard output)")
    p.add_argument("--engine", choices=("simplex", "taos"), default="simplex",
                   help="taos: each condition's record fitted with the 3-D model and its own FEM gimbal; "
                        "Figure 11 analogue and the K_L shift the FEM does not explain")
    est_opts(p)
    p.set_defaults(func=cmd_compare)
