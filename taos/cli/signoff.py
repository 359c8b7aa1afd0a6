"""``taos lco ... --requirements FILE [--signoff DIR]``: the flight sign-off
(:mod:`taos.flight.signoff`): the verdict and the pass/fail table with the margin to each limit
on standard output, the sign-off in the ``--json`` output, and with ``--signoff DIR`` the folder
``DIR/signoff.json`` + ``DIR/signoff.html`` (written whole or not at all)."""

from __future__ import annotations

import dataclasses
import json
import sys

from taos.results import write_json

#: the sign-off folder's files
OUTPUTS = ("signoff.json", "signoff.html")


def run_signoff(args, flight, model, amps, freqs) -> int:
    from taos.flight.lco_map import parse_sweep
    from taos.flight.signoff import load_requirements, sign_off
    from taos.results import check_output_folder, write_output_folder

    from taos.errors import InputError

    for flag in ("plot", "plot_df", "plot_time", "df_out", "plot_map"):   # outputs of the other modes
        if getattr(args, flag, None):
            raise InputError("command line", "--" + flag.replace("_", "-"), "no plot or map file with --requirements "
                             "(the sign-off page, --signoff DIR, has the Nichols chart)", got=str(getattr(args, flag)))
    for flag in ("out", "resume", "workers", "scheduler", "scheduler_file"):   # a map campaign's options
        if getattr(args, flag, None):
            raise InputError("command line", "--" + flag.replace("_", "-"), "not with --requirements (the sign-off "
                             "runs in this process; its folder is --signoff DIR)", got=str(getattr(args, flag)))
    req = load_requirements(args.requirements)
    axes = [parse_sweep(s) for s in args.sweep or ()]
    if args.signoff:   # every input and output checked before any work
        check_output_folder(args.signoff, OUTPUTS, "--signoff")
    if axes and args.axis:
        flight = dataclasses.replace(flight, axis=args.axis)
    so = sign_off(req, flight, model, sweep_axes=axes, progress=not args.json == "-", axis=args.axis,
                  duration_s=args.duration, avionics=args.avionics, amplitudes_rad=amps, freq_hz=freqs,
                  window_s=min(120.0, 0.5 * args.duration), time_domain=not args.no_time_domain, steady=args.steady)
    d = {"signoff": so.to_dict(), "avionics": args.avionics}
    if args.signoff:
        from taos.plotting.signoff_page import render_signoff_html
        page = render_signoff_html(so)
        text = json.dumps(d, indent=2, allow_nan=False) + "\n"
        write_output_folder(args.signoff, {"signoff.json": lambda p: p.write_text(text),
                                           "signoff.html": lambda p: p.write_text(page, encoding="utf-8")},
                            "--signoff")
    if args.json:
        write_json(args.json, d)
    out = sys.stderr if args.json == "-" else sys.stdout
    print(so.text(), file=out)
    print(so.table_text(), file=out)
    if args.signoff:
        print(f"wrote {args.signoff}/signoff.html and signoff.json", file=out)
    return 0
