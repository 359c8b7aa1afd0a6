"""``taos ascent`` (fly an ascent with the nonlinear TVC, friction laws overlaid) and
``taos montecarlo`` (dispersed campaigns of the flight LCO on Dask)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from taos.errors import InputError
from taos.results import atomic_write, write_json


def _out_folder(path: str, names: list[str]) -> Path:
    """An output folder receiving ``names``: refused if it is a file or if one of the names
    exists already (taos replaces no file it did not write in this run)."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", "a folder (or a new path)", got=f"{out} (a file)")
    clash = [n for n in names if (out / n).exists()]
    if clash:
        raise InputError("command line", "--out", "a folder where the run's file names are free", got=f"{out / clash[0]} exists")
    return out


#: the shipped non-SLS ascent that ``taos ascent --template`` writes (docs/reference/flight_files.md)
TEMPLATE = "generic_upper_ascent"


def write_template(out: str) -> Path:
    """Write the ascent template (the shipped ``models/flight/generic_upper_ascent.toml``, whose
    ``flight`` and ``tvc_model`` references still resolve from a copy elsewhere by the one rule
    of file references) to ``out``; an existing file is refused (nothing written)."""
    from taos.shipped import models_dir

    p = Path(out)
    if p.suffix != ".toml":
        raise InputError("command line", "--template", "a new .toml file name", got=repr(out))
    if p.exists():
        raise InputError("command line", "--template", "a new file (taos replaces no file it did not write)",
                         got=f"{p} exists")
    if not p.parent.is_dir():
        raise InputError("command line", "--template", "a file in an existing folder", got=str(p))
    text = (models_dir() / "flight" / f"{TEMPLATE}.toml").read_text(encoding="utf-8")
    head = ("# Template written by `taos ascent --template`: the shipped generic upper-stage ascent\n"
            "# (models/flight/generic_upper_ascent.toml). Edit every value for your vehicle; the keys,\n"
            "# units and frames are in docs/reference/flight_files.md. `flight` and `tvc_model` name the\n"
            "# shipped generic stage and engine until you point them at your own files.\n")
    atomic_write(p, lambda q: q.write_text(head + text, encoding="utf-8"))
    return p


def cmd_ascent(args) -> int:
    from taos.flight.ascent import load_ascent
    from taos.flight.ascent_sim import fly_ascent, run_file
    from taos.model import load_model
    from taos.units import to_si

    if args.template is not None:
        if args.ascent is not None or args.out is not None:
            raise InputError("command line", "--template", "no ascent file and no --out with --template",
                             got=f"{args.ascent or ''} {args.out or ''}".strip())
        print(f"ascent template written to {write_template(args.template)}")
        return 0
    if args.ascent is None or args.out is None:
        raise InputError("command line", "ascent", "an ascent file and --out (or --template OUT.toml)",
                         got="ascent" if args.ascent else "no ascent file")
    ascent = load_ascent(args.ascent)
    laws = [s.strip() for s in args.friction.split(",")] if args.friction is not None else [None]
    if args.friction is not None and not all(laws):
        raise InputError("command line", "--friction", "friction law names separated by single commas, like "
                         "dahl,lugre", got=repr(args.friction))
    if len(laws) > 6:
        raise InputError("command line", "--friction", "at most six friction laws", got=args.friction)
    tvc = args.model or ascent.tvc_model
    if not tvc:
        raise InputError(ascent.source, "tvc_model", "a TVC model (here or --model)", got="none")
    start, end = args.start, ascent.end_time_s if args.end is None else args.end
    if not (0.0 <= start < end <= ascent.end_time_s):
        raise InputError("command line", "--end", f"0 <= start < end <= {ascent.end_time_s:g} s",
                         got=f"start {start:g}, end {end:g}")
    if not 1e-5 <= args.dt <= 2e-3:
        raise InputError("command line", "--dt", "an RK4 step from 1e-5 to 2e-3 s", got=repr(args.dt))
    axes = ("pitch", "yaw") if args.axis == "both" else (args.axis,)
    # -- the models: one per friction law, then the reference without friction (law none)
    models = []
    k = (to_si(args.load_stiffness, "stiffness", source="command line", field="--load-stiffness", positive=True)
         if args.load_stiffness else None)
    for law in laws + ["none"]:
        m = load_model(tvc, friction=law)
        # a model variant (taos.variants): the file's load-path damping ratio kept
        models.append(m.with_values({"structure.load_stiffness": k}) if k is not None else m)
    reference = models.pop()
    # --
    out = _out_folder(args.out, [run_file(m.friction.name) for m in models] + ["summary.json", "ascent.png"])
    study = fly_ascent(ascent, models, reference=reference, avionics=args.avionics, axes=axes, start_s=start,
                       end_s=end, dt_s=args.dt, seed=args.seed, progress=args.progress,
                       friction_follows_thrust=args.friction_follows_thrust)
    summary = study.summary()
    text = json.dumps(summary, indent=1, allow_nan=False) + "\n"  # checked before anything is written
    out.mkdir(parents=True, exist_ok=True)
    for h in study.runs:
        h.to_hdf5(out / run_file(h.friction_model))
    from taos.plotting import save
    from taos.plotting.ascent import plot_study
    save(plot_study(study), out / "ascent.png")
    atomic_write(out / "summary.json", lambda p: p.write_text(text))
    if args.json:
        write_json(args.json, summary)
    else:
        for r in summary["runs"]:
            for w in r["windows"]:
                if w["kind"] == "quiescent":
                    verdict = (f"limit cycle {w['amplitude_deg']:.3f} deg command at {w['frequency_hz']:.3f} Hz"
                               if w["lco"] else "no sustained oscillation")
                    print(f"{r['friction_model']:>17s} {w['axis']:>5s} {w['start_s']:6.0f}-{w['end_s']:4.0f} s: {verdict}")
        print(f"ascent runs written to {out}")
    return 0


