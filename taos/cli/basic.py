"""``taos info``, ``taos freqresp`` and ``taos simulate``: argument parsing over the library
(``taos info``: :func:`taos.report.summary.model_summary`)."""

from __future__ import annotations

import math
import sys

from typing import TYPE_CHECKING

from taos.cli import add_friction_option
from taos.errors import InputError
from taos.planar.envelope import ENGINES
from taos.report.summary import model_summary
from taos.results import write_json
from taos.units import parse_float_list

if TYPE_CHECKING:  # the model layer is imported when a command runs, not for --help
    from taos.model import TvcModel

AXES = ("pitch", "yaw")


def model_from_args(args) -> TvcModel:
    from taos.model import load_model

    return load_model(args.model, friction=getattr(args, "friction", None))


def taos_from_args(args, model: TvcModel):
    """The 3-D model of ``model`` when ``--engine taos`` (else None), built right after loading:
    every 3-D input check (geometry, stiffness file, derived keys) runs before any simulation,
    and the 3-D model carries the same friction (``--friction`` included) as ``model``."""
    if getattr(args, "engine", "simplex") != "taos":
        return None
    from taos.taos3d import taos_model

    return taos_model(model)


def servo_line(ax: str, sv: dict) -> str:
    """``taos info``'s servo lines of one axis (:mod:`taos.report.servo`)."""
    def loop(d):
        gm = "no phase crossover" if d["gain_margin_db"] is None else f"{d['gain_margin_db']:.1f} dB"
        pm = "no gain crossover" if d["phase_margin_deg"] is None else f"{d['phase_margin_deg']:.1f} deg"
        return f"{gm} / {pm}"
    lab, lm = sv["laboratory"], sv["load_mode"]
    bw = "none below 50 Hz" if lab["engine_bandwidth_3db_hz"] is None else f"{lab['engine_bandwidth_3db_hz']:.2f} Hz"
    mode = "none" if lm["freq_hz"] is None else f"{lm['freq_hz']:.2f} Hz, zeta {lm['damping_ratio']:.3f}"
    return (f"  {ax} servo        loop margins {loop(sv['position_loop'])} (lab {loop(lab)}); lab peak "
            f"{lab['engine_peaking_db']:+.2f} dB, -3 dB {bw}; load mode {mode}")


def cmd_info(args) -> int:
    model = model_from_args(args)
    d = model_summary(model, steps=args.steps)
    if args.json:
        from taos.results import output_provenance
        d["provenance"] = output_provenance([model])
        write_json(args.json, d)
    else:
        print(f"{d['name']}  ({d['model_file']})")
        print(f"  load resonance    {d['load_resonance_hz']:.3f} Hz (pitch), notch {d['notch_frequency_hz']:.3f} Hz")
        print(f"  breakaway defl.   {d['breakaway_deflection_deg']:.4f} deg")
        print(f"  oil column        {d['oil_column_stiffness_N_per_m']:.4g} N/m")
        print(f"  friction          {model.friction.name}, {model.friction.coulomb_torque_Nm:.5g} N m")
        print(f"  avionics LSB      {d['avionics_lsb_deg']:.5f} deg")
        for ax, fm in d["figures_of_merit"].items():
            e, st = fm["engine"], fm.get("step")
            bw = "none below 50 Hz" if e["bandwidth_3db_hz"] is None else f"{e['bandwidth_3db_hz']:.2f} Hz"
            p90 = "none" if e["phase_90_hz"] is None else f"{e['phase_90_hz']:.2f} Hz"
            print(f"  {ax} engine       -3 dB {bw}, -90 deg {p90}, peak {e['peak_gain_db']:+.2f} dB at "
                  f"{e['peak_freq_hz']:.2f} Hz (linear, relative to low frequency)")
            print(f"  {ax} notch        {fm['notch_hz']:.3f} Hz, load resonance {fm['load_resonance_hz']:.3f} Hz")
            print(servo_line(ax, d["servo"][ax]))
            if st:
                rt = "n/a" if st["rise_time_s"] is None else f"{1e3 * st['rise_time_s']:.1f} ms"
                ov = "n/a" if st["overshoot_pct"] is None else f"{st['overshoot_pct']:.1f} %"
                print(f"  {ax} step {st['step_amplitude_deg']:g} deg  rise (10-90 %) {rt}, overshoot {ov}, threshold "
                      f"{st['threshold_deg']:.4f} deg, hysteresis {st['hysteresis_deg']:.4f} deg, null shift "
                      f"{st['null_shift_deg']:.4f} deg ({st['friction_model']})")
    return 0


def _check_freqresp_flags(args) -> None:
    """Refuse flags that contradict each other (one would be silently ignored), naming one."""
    if args.linear and args.amplitude_deg is not None:
        raise InputError("command line", "--amplitude-deg", "no amplitude with --linear (the linear response "
                         "has none)", got=repr(args.amplitude_deg))
    if args.linear and args.friction:
        raise InputError("command line", "--friction", "no friction law with --linear (the linear response has no "
                         "friction)", got=repr(args.friction))
    if args.steady is not None and args.amplitude_deg is None:
        raise InputError("command line", "--steady", "--amplitude-deg too (--steady chooses how a sine dwell "
                         "settles; the linear response has no dwell)", got=args.steady)
    if args.cross and args.engine != "taos":
        raise InputError("command line", "--cross", "--engine taos (the planar engine has no cross-axis "
                         "response)", got=f"--engine {args.engine}")
    args.steady = args.steady or "settle"


