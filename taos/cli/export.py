"""``taos export MODEL --out FILE.mat | DIR`` : linear models and responses for other tools
(:mod:`taos.interop.files`)."""

from __future__ import annotations

import numpy as np

from taos.errors import InputError


def cmd_export(args) -> int:
    from taos.cli.basic import parse_float_list
    from taos.interop.files import export_csv, export_mat
    from taos.model import load_model

    from taos.results import check_output_file

    if (args.format or ("mat" if str(args.out).lower().endswith(".mat") else "csv")) == "mat":
        check_output_file(args.out, "--out", (".mat",))   # before any work
    model = load_model(args.model, friction=getattr(args, "friction", None))
    freqs = (parse_float_list(args.freq_hz, "--freq-hz") if args.freq_hz
             else np.logspace(-1, np.log10(30.0), 200).tolist())
    fmt = args.format or ("mat" if str(args.out).lower().endswith(".mat") else "csv")
    if fmt == "mat":
        if not str(args.out).lower().endswith(".mat"):
            raise InputError("command line", "--out", "a .mat file for --format mat", got=repr(args.out))
        export_mat(model, args.out, freqs)
        print(f"wrote {args.out} (pitch, yaw: A, B, C, D with signal names; linear response at {len(freqs)} "
              "frequencies)")
    else:
        paths = export_csv(model, args.out, freqs)
        print(f"wrote {len(paths)} CSV files in {args.out}")
    return 0


def add_parsers(sub) -> None:
    p = sub.add_parser("export", help="linear state space and response to MATLAB .mat or CSV")
    p.add_argument("model", help="model file (TOML), e.g. models/rs25_hotfire.toml")
    p.add_argument("--out", required=True, help="FILE.mat, or a folder for CSV files")
    p.add_argument("--format", choices=("mat", "csv"), help="default: mat when --out ends in .mat, else csv")
    p.add_argument("--freq-hz", help="response frequencies (default 200 from 0.1 to 30 Hz)")
    p.set_defaults(func=cmd_export)