def scheduler_address(text: str, flag: str = "--scheduler") -> str:
    """A Dask scheduler address as Dask accepts it: ``tcp://host:port``, ``tls://host:port``,
    ``host:port`` (tcp), IPv6 in brackets (``tcp://[::1]:8786``); the port 1 to 65535 (default
    8786). ``inproc://`` (an address inside one process) and other protocols are refused."""
    from distributed.comm.addressing import parse_address, parse_host_port

    want = ("a Dask scheduler address like tcp://10.0.0.5:8786, tls://host:8786, host:8786 or tcp://[::1]:8786 "
            "(port 1 to 65535)")
    text = text.strip() if isinstance(text, str) else ""
    try:
        scheme, loc = parse_address(text, strict=False)
        if scheme not in ("tcp", "tls"):
            raise ValueError(f"{scheme}:// does not reach a scheduler in another process: use tcp:// or tls://")
        host, port = parse_host_port(loc, default_port=8786)
        if not host or re.search(r"[\s/]", host) or not 1 <= int(port) <= 65535:
            raise ValueError("a host and a port 1 to 65535")
    except (ValueError, TypeError) as e:
        raise InputError("command line", flag, want, got=f"{text!r} ({str(e)[:160]})") from None
    return f"{scheme}://{'[' + host + ']' if ':' in host else host}:{port}"


