"""``taos fmu MODEL --out FILE.fmu [--standalone]``: the nonlinear TVC of one engine as an FMI 2.0
co-simulation FMU: with ``--standalone`` in C, no Python at run time
(:func:`taos.cosim._standalone.build_standalone_fmu`, planar simplex model); else through
pythonfmu, running taos in the host's Python (:func:`taos.cosim.build_fmu`, either engine)."""

from __future__ import annotations

from taos.cli import add_friction_option
from taos.planar.envelope import ENGINES


def cmd_fmu(args) -> int:
    if args.standalone:
        from taos.cosim._standalone import build_standalone_fmu
        from taos.errors import InputError

        if args.engine != "simplex":
            raise InputError("command line", "--engine", "simplex with --standalone (the 3-D model has no "
                             "standalone FMU)", got=repr(args.engine))
        b = build_standalone_fmu(args.model, args.out, friction=args.friction, avionics=args.avionics, dt_s=args.dt,
                                 allow_unstable=args.allow_unstable)
        runs = "standalone C, linux64 binary and sources; no Python at run time"
    else:
        from taos.cosim import build_fmu

        b = build_fmu(args.model, args.out, engine=args.engine, friction=args.friction, avionics=args.avionics,
                      dt_s=args.dt, allow_unstable=args.allow_unstable)
        runs = "runs in a Python with taos importable"
    print(f"wrote {b.path} (FMI 2.0 co-simulation, {b.engine} engine, internal step {b.dt_s:g} s; "
          f"{b.n_inputs} inputs, {b.n_outputs} outputs, {b.n_parameters} parameters; model_sha256 "
          f"{b.model_sha256[:12]}...; {runs})")
    return 0


def add_parsers(sub) -> None:
    from taos.cosim._options import AVIONICS

    p = sub.add_parser("fmu", help="the nonlinear TVC (both axes) as an FMI 2.0 co-simulation FMU")
    p.add_argument("model", help="model file (TOML), e.g. models/rs25_hotfire.toml")
    p.add_argument("--out", required=True, help="FMU file to write (*.fmu)")
    p.add_argument("--standalone", action="store_true",
                   help="C code and a linux64 binary, no Python at run time (simplex engine; needs a C compiler); "
                   "default: a pythonfmu FMU that runs taos in the host's Python")
    p.add_argument("--engine", choices=ENGINES, default="simplex", help="simplex (planar, per axis) or taos (3-D)")
    add_friction_option(p)
    p.add_argument("--avionics", choices=AVIONICS, default="model",
                   help="model: the file's quantisation and crossover curve (default); bounding: the paper's "
                   "-1 dB gain without quantisation (as taos lco --avionics bounding)")
    p.add_argument("--dt", type=float, default=None, help="internal step [s] (default: the engine's, 2e-4 s "
                   "simplex, 4e-4 s taos); communication steps must be multiples of it")
    p.add_argument("--allow-unstable", action="store_true", help="build a model whose linear block is unstable")
    p.set_defaults(func=cmd_fmu)