def cmd_freqresp(args) -> int:
    import numpy as np

    from taos.planar.freqresp import family_to_dict, linear_freqresp, sine_dwell_family

    from taos import bounds as limits
    from taos.planar import envelope as run_checks
    from taos.results import check_output_file

    _check_freqresp_flags(args)
    freqs = parse_float_list(args.freq_hz, "--freq-hz")
    limits.check_response_frequencies(freqs)
    for opt, suf in (("json", ()), ("plot", (".png", ".svg"))):
        if getattr(args, opt) not in (None, "-"):
            check_output_file(getattr(args, opt), f"--{opt}", suf)
    model = model_from_args(args)
    tm = taos_from_args(args, model)
    amps_rad: list[float] = []
    if args.amplitude_deg is not None and not args.linear:
        amps_rad = [math.radians(a) for a in parse_float_list(args.amplitude_deg, "--amplitude-deg")]
        for a in amps_rad:
            limits.check_amplitude(a, model, "--amplitude-deg")
        if args.engine == "taos" and args.steady == "shoot":
            raise InputError("command line", "--steady", "settle with --engine taos (shooting is for the "
                             "simplex engine)", got="shoot")
        run_checks.check_linear_stability(model, (args.axis,), allow=args.allow_unstable)
        run_checks.check_dwell(model, freqs, axis=args.axis, n_amplitudes=len(amps_rad))
    if tm is not None:
        from taos.taos3d import taos_freqresp, taos_freqresp_family
        fam = (taos_freqresp_family(tm, freqs, amps_rad, args.axis, cross=args.cross) if amps_rad
               else [taos_freqresp(tm, freqs, None, args.axis, cross=args.cross)])
    elif not amps_rad:
        fam = [linear_freqresp(model, freqs, args.axis)]
    else:   # every amplitude x frequency dwell in one parallel call
        fam = sine_dwell_family(model, freqs, amps_rad, args.axis, method=args.steady)
    fr = fam[0]
    d = family_to_dict(fam) if len(fam) > 1 else fr.to_dict()
    from taos.results import output_provenance
    d["provenance"].update(output_provenance([model]))   # the solver's own account (what ran) stays as it is
    if not args.cross:
        from taos.report.merit import frequency_merit
        # figures of the model that answered: the 3-D model's own linearisation with --engine taos
        d["figures_of_merit"] = frequency_merit(model, args.axis, taos=tm).to_dict()
    if args.json:
        write_json(args.json, d)
    else:
        print(f"{'amp_deg':>8} {'freq_hz':>9} {'piston dB':>10} {'piston deg':>11} {'engine dB':>10} "
              f"{'engine deg':>11}   (piston x_p/(R theta_c); phase continuous from low frequency)")
        for r in (f.to_dict() for f in fam):
            amp = "linear" if r["amplitude_deg"] is None else f"{r['amplitude_deg']:.4g}"
            for i, f in enumerate(r["freq_hz"]):
                eg, ep = r["engine"]["gain_db"][i], r["engine"]["phase_deg"][i]
                eng = f"{eg:10.3f} {ep:11.2f}" if eg is not None else f"{'engine held':>22s}"
                print(f"{amp:>8} {f:9.4g} {r['piston']['gain_db'][i]:10.3f} {r['piston']['phase_deg'][i]:11.2f} {eng}")
        if d.get("note"):
            print(d["note"])
    if args.plot:
        from taos.plotting import save
        from taos.plotting import bode
        from taos.plotting.spec import bode_axes
        if args.engine == "taos":
            fig = bode.plot_freqresp(fam, resonance_hz=model.load_resonance_hz(args.axis))
        else:   # the linear response as a dense curve, not straight lines between the listed points
            fd = np.logspace(math.log10(min(freqs) / 1.5), math.log10(max(freqs) * 1.5), 400)
            dense = linear_freqresp(model, fd, args.axis)
            from taos.planar.simplex import load_resonance_from_notch   # the one notch finder every command uses
            fig = bode.plot_freqresp([dense] + ([] if fr.amplitude_rad is None else fam),
                                     resonance_hz=model.load_resonance_hz(args.axis),
                                     notch_hz=load_resonance_from_notch(model, args.axis))
            if fr.amplitude_rad is None:
                bode.draw_response(bode_axes(fig), fr, 1.0, color="k", label="listed points", gid="points",
                                   marker="o", linestyle="none", ref=dense)
        save(fig, args.plot)
    return 0