def scheduler_from_file(path: str) -> str:
    """The address in a Dask scheduler file (the JSON ``dask scheduler --scheduler-file`` and
    dask-jobqueue write), checked as :func:`scheduler_address` checks one."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise InputError(path, "(file)", "a Dask scheduler file (JSON with an \"address\")",
                         got=type(e).__name__ if not isinstance(e, OSError) else (e.strerror or "unreadable")) from None
    addr = doc.get("address") if isinstance(doc, dict) else None
    if not isinstance(addr, str):
        raise InputError(path, "address", "the scheduler's address (a string)", got=repr(addr)[:60])
    return scheduler_address(addr, flag=f"--scheduler-file {path}: address")


def cluster_address(args) -> str | None:
    """The scheduler named by ``--scheduler`` or ``--scheduler-file`` (None: local workers or
    this process), refusing more than one of ``--workers``, ``--scheduler``, ``--scheduler-file``
    (taos montecarlo, taos sweep, taos lco --sweep --out)."""
    given = [f for f, v in (("--workers", args.workers), ("--scheduler", args.scheduler),
                            ("--scheduler-file", args.scheduler_file)) if v is not None]
    if len(given) > 1:
        raise InputError("command line", given[1], "one of --workers, --scheduler, --scheduler-file",
                         got=" and ".join(given))
    if args.scheduler is not None:
        return scheduler_address(args.scheduler)
    if args.scheduler_file is not None:
        return scheduler_from_file(args.scheduler_file)
    return None


def command_line(words, options) -> str:
    """``taos WORDS OPTIONS --resume`` as one shell line: ``options`` is (flag, value) pairs; a
    value None or False is left out, True is the bare flag, a list repeats the flag."""
    import shlex
    parts = [str(w) for w in words]
    for flag, v in options:
        if v is None or v is False:
            continue
        for x in (v if isinstance(v, (list, tuple)) else [v]):
            parts += [flag] if x is True else [flag, str(x)]
    return shlex.join(parts + ["--resume"])


def resume_command(args) -> str:
    """The command that continues this campaign (``--resume`` on the same folder)."""
    return command_line(["taos", "montecarlo", args.campaign],
                        [("--runs", args.runs), ("--case", args.case), ("--friction", args.friction),
                         ("--sensitivity", args.sensitivity), ("--scheduler", args.scheduler),
                         ("--scheduler-file", args.scheduler_file), ("--workers", args.workers), ("--out", args.out)])


def stored_runs(spath: Path, groups=(None, "nominal")) -> tuple[int, int] | None:
    """(runs stored, runs) of the store ``spath`` over ``groups``, None without a readable store."""
    from taos.montecarlo import store
    sts = [store.status(spath, g) for g in groups]
    if any(st is None for st in sts):
        return None
    return sum(int((st != store.STATUS["pending"]).sum()) for st in sts), sum(len(st) for st in sts)


class KeptStore:
    """The campaign store a command begins or continues in ``out`` (``manifest`` and ``store``
    names in it), kept on purpose when the command stops: after a signal or a failed cluster it
    says how many ``noun`` (runs, points) are stored and the command that continues
    (``resume``). The same words for every campaign command (taos montecarlo, taos sweep,
    taos lco --sweep --out)."""

    def __init__(self, out, manifest: str, store: str, noun: str, resume: str, resuming: bool,
                 groups=(None,)):
        self.out, self.spath, self.noun, self.resume, self.groups = Path(out), Path(out) / store, noun, resume, groups
        self.mpath = self.out / manifest
        # a manifest there before this run belongs to another run unless this one continues it
        self.ours = resuming or not self.mpath.exists()

    def describe(self) -> str | None:
        """What is kept and how to continue; None when this run left no campaign in ``out``."""
        if not (self.ours and self.mpath.is_file()):
            return None
        n = stored_runs(self.spath, self.groups)
        held = f"{n[0]} of {n[1]} {self.noun} stored" if n is not None else f"none of the {self.noun} stored yet"
        return f"{held} in {self.spath} (kept); continue with: {self.resume}"

    def watch(self) -> None:
        """From here on a signal's line says what is kept (:func:`taos.errors.on_signal_kept`)."""
        from taos.errors import on_signal_kept
        on_signal_kept(self.describe)

    def stopped(self, e) -> InputError:
        """A :class:`taos.montecarlo.engine.CampaignStopped` as one line with the kept store."""
        return InputError(e.source, e.field, e.expected,
                          got=f"{e.reason}; {self.describe() or f'no {self.noun} stored (nothing kept)'}")


def cmd_montecarlo(args) -> int:
    from taos.montecarlo import load_campaign, run_campaign
    from taos.montecarlo.engine import CampaignStopped
    from taos.montecarlo.executor import MANIFEST, STORE

    scheduler = cluster_address(args)
    if args.workers is not None and args.workers < 1:
        raise InputError("command line", "--workers", "1 or more workers", got=str(args.workers))
    if args.resume:   # before any work: a resume with nothing to continue would start afresh silently
        if not (Path(args.out) / MANIFEST).is_file():
            raise InputError("command line", "--resume", f"a --out folder holding a campaign ({MANIFEST}) to continue",
                             got=f"none in {args.out}")
    c = load_campaign(args.campaign)
    kept = KeptStore(args.out, MANIFEST, STORE, "runs", resume_command(args), args.resume, groups=(None, "nominal"))
    kept.watch()   # a signal from here on: the stored runs and the resume line
    try:
        res = run_campaign(c, args.out, runs=args.runs, case=args.case, friction=args.friction,
                           workers=args.workers, scheduler=scheduler, resume=args.resume,
                           progress=not args.no_progress, design=args.sensitivity or "montecarlo", batch=args.batch,
                           connect_timeout_s=args.connect_timeout)
    except CampaignStopped as e:
        raise kept.stopped(e) from None
    from taos.plotting import save
    from taos.plotting.ascent import plot_campaign
    save(plot_campaign(res), Path(args.out) / "montecarlo.png")
    summary = json.loads((Path(args.out) / "summary.json").read_text())
    if args.json:
        write_json(args.json, summary)
        return 0
    s = res.summary
    amp = s["amplitude_deg_lco_runs"]
    print(f"{c.name}, case {s['case']}: {s['headline']}"
          + (f"; command amplitude median {amp['p50']:.3f} deg (5-95 %: {amp['p5']:.3f}-{amp['p95']:.3f})"
             if amp else ""))
    if s["runs_failed"] or s["runs_diverged"]:
        print("(seeds and reasons of the runs without a verdict in summary.json and the store)")
    for w in s["warnings"] + ((summary.get("sensitivity") or {}).get("warnings") or []):
        print(f"warning: {w}")
    sens = summary.get("sensitivity")
    if sens and sens.get("indices"):
        top = sens["indices"][0]
        val = (f"ST {top['ST']:.2f} +- {top['ST_conf']:.2f}, S1 {top['S1']:.2f} +- {top['S1_conf']:.2f}"
               if sens["method"] == "sobol" else f"mu* {top['mu_star']:.3g} +- {top['mu_star_conf']:.2g} deg")
        print(f"{sens['method']}: strongest driver of the amplitude: {top['parameter']} ({val})")
    elif sens:
        print(f"{sens['method']}: no indices ({sens['error']})")
    elif s["sensitivity_of_amplitude"]:
        top = s["sensitivity_of_amplitude"][0]
        print(f"strongest driver of the amplitude: {top['parameter']} (Spearman {top['spearman_rho']:+.2f}, "
              f"Holm p {top['p_holm']:.2g})")
    print(f"campaign written to {args.out}")
    return 0


