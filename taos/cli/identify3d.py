"""``taos fit --engine taos`` and ``taos compare --engine taos``: the 3-D TAOS model fitted to
two-axis records (:mod:`taos.identify.fit3d`) and ambient against hot fire with each
condition's FEM gimbal (:mod:`taos.identify.compare3d`)."""

from __future__ import annotations

import sys

from taos.cli._fit_args import _free, _outputs, _parse_bounds, _parse_start
from taos.errors import InputError
from taos.results import write_json

COMPARE3D_FILES = ("table.txt", "comparison.json", "figure11.png")


def _refuse_planar_only(args) -> None:
    """The planar fit's options the 3-D fit has no meaning for: one line, exit 2."""
    if getattr(args, "no_correction", False):
        raise InputError("command line", "--no-correction", "no --no-correction with --engine taos (the 3-D fit "
                         "replays the nonlinear model itself: it has no defect correction to skip)", got="given")


def _starts(args) -> int | None:
    """--starts with --engine taos: local stages from the start and the STARTS-1 best grid cells."""
    from taos.bounds import MAX_STARTS
    n = getattr(args, "starts", None)
    if n is not None and not 1 <= n <= MAX_STARTS:
        raise InputError("command line", "--starts", f"a number of starts from 1 to {MAX_STARTS}", got=str(n))
    return n


def cmd_fit3d(args) -> int:
    from taos.identify.data import load_test_data
    from taos.identify.fit3d import fit_taos
    from taos.model import load_model
    from taos.results import output_provenance
    from taos.taos3d import taos_model

    _outputs(args, "json", "plot", "out_model")
    _refuse_planar_only(args)
    if not 0.0 <= args.min_coherence <= 1.0:
        raise InputError("command line", "--min-coherence", "a coherence from 0 to 1", got=repr(args.min_coherence))
    starts = _starts(args)
    from taos.identify.params3d import PARAMETERS3D
    bounds = _parse_bounds(args.bounds, PARAMETERS3D)
    tm = taos_model(load_model(args.model, friction=args.friction))
    free = _free(args.free)
    start = _parse_start(args.start, PARAMETERS3D)
    datas = [load_test_data(p) for p in args.data]             # every record read and checked first
    axes = None if args.axis in (None, "both") else (args.axis,)
    res = fit_taos(tm, datas, free, start=start, method=args.method, axes=axes, nperseg=args.nperseg,
                   min_coherence=args.min_coherence, use_engine=not args.no_engine,
                   refuse=not args.allow_unidentifiable, starts=starts, bounds=bounds)
    d = res.to_dict()
    d["model_file"] = tm.base.source
    d["provenance"] = {**output_provenance([tm.base], [("data", p) for p in args.data]), "engine": "taos",
                       "solver": res.solver, "seeds": "none (deterministic)"}
    if args.out_model:
        res.write_model(args.out_model, data_label=", ".join(map(str, args.data)))
        d["fitted_model_file"] = str(args.out_model)
    if args.plot:
        from taos.identify.compare3d import Comparison3d, comparison3d_curves
        from taos.plotting import save
        from taos.plotting.compare import plot_compare3d
        one = Comparison3d((tm.base.name, ""), (res,), (0.0,), (0.0,), (0.0,), (0.0,))
        save(plot_compare3d(comparison3d_curves(one), "Data against the 3-D TAOS fit"), args.plot)
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    print(res.table(), file=out)
    if args.out_model:
        print(f"wrote {args.out_model}", file=out)
    if not res.adequacy().ok and args.strict:
        return 4
    return 0


def cmd_compare3d(args) -> int:
    from taos.identify.compare3d import compare_taos, comparison3d_curves
    from taos.identify.data import load_test_data
    from taos.model import load_model
    from taos.results import check_output_folder, output_provenance, write_output_folder
    from taos.taos3d import taos_model

    if args.records or args.model:
        raise InputError("command line", "--records" if args.records else "--model",
                         "two models and --data A_DATA B_DATA with --engine taos (no series mode)", got="given")
    if args.model_a is None or args.model_b is None or not args.data:
        raise InputError("command line", "MODEL_A MODEL_B --data A_DATA B_DATA",
                         "two models and their records with --engine taos",
                         got=" ".join(x for x in (args.model_a, args.model_b) if x) or "none")
    starts = _starts(args)
    check_output_folder(args.out, COMPARE3D_FILES)
    _outputs(args, "json")
    labels = tuple(x.strip() for x in args.labels.split(",")) if args.labels is not None else None
    if labels is not None and (len(labels) != 2 or not all(labels)):
        raise InputError("command line", "--labels", "two labels like ambient,'hot fire'", got=args.labels)
    models = [taos_model(load_model(p)) for p in (args.model_a, args.model_b)]
    datas = [[load_test_data(p)] for p in args.data]
    frees = []
    for m in models:   # the friction level only where the law has friction
        frees.append(_free(args.free, "load_stiffness,coulomb_torque" if m.base.friction.has_friction
                           else "load_stiffness"))
    axes = None if args.axis in (None, "both") else (args.axis,)
    cmp = compare_taos(models, datas, frees, labels or (models[0].base.name, models[1].base.name),
                       method=args.method, axes=axes, nperseg=args.nperseg, starts=starts)
    payload = {**cmp.to_dict(), "provenance": {**output_provenance([m.base for m in models],
                                                                   [("data", p) for p in args.data]),
                                               "engine": "taos"}}
    import json

    import matplotlib.pyplot as plt

    from taos.plotting.compare import plot_compare3d
    text = json.dumps(payload, indent=2, allow_nan=False, default=str) + "\n"

    def fig(p):
        f = plot_compare3d(comparison3d_curves(cmp))
        try:
            f.savefig(p, dpi=120, format="png")
        finally:
            plt.close(f)
    out = write_output_folder(args.out, {"table.txt": lambda p: p.write_text(cmp.table() + "\n"),
                                         "comparison.json": lambda p: p.write_text(text), "figure11.png": fig})
    if args.json:
        write_json(args.json, json.loads(text))
    stream = sys.stderr if args.json == "-" else sys.stdout
    print(cmp.table(), file=stream)
    print(f"wrote {out}/ ({', '.join(COMPARE3D_FILES)})", file=stream)
    return 0
