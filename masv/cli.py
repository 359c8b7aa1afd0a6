"""``masv`` command line: modes, 8x8 frequency responses, coupling and loop margins.

    masv modes CONFIG [--factor F] [--json PATH]     (modes in the file's [band], or bandwidth x/÷ F)
    masv freqresp CONFIG --freq-hz 0.5,1,2,5 [--json PATH] [--plot GRID.png]
    masv coupling CONFIG [--reference CONFIG] [--json PATH] [--plot MATRIX.png]
                                                      (with a reference: the same figures for it)
    masv tvse CONFIG [--json PATH] [--plot BODE.png]   TVSE loops (paper sec. 3.3) and their margins
    masv simulate CONFIG --profile P --out RUN.h5 [--actuator-profile NAME=P ...] [--dt S]
                  [--record-every N] [--duration S] [--friction LAW] [--json PATH]
                                                      every engine's nonlinear TVC coupled through
                                                      the modes, in the time domain (masv.timedomain)

Bad input exits with status 2 and one line naming the file, the field and what was expected.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from taos.units import parse_float_list
from taos.errors import InputError
from taos.results import write_json

from . import analysis as an
from .config import load_config
from .system import build_system


def _system(args):
    return build_system(load_config(args.config))


def _prov(cfg) -> dict:
    from masv.provenance import config_provenance

    return config_provenance(cfg)


#: ``masv modes`` lists every mode up to this many (beyond, only the modes in the band)
MODES_TABLE_MAX = 60


def cmd_modes(args) -> int:
    if args.factor is not None and not (args.factor > 1 and math.isfinite(args.factor)):
        raise InputError("command line", "--factor", "a number above 1", got=repr(args.factor))
    s = _system(args)
    mp = an.modes_in_band(s) if args.factor is None else an.modes_near_bandwidth(s, args.factor)
    st = s.config.structure
    d = {"n_modes": st.n_modes, "freq_hz": st.freq_hz.tolist(), "damping_ratio": st.damping_ratio.tolist(),
         "near_bandwidth": mp.to_dict(), "provenance": _prov(s.config)}
    if args.json:
        write_json(args.json, d)
    else:
        print(f"{st.n_modes} modes ({st.source}); actuator bandwidth {mp.bandwidth_hz:.2f} Hz; "
              f"{mp.freq_hz.size} modes in {mp.band_hz[0]:.2f}-{mp.band_hz[1]:.2f} Hz ({mp.band_source})")
        # every mode of the structure (up to MODES_TABLE_MAX; beyond, the in-band ones), in-band marked
        table = (an.modes_in_band(s, (0.0, math.inf), bandwidth_hz=mp.bandwidth_hz)
                 if st.n_modes <= MODES_TABLE_MAX else mp)
        inband = set(int(i) for i in mp.mode_index)
        print(f"{'mode':>5} {'freq_hz':>9} {'zeta':>7} {'max K_L phi^2/w^2':>18} {'in band':>8}  strongest actuator")
        for i in range(table.freq_hz.size):
            k = int(table.compliance_ratio[i].argmax())
            j = int(table.mode_index[i])
            print(f"{j + 1:5d} {table.freq_hz[i]:9.3f} {table.damping_ratio[i]:7.4f} "
                  f"{table.compliance_ratio[i, k]:18.4g} {'yes' if j in inband else 'no':>8}  {table.actuators[k]}")
    return 0


def cmd_freqresp(args) -> int:
    freqs = parse_float_list(args.freq_hz, "--freq-hz")
    s = _system(args)
    fr = an.frequency_response(s, freqs)
    d = fr.to_dict()
    d["provenance"].update(_prov(s.config))
    if args.json:
        write_json(args.json, d)
    else:
        print(f"{'freq_hz':>9} " + " ".join(f"{a[-12:]:>13}" for a in fr.actuators) + "   (own piston gain dB)")
        for i, f in enumerate(fr.freq_hz):
            print(f"{f:9.4g} " + " ".join(f"{d['piston']['gain_db'][k][k][i]:13.3f}" for k in range(len(fr.actuators))))
    if args.plot:
        from .plotting import plot_gain_grid, save
        save(plot_gain_grid(fr, kind=args.kind), args.plot)
    return 0


def _coupling_summary(s) -> dict:
    """Stability, worst loop margins and engine-to-engine coupling of one system (the figures
    ``masv coupling`` compares with a reference configuration)."""
    c = an.coupling(s)
    eig = an.closed_loop_eigenvalues(s)
    m = an.structure_effect(s)
    return {"config_file": s.config.source, "n_modes": s.config.structure.n_modes, "stable": eig.stable,
            "max_real_per_s": eig.max_real_per_s, "least_damped": eig.least_damped(2),
            "worst_phase_margin_deg": m["worst_phase_margin_deg"],
            "worst_gain_margin_db": None if math.isinf(m["worst_gain_margin_db"]) else m["worst_gain_margin_db"],
            "engine_to_engine": {k: c.engine_to_engine(k) for k in ("engine", "piston")}}


def _e2e_line(v: dict | None) -> str:
    if not v:
        return "none (one engine)"
    if v["cross_db"] <= -300:
        return f"none (rigid structure); direct {v['direct_db']:+.1f} dB"
    return (f"{v['cross_db']:+.1f} dB at {v['cross_hz']:.2f} Hz ({v['command']} -> {v['response']}), "
            f"{v['below_direct_db']:.1f} dB below the direct response (peak {v['direct_db']:+.1f} dB)")


def cmd_coupling(args) -> int:
    s = _system(args)
    c = an.coupling(s)
    eig = an.closed_loop_eigenvalues(s)
    d = {"coupling": c.to_dict(), "notches": an.notch_frequencies(s), "closed_loop": eig.to_dict(),
         "margins": an.structure_effect(s), "provenance": _prov(s.config)}
    ref_path = args.reference if args.reference else s.config.reference
    if ref_path:
        ref = build_system(load_config(ref_path))
        d["reference"] = _coupling_summary(ref)
        d["this"] = _coupling_summary(s)
    if args.json:
        write_json(args.json, d)
    else:
        print(f"closed loop: {'stable' if eig.stable else 'UNSTABLE'} (max Re {eig.max_real_per_s:.4g} 1/s)")
        for name, n in d["notches"].items():
            print(f"  notch {name:>18}: {n['notch_hz']:.3f} Hz (simplex {n['simplex_load_resonance_hz']:.3f} Hz)")
        for r in d["margins"]["loops"]:
            w, g = r["with_structure"], r["rigid"]
            print(f"  loop  {r['actuator']:>18}: PM {w['phase_margin_deg']:.1f} deg (rigid {g['phase_margin_deg']:.1f}), "
                  f"GM {w['gain_margin_db'] if w['gain_margin_db'] is None else round(w['gain_margin_db'], 1)} dB")
        for k in ("strongest_engine_to_engine", "strongest_axis_to_axis"):
            v = d["coupling"][k]
            if v:
                print(f"  {k}: {v['command']} -> {v['response']} {v['gain_db']:.1f} dB at {v['freq_hz']:.2f} Hz")
        lo, hi = c.band_hz
        for kind, label in (("engine", "theta_i / theta_c,j"), ("piston", "x_p,i / x_c,j")):
            ep = c.engine_pairs(kind)
            print(f"engine-to-engine, peak |{label}| over {lo:g}-{hi:g} Hz [dB] "
                  "(row response engine, column command engine; diagonal: the engine's own direct response)")
            print("  " + " " * 10 + "".join(f"{e:>10}" for e in ep["engines"]))
            for e, row in zip(ep["engines"], ep["peak_db"]):
                print(f"  {e:>10}" + "".join(f"{'-' if v <= -300 else f'{v:+.1f}':>10}" for v in row))
            print(f"  strongest ({kind}): {_e2e_line(c.engine_to_engine(kind))}")
        if ref_path:
            print(f"against the reference {ref_path}:")
            for tag, v in (("this", d["this"]), ("reference", d["reference"])):
                gm = v["worst_gain_margin_db"]
                print(f"  {tag:>9}: {v['n_modes']} modes, {'stable' if v['stable'] else 'UNSTABLE'}, worst PM "
                      f"{v['worst_phase_margin_deg']:.1f} deg, worst GM {'inf' if gm is None else f'{gm:.1f}'} dB; "
                      f"engine-to-engine (engine) {_e2e_line(v['engine_to_engine']['engine'])}")
    if args.plot:
        from .plotting import plot_coupling_matrix, save
        save(plot_coupling_matrix(c), args.plot)
    return 0


def cmd_tvse(args) -> int:
    s = _system(args)
    loops = an.tvse_loops(s)
    d = {"tvse": [lp.to_dict() for lp in loops], "provenance": _prov(s.config)}
    if args.json:
        write_json(args.json, d)
    else:
        print("TVSE loops, each broken at its engine's inertial coupling into the structure (others closed)")
        for lp in loops:
            m = lp.margin
            if not np.any(lp.loop):
                print(f"  {lp.actuator:>18}: no loop (rigid structure or no c.g. offset)")
                continue
            gm = "inf" if math.isinf(m.gain_margin_db) else f"{m.gain_margin_db:.1f}"
            pm = "inf" if math.isinf(m.phase_margin_deg) else f"{m.phase_margin_deg:.1f}"
            print(f"  {lp.actuator:>18}: peak {lp.peak_db:+.1f} dB at {lp.peak_hz:.2f} Hz; GM {gm} dB, PM {pm} deg")
    if args.plot:
        from .plotting import plot_tvse_loops, save
        save(plot_tvse_loops(loops), args.plot)
    return 0


def cmd_simulate(args) -> int:
    from taos.profiles import load_profile
    from taos.results import check_output_file

    from .timedomain import simulate

    check_output_file(args.out, "--out", suffixes=(".h5", ".hdf5"))
    cfg = load_config(args.config)
    commands = {n: None for n in cfg.actuator_names}
    if args.profile:
        p = load_profile(args.profile)
        commands = {n: p for n in cfg.actuator_names}
    for item in args.actuator_profile or []:
        name, sep, path = item.partition("=")
        if not sep or name not in commands:
            raise InputError("command line", "--actuator-profile", "NAME=PROFILE with NAME an actuator of "
                             + cfg.source + " (" + ", ".join(cfg.actuator_names) + ")", got=repr(item))
        commands[name] = load_profile(path)
    if all(v is None for v in commands.values()):
        raise InputError("command line", "--profile", "a command profile (or --actuator-profile NAME=P)")
    for opt, v in (("--dt", args.dt), ("--duration", args.duration)):
        if v is not None and not (v > 0 and math.isfinite(v)):
            raise InputError("command line", opt, "a positive number of seconds", got=repr(v))
    if args.record_every < 1:
        raise InputError("command line", "--record-every", "a whole number >= 1", got=str(args.record_every))
    kw = {} if args.dt is None else {"dt_s": args.dt}
    h = simulate(cfg, commands, record_every=args.record_every, duration_s=args.duration, friction=args.friction,
                 **kw)
    h.to_hdf5(args.out)
    d = {"out": args.out, "t_end_s": float(h.t_s[-1]), "actuators": list(h.actuators),
         "peak_engine_deg": {a: float(np.degrees(np.abs(h.engine_rad[i]).max())) for i, a in enumerate(h.actuators)},
         "peak_load_force_N": {a: float(np.abs(h.load_force_N[i]).max()) for i, a in enumerate(h.actuators)},
         "provenance": h.provenance}
    if args.json:
        write_json(args.json, d)
    else:
        s = h.provenance["solver"]
        print(f"{len(h.actuators)} actuators, {h.modal_q.shape[0]} modes, {h.t_s[-1]:.2f} s simulated in "
              f"{s['kernel_wall_s']:.2f} s ({s['real_time_factor']:.1f}x real time) -> {args.out}")
        for a in h.actuators:
            print(f"  {a:>18}: peak engine {d['peak_engine_deg'][a]:.3f} deg, peak load {d['peak_load_force_N'][a]:.4g} N")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="masv", description="MASV: four engines, eight actuators, thrust-structure modes")
    sub = ap.add_subparsers(dest="command", required=True)

    def common(p):
        p.add_argument("config", help="MASV configuration (TOML), e.g. models/masv/core_stage.toml")
        p.add_argument("--json", metavar="PATH", help="write JSON here ('-' for standard output)")

    p = sub.add_parser("modes", help="structural modes near the actuator bandwidth and their participation")
    common(p)
    p.add_argument("--factor", type=float, default=None,
                   help="band: bandwidth / factor .. bandwidth * factor (default: the file's [band])")
    p.set_defaults(func=cmd_modes)
    p = sub.add_parser("freqresp", help="8x8 command -> piston and command -> engine responses")
    common(p)
    p.add_argument("--freq-hz", required=True, help="comma-separated frequencies, e.g. 0.5,1,2,5")
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="also save the gain grid")
    p.add_argument("--kind", choices=("engine", "piston"), default="engine", help="gain grid of engine or piston")
    p.set_defaults(func=cmd_freqresp)
    p = sub.add_parser("coupling", help="notches, coupling peaks, closed-loop stability, loop margins")
    common(p)
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="also save the peak-coupling matrix")
    p.add_argument("--reference", metavar="CONFIG",
                   help="compare with this configuration (default: the file's own `reference`, if any)")
    p.set_defaults(func=cmd_coupling)
    p = sub.add_parser("tvse", help="TVSE loops: engines' inertial coupling with the structure modes, margins")
    common(p)
    p.add_argument("--plot", metavar="PNG_OR_SVG", help="also save the Bode plot of the loops")
    p.set_defaults(func=cmd_tvse)
    p = sub.add_parser("simulate", help="nonlinear time domain: every engine's TVC coupled through the modes")
    common(p)
    p.add_argument("--profile", help="command profile (TOML) for every actuator (two-axis: pitch/yaw parts)")
    p.add_argument("--actuator-profile", action="append", metavar="NAME=PROFILE",
                   help="a profile for one actuator (repeatable; overrides --profile for it)")
    p.add_argument("--out", required=True, help="HDF5 file of the run")
    p.add_argument("--dt", type=float, default=None, help="RK4 step [s] (default 4e-4)")
    p.add_argument("--record-every", type=int, default=5, help="keep every n-th step (default 5: 2 ms)")
    p.add_argument("--duration", type=float, default=None, help="simulated time [s] (default profile + 1 s)")
    p.add_argument("--friction", default=None, help="friction law for every engine (default each model's)")
    p.set_defaults(func=cmd_simulate)
    return ap


def main(argv: list[str] | None = None) -> int:
    from taos.errors import run_cli as run
    from taos.results import check_arguments

    return run(build_parser(), argv, check=check_arguments)


def console() -> None:
    """The installed ``masv`` script: :func:`main`, then the interpreter's exit without its
    release of the loaded modules (:func:`taos.cli._exit.exit_process`)."""
    from taos.cli._exit import exit_process

    exit_process(main())


if __name__ == "__main__":  # pragma: no cover
    console()