def _positive_int(text: str) -> int:
    try:
        v = int(text)
    except ValueError:
        raise InputError("command line", "--runs/--workers", "a whole number", got=repr(text)) from None
    return v


def add_parsers(sub) -> None:
    p = sub.add_parser("ascent", help="fly an ascent (boosters, PTIs, winds) with the nonlinear TVC")
    p.add_argument("ascent", nargs="?", help="ascent file or shipped name, e.g. ascent (models/flight/ascent.toml) "
                   "or generic_upper_ascent (a non-SLS two-engine upper stage)")
    p.add_argument("--template", metavar="OUT.toml", help="write an ascent file template (the shipped generic "
                   "upper stage, every key commented; docs/reference/flight_files.md) and stop")
    p.add_argument("--model", help="TVC model (default: the ascent file's tvc_model)")
    p.add_argument("--friction", help="friction law(s), comma-separated, overlaid (e.g. coulomb-switching,dahl,lugre)")
    p.add_argument("--load-stiffness", help="override the load stiffness, e.g. '205000 lbf/in' (stiff structure)")
    p.add_argument("--axis", choices=("pitch", "yaw", "both"), default="yaw", help="axes flown (default yaw)")
    p.add_argument("--avionics", choices=("bounding", "model"), default="bounding",
                   help="bounding: the paper's -1 dB gain (default); model: the file's quantisation")
    p.add_argument("--start", type=float, default=0.0, help="start of the flown segment [s] (default 0)")
    p.add_argument("--end", type=float, help="end of the flown segment [s] (default the trajectory's end)")
    p.add_argument("--dt", type=float, default=2e-4, help="RK4 step [s] (default 2e-4: the switching Coulomb stick band needs it)")
    p.add_argument("--seed", type=int, default=0, help="turbulence seed (default 0)")
    p.add_argument("--friction-follows-thrust", action="store_true", help="the friction level follows the "
                   "trajectory's core thrust per engine, T_c = mu N(t) r_b (default: the model's level throughout)")
    p.add_argument("--out", help="output folder: ascent_<law>.h5, ascent.png, summary.json (required to fly)")
    p.add_argument("--json", metavar="PATH", help="write the window analysis here ('-' for standard output)")
    p.add_argument("--progress", action="store_true", help="show a progress bar")
    p.set_defaults(func=cmd_ascent)

    p = sub.add_parser("montecarlo", help="dispersed campaign or global sensitivity of the flight LCO on Dask (resumable)")
    p.add_argument("campaign", help="campaign file or shipped name, e.g. post_separation (models/montecarlo/)")
    p.add_argument("--runs", type=_positive_int, required=True, help="number of dispersed runs")
    p.add_argument("--case", help="named case of the campaign (default: its default_case)")
    p.add_argument("--friction", help="swap the friction law, keeping the torque levels")
    p.add_argument("--workers", type=_positive_int, help="local Dask workers (default 2)")
    p.add_argument("--scheduler", help="an existing Dask scheduler: tcp://HOST:PORT, tls://HOST:PORT, HOST:PORT or "
                   "tcp://[IPv6]:PORT")
    p.add_argument("--scheduler-file", metavar="PATH", help="the scheduler's address from a Dask scheduler file "
                   "(dask scheduler --scheduler-file PATH; dask-jobqueue)")
    p.add_argument("--out", required=True, help="campaign folder (runs are stored as they arrive)")
    p.add_argument("--resume", action="store_true", help="continue the campaign stored in --out")
    p.add_argument("--json", metavar="PATH", help="write the summary here ('-' for standard output)")
    p.add_argument("--sensitivity", choices=("sobol", "morris"),
                   help="a global sensitivity design instead of the dispersed runs: sobol (Saltelli, --runs N "
                        "base samples, a power of two: N (k + 2) runs) or morris (--runs N trajectories)")
    p.add_argument("--batch", type=_positive_int, help="runs per Dask task (default: about 10 s of work, 50-1000)")
    p.add_argument("--connect-timeout", type=float, default=20.0,
                   help="seconds to wait for --scheduler to answer (default 20)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_montecarlo)