def cmd_simulate(args) -> int:
    from taos.planar import envelope as run_checks
    from taos.identify.replay import load_command_source
    from taos.results import check_output_file, input_provenance
    from taos.planar.simulate import simulate

    check_output_file(args.out, "--out")
    if args.engine == "taos" and args.integrator != "rk4":
        raise InputError("command line", "--integrator", "rk4 with --engine taos (the exponential integrator is the "
                         "simplex engine's)", got=args.integrator)
    model = model_from_args(args)
    tm = taos_from_args(args, model)
    profile = load_command_source(args.profile)
    dt = run_checks.default_dt_s(args.engine, time_run=True) if args.dt is None else args.dt
    run_checks.check_run(model, profile, dt, pressure_limit=args.engine != "taos")
    run_checks.check_linear_stability(model, allow=args.allow_unstable)
    if tm is not None:
        from taos.taos3d import simulate_taos
        th = simulate_taos(tm, profile, dt_s=dt)
    else:
        th = simulate(model, profile, dt_s=dt, progress=sys.stderr.isatty(), integrator=args.integrator)
    if not args.allow_unstable:
        run_checks.check_envelope(th, model)
    th.provenance.update(input_provenance(args.profile, "profile", th.provenance))
    th.to_hdf5(args.out)
    print(f"wrote {args.out} ({th.t_s.size} samples, {', '.join(th.axes)})")
    if str(args.profile).lower().endswith((".csv", ".txt", ".h5", ".hdf5")):   # a replayed record
        from taos.identify.data import load_test_data
        from taos.identify.replay import compare_replay
        for r in compare_replay(load_test_data(args.profile), th):
            d = r.to_dict()
            eng = ("" if d["engine_rms_error_deg"] is None else
                   f", engine {d['engine_rms_error_deg']:.4f} deg ({100 * d['engine_relative_rms_error']:.1f} %)")
            print(f"replay {r.axis}: model - test RMS piston {d['piston_rms_error_in']:.5f} in "
                  f"({100 * d['piston_relative_rms_error']:.1f} %){eng}")
    return 0


def add_parsers(sub) -> None:
    def common(p, friction=True):
        p.add_argument("model", help="model file (TOML), e.g. models/rs25_ambient.toml")
        if friction:
            add_friction_option(p)
        p.add_argument("--json", metavar="PATH", help="write JSON here ('-' for standard output)")

    p = sub.add_parser("info", help="parameters in SI and derived figures")
    common(p)
    p.add_argument("--steps", action="store_true", help="also the step, threshold and hysteresis figures of merit "
                   "(simulated on the nonlinear model; without it info is linear analysis only and starts in a blink)")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("freqresp", help="command -> piston and engine frequency response")
    common(p)
    p.add_argument("--freq-hz", required=True, help="comma-separated frequencies, e.g. 0.1,0.5,1,2,5")
    p.add_argument("--amplitude-deg", help="command amplitude(s) for the sine-dwell (nonlinear) response; a "
                   "comma-separated list gives the whole N(A, w) map in one call (JSON: amplitude x frequency rows)")
    p.add_argument("--steady", choices=("settle", "shoot"), default=None,
                   help="with --amplitude-deg: how each dwell reaches its periodic orbit: settle (integrate from "
                   "rest through the settling time, default) or shoot (periodic steady state by shooting, simplex engine)")
    p.add_argument("--linear", action="store_true", help="exact linear response (no friction, unity avionics)")
    p.add_argument("--axis", choices=AXES, default="pitch")
    p.add_argument("--engine", choices=ENGINES, default="simplex",
                   help="simplex (planar) or taos (3-D, two actuators, compliant two-half gimbal)")
    p.add_argument("--cross", action="store_true", help="with --engine taos: the other axis' response")
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="also save a Bode plot")
    p.add_argument("--allow-unstable", action="store_true", help="run the sine dwell even if the linear model is unstable")
    p.set_defaults(func=cmd_freqresp)

    p = sub.add_parser("simulate", help="time history of a command profile, to HDF5")
    p.add_argument("model")
    p.add_argument("--profile", required=True, help="profile file (TOML), e.g. models/profiles/greenrun_two_axis.toml, "
                   "or a measured record (.csv/.h5, e.g. models/data/greenrun_hotfire_synthetic.csv) whose commands "
                   "are replayed and compared with its piston and engine angles")
    p.add_argument("--out", required=True, help="HDF5 file to write")
    p.add_argument("--engine", choices=ENGINES, default="simplex", help="simplex or taos (3-D)")
    add_friction_option(p, "swap the friction law")
    p.add_argument("--dt", type=float, default=None, help="integration step [s] (default: the engine's own, 2e-4 s "
                   "simplex, 8e-4 s taos)")
    p.add_argument("--integrator", choices=("rk4", "exp"), default="rk4",
                   help="simplex engine: rk4 (fixed step --dt, default) or exp (exponential ETDRK4: the linear block "
                   "and the quantised command exact, the step set by the friction loop and the records, the command "
                   "sampled every --dt; falls back to rk4 where the limits are reached, said in the provenance)")
    p.add_argument("--allow-unstable", action="store_true",
                   help="run a model whose linear block is unstable, and do not stop at the envelope")
    p.set_defaults(func=cmd_simulate)
