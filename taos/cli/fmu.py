"""``taos fmu MODEL --out FILE.fmu [--engine simplex|taos] [--python]``: the nonlinear TVC of one
engine as an FMI 2.0 co-simulation FMU. By default in C, no Python at run time: the planar
simplex model (:func:`taos.cosim._standalone.build_standalone_fmu`) or the 3-D TAOS model
(:func:`taos.cosim._standalone3d.build_standalone_fmu_3d`); with ``--python`` through
pythonfmu, running taos in the host's Python (:func:`taos.cosim.build_fmu`), an FMU that lacks
the host behaviours :data:`PYTHON_LACKS` lists."""

from __future__ import annotations

from taos.cli import add_friction_option
from taos.planar.envelope import ENGINES

#: what a ``--python`` (pythonfmu) FMU lacks, as the help, the refusal and docs/guide/fmu.md say it
PYTHON_LACKS = ("needs Python 3.11 with taos and its stack on the importing machine; reports fmi2Terminated at "
                "all times, so FMPy ends a run at its first discarded step; claims no FMU state yet returns OK "
                "without saving one; accepts fixed parameters after initialisation; returns fmi2Fatal for host "
                "mistakes; ignores currentCommunicationPoint; declares no output dependencies; a C host can crash "
                "at exit")


def cmd_fmu(args) -> int:
    from taos.errors import InputError

    if args.python and args.standalone:
        raise InputError("command line", "--python, --standalone", "one of them (--standalone is the default)",
                         got="both")
    if not args.python:
        if args.engine == "taos":
            from taos.cosim._standalone3d import build_standalone_fmu_3d as build
        else:
            from taos.cosim._standalone import build_standalone_fmu as build
        b = build(args.model, args.out, friction=args.friction, avionics=args.avionics, dt_s=args.dt,
                  allow_unstable=args.allow_unstable)
        runs = "standalone C, linux64 binary and sources; no Python at run time"
    else:
        from taos.cosim import build_fmu

        b = build_fmu(args.model, args.out, engine=args.engine, friction=args.friction, avionics=args.avionics,
                      dt_s=args.dt, allow_unstable=args.allow_unstable)
        runs = "pythonfmu: runs in a Python with taos importable; " + PYTHON_LACKS
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
                   help="C sources and a linux64 binary, no Python at run time (the default, either engine; needs "
                   "a C compiler and FMPy's FMI headers at build time)")
    p.add_argument("--python", action="store_true",
                   help="instead a pythonfmu FMU that runs taos in the host's Python (either engine). It " + PYTHON_LACKS)
    p.add_argument("--engine", choices=ENGINES, default="simplex",
                   help="simplex (planar, per axis) or taos (3-D: the standalone FMU has no tunable parameters)")
    add_friction_option(p)
    p.add_argument("--avionics", choices=AVIONICS, default="model",
                   help="model: the file's quantisation and crossover curve (default); bounding: the paper's "
                   "-1 dB gain without quantisation (as taos lco --avionics bounding)")
    p.add_argument("--dt", type=float, default=None, help="internal step [s] (default: the engine's, 2e-4 s "
                   "simplex, 4e-4 s taos, at most 1e-3 s); communication steps must be multiples of it (the standalone "
                   "FMU's internal_step_s parameter can change it before initialisation)")
    p.add_argument("--allow-unstable", action="store_true", help="build a model whose linear block is unstable")
    p.set_defaults(func=cmd_fmu)
