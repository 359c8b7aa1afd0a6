"""``taos view`` (3-D gimbal animation, live or offline HTML) and ``taos greenrun`` (the report:
:func:`taos.report.greenrun`)."""

from __future__ import annotations

import math
import sys

from taos.cli import add_friction_option
from taos.errors import InputError
from taos.planar.envelope import ENGINES


def _positive(value: float, option: str) -> float:
    if not (math.isfinite(value) and value > 0):
        raise InputError("command line", option, "a positive number", got=repr(value))
    return value


def cmd_view(args) -> int:
    from taos.viewer import load_run, serve, write_html

    if args.paused_at is not None and not args.html:
        raise InputError("command line", "--paused-at", "--html too (the live viewer has its own time slider)",
                         got=repr(args.paused_at))
    if args.html:
        from taos.results import check_output_file
        check_output_file(args.html, "--html")
    th = load_run(args.run)
    kw = dict(angle_scale=_positive(args.angle_scale, "--angle-scale"),
              deflection_scale=(None if args.deflection_scale is None
                                else _positive(args.deflection_scale, "--deflection-scale")),
              fps=_positive(args.fps, "--fps"),
              gimbal_scale=(None if args.gimbal_scale is None else _positive(args.gimbal_scale, "--gimbal-scale")))
    if args.html:
        if args.paused_at is not None and not (0 <= args.paused_at <= th.t_s[-1]):
            raise InputError("command line", "--paused-at", f"a time in [0, {th.t_s[-1]:g}] s", got=repr(args.paused_at))
        write_html(th, args.html, paused_at_s=args.paused_at, **kw)
        print(f"wrote {args.html}")
        return 0

    def ready(url):
        print(f"taos view: serving {args.run} at {url}  (127.0.0.1 only; Ctrl-C to stop)", flush=True)

    rc = serve(th, on_ready=ready, **kw)
    print("taos view: stopped", flush=True)
    return rc


def cmd_greenrun(args) -> int:
    from pathlib import Path

    from taos.report.analysis import DEFAULT_SPEC, greenrun

    spec = None if args.spec == "none" else (args.spec or DEFAULT_SPEC)
    res = greenrun(args.model, args.profile, engine=args.engine, friction=args.friction, out=args.out,
                   spec=spec, data=args.data, allow_unstable=args.allow_unstable, progress=not args.quiet)
    out = Path(args.out)
    if res.spec_verdict_text:
        print(res.spec_verdict_text)
    print(f"wrote {out / 'index.html'} and {out / 'greenrun.h5'}")
    return 0


def add_parsers(sub) -> None:
    p = sub.add_parser("view", help="3-D gimbal animation of a run (meshcat): live, or --html OUT.html")
    p.add_argument("run", help="run file (HDF5) written by taos simulate")
    p.add_argument("--html", metavar="OUT.html", help="write one self-contained offline HTML file instead of serving")
    p.add_argument("--paused-at", type=float, metavar="SECONDS",
                   help="with --html: open paused at this time (the page also takes ?t=SECONDS)")
    p.add_argument("--angle-scale", type=float, default=1.0, help="engine-angle exaggeration (default 1)")
    p.add_argument("--deflection-scale", type=float, default=None,
                   help="load-path deflection exaggeration, x_p - R theta (default: automatic, "
                        "peak drawn near 0.15 m; shown in the page legend)")
    p.add_argument("--gimbal-scale", type=float, default=None,
                   help="3-D (--engine taos) runs: gimbal-half deflection exaggeration (default: automatic, "
                        "peak drawn near 3 cm)")
    p.add_argument("--fps", type=float, default=100.0, help="keyframes per second of run time (default 100)")
    p.set_defaults(func=cmd_view)

    p = sub.add_parser("greenrun", help="two-axis Green Run profile through the model; HTML report in --out")
    p.add_argument("model", help="model file (TOML), e.g. models/rs25_hotfire.toml")
    p.add_argument("--out", default="out/greenrun", help="report folder (default out/greenrun)")
    p.add_argument("--profile", default=None, help="profile (default models/profiles/greenrun_two_axis.toml)")
    add_friction_option(p)
    p.add_argument("--spec", help="spec mask (TOML) marked pass/fail on the plots and in summary.json "
                   "(default models/specs/tvc_actuator_notional.toml; 'none' for no check)")
    p.add_argument("--data", help="measured record overlaid on the model (e.g. models/data/greenrun_hotfire_synthetic.csv)")
    p.add_argument("--engine", choices=ENGINES, default="simplex",
                   help="simplex (planar) or taos (3-D engine, FEM gimbal halves)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--allow-unstable", action="store_true",
                   help="run a model whose linear block is unstable, and do not stop at the envelope")
    p.set_defaults(func=cmd_greenrun)


if __name__ == "__main__":  # pragma: no cover
    from taos.cli import main
    sys.exit(main())
