"""The summaries as plain dicts (JSON-ready): what ``taos info --json`` prints and what the Green
Run report writes to ``summary.json``.

* :func:`model_summary` - a model's parameters in SI and its derived figures: the load
  resonance w_L = sqrt((K_L R^2 + K_n) / J_n) (paper eq. 1), the piston notch
  (:func:`taos.planar.simplex.load_resonance_from_notch`), the breakaway deflection
  T_c / (K_L R^2), the oil-column stiffness, K_L R^2, the stall force A P_s, the avionics LSB, the
  linear modes of the pitch block, the figures of merit (:func:`figures_of_merit`) and the
  servo's own figures per axis (:func:`taos.report.servo.servo_figures`: position-loop margins
  with the model's load and in the laboratory condition, laboratory peaking and bandwidth, the
  load mode's frequency and damping);
* :func:`figures_of_merit` - per axis, the frequency figures of the exact linear response
  (:func:`taos.report.merit.frequency_merit`) and, with ``steps``, the step, threshold and
  hysteresis figures simulated on the nonlinear model (:func:`taos.report.merit.step_merit`);
* :func:`greenrun_summary` - the Green Run report's ``summary.json`` of a
  :class:`taos.report.analysis.GreenRunResult` (its keys are a contract: docs/reference/outputs.md).

Without ``steps`` the model summary is linear analysis only: nothing here imports the compiled
kernels, scipy or matplotlib (``tests/test_startup.py`` guards ``taos info``'s start-up).
Units: SI with the unit in the key, plus degrees, Hz and dB where that is the habit.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING
from taos.results import model_provenance

if TYPE_CHECKING:  # imported when a summary is made, not when this module is
    from taos.model import TvcModel

AXES = ("pitch", "yaw")


def figures_of_merit(model: TvcModel, axes=AXES, steps: bool = True, threads: int | None = None) -> dict:
    """``{axis: FrequencyMerit.to_dict() (+ "step": StepMerit.to_dict())}`` (:mod:`taos.report.merit`):
    frequency figures from the linear response, and (``steps``) the step, threshold and hysteresis
    figures by simulation (a second or two per axis; every axis' runs spread over ``threads``
    threads, :func:`taos.report.merit.step_merits`, the same numbers on any count)."""
    from .merit import frequency_merit, step_merits

    out = {ax: frequency_merit(model, ax).to_dict() for ax in axes}
    if steps:
        for ax, m in step_merits(model, tuple(axes), threads=threads).items():
            out[ax]["step"] = m.to_dict()
    return out


def model_summary(model: TvcModel, steps: bool = True, threads: int | None = None) -> dict:
    """Parameters in SI and derived figures (the ``taos info --json`` document without its
    ``provenance``), with the figures of merit (``steps=False``: the linear ones only;
    ``threads``: for the step figures' runs, :func:`figures_of_merit`)."""
    from dataclasses import asdict

    import numpy as np

    from taos.bounds import check_flag, check_instance
    from taos.model import TvcModel
    from taos.planar._parallel import thread_count
    from taos.planar.simplex import load_resonance_from_notch, simplex_state_space

    from .servo import servo_figures

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_flag(steps, "steps")
    if threads is not None:
        thread_count(threads)

    poles = simplex_state_space(model, "pitch").poles()
    p = poles[poles.imag >= 0]
    p = p[np.argsort(np.abs(p))]
    friction = {"model": model.friction.name, **asdict(model.friction)}
    av = model.avionics
    return {
        **model_provenance(model),
        "name": model.name,
        "load_resonance_hz": model.load_resonance_hz("pitch"),
        "load_resonance_yaw_hz": model.load_resonance_hz("yaw"),
        "notch_frequency_hz": load_resonance_from_notch(model, "pitch"),
        "breakaway_deflection_deg": math.degrees(model.breakaway_deflection_rad()),
        "oil_column_stiffness_N_per_m": model.actuator.oil_column_stiffness_N_per_m,
        "load_stiffness_rotational_Nm_per_rad": model.structure.load_stiffness_N_per_m * model.actuator.moment_arm_m ** 2,
        "stall_force_N": model.actuator.stall_force_N,
        "avionics_lsb_deg": math.degrees(av.lsb_rad),
        "figures_of_merit": figures_of_merit(model, steps=steps, threads=threads),
        "servo": {ax: servo_figures(model, ax).to_dict() for ax in AXES},
        "linear_modes": [{"freq_hz": float(abs(x) / (2 * math.pi)),
                          "damping_ratio": float(-x.real / abs(x)) if abs(x) > 0 else 1.0} for x in p],
        "parameters": {
            "engine": asdict(model.engine),
            "actuator": asdict(model.actuator),
            "structure": asdict(model.structure),
            "friction": friction,
            "avionics": {"quantization_bits": av.quantization_bits, "command_range_rad": av.command_range_rad,
                         "rounding": "round" if av.rounding else "truncate",
                         "crossover_command_rad": list(av.gain_table_rad), "crossover_gain": list(av.gain_table)},
        },
    }


# -- the Green Run summary.json ---------------------------------------------------------------

def _response_rows(model, ax: str, frs) -> list[dict]:
    """One row per (amplitude, frequency) of responses ``frs``: gains [dB] and phases [deg],
    continuous from low frequency against the linear response (:func:`linear_phase_reference`)."""
    from taos.linear import gain_db, phase_deg_continuous
    from taos.planar.freqresp import linear_phase_reference

    rows = []
    for r in frs:
        rp, re = linear_phase_reference(model, r.freq_hz, ax)
        pp, pe = phase_deg_continuous(r.freq_hz, r.piston, rp), phase_deg_continuous(r.freq_hz, r.engine, re)
        rows += [{"amplitude_deg": math.degrees(r.amplitude_rad), "freq_hz": float(f),
                  "piston_gain_db": float(gain_db(r.piston[j])), "piston_phase_deg": float(pp[j]),
                  "engine_gain_db": float(gain_db(r.engine[j])), "engine_phase_deg": float(pe[j])}
                 for j, f in enumerate(r.freq_hz)]
    return rows


def _test_data(test: dict, dwell_grids: dict, model) -> dict:
    """``test_data``: the measured record's responses beside the model's sine dwell at its points."""
    import numpy as np

    rows = {}
    for ax, r in test.items():
        d = r.to_dict(model=model)
        dm = dwell_grids.get(ax)
        items = []
        for k, f in enumerate(r.freq_hz):
            it = {"freq_hz": float(f), "amplitude_deg": math.degrees(r.amplitude_rad[k]),
                  "piston_gain_db": d["piston"]["gain_db"][k], "piston_phase_deg": d["piston"]["phase_deg"][k]}
            if d["engine"]:
                it.update(engine_gain_db=d["engine"]["gain_db"][k], engine_phase_deg=d["engine"]["phase_deg"][k])
            if dm is not None and len(dm["freq_hz"]):
                j = np.flatnonzero(np.isclose(dm["freq_hz"], f, rtol=2e-3))
                i = np.flatnonzero(np.isclose(dm["amplitude_rad"], r.amplitude_rad[k], rtol=2e-2))
                if i.size and j.size:
                    it["model_piston_gain_db"] = float(20 * np.log10(abs(dm["piston"][i[0], j[0]])))
                    it["model_engine_gain_db"] = float(20 * np.log10(abs(dm["engine"][i[0], j[0]])))
            items.append(it)
        rows[ax] = {"method": r.method, "excitation": d["excitation"], "points": items}
    return {"source": next(iter(test.values())).source, "axes": rows}


def greenrun_summary(result) -> dict:
    """The Green Run report's ``summary.json`` (docs/reference/outputs.md) of ``result`` (a
    :class:`taos.report.analysis.GreenRunResult`): the model's derived
    figures, the run's peaks, the sine-dwell and run-dwell responses per axis, the figures of
    merit, and (when checked / given) the spec-mask verdict and the measured record beside the
    model. Numbers only: the same dict whether or not the report folder is written."""
    import numpy as np

    from taos.units import from_si

    model, th, info = result.model, result.time_history, result.model_info
    fr = model.friction
    prov = th.provenance
    axes = tuple(th.axes)
    s = {
        **model_provenance(model),
        "profile_file": result.profile_file, "profile": prov.get("profile", ""),
        "friction_model": fr.name, "engine_model": prov.get("engine", "simplex"),
        "package_version": prov.get("package_version", ""),
        "provenance": {k: prov.get(k, "") for k in (
            "package_version", "git_revision", "model_file", "model_sha256", "profile_file", "profile_sha256",
            "stiffness_source", "stiffness_sha256", "solver", "seeds", "engine", "friction_model")}
        | {k: prov[k] for k in ("model_file_sha256", "model_overrides") if k in prov},
        "created_utc": result.created_utc,
        "load_resonance_hz": dict(result.load_resonance_hz), "notch_frequency_hz": dict(result.notch_hz),
        "breakaway_deflection_deg": info["breakaway_deflection_deg"],
        "load_stiffness_N_per_m": model.structure.load_stiffness_N_per_m,
        "load_stiffness_lbf_per_in": from_si(model.structure.load_stiffness_N_per_m, "N/m", "lbf/in"),
        "load_stiffness_rotational_Nm_per_rad": info["load_stiffness_rotational_Nm_per_rad"],
        "oil_column_stiffness_N_per_m": info["oil_column_stiffness_N_per_m"],
        "coulomb_torque_Nm": fr.coulomb_torque_Nm,
        "coulomb_torque_in_lbf": from_si(fr.coulomb_torque_Nm, "N*m", "in*lbf"),
        "moment_arm_m": model.actuator.moment_arm_m, "stall_force_N": info["stall_force_N"],
        "avionics_lsb_deg": info["avionics_lsb_deg"],
        "run": {"duration_s": float(th.t_s[-1]), "samples": int(th.t_s.size),
                "peak_engine_deg": {ax: float(np.degrees(np.max(np.abs(th.engine_rad[k])))) for k, ax in enumerate(axes)},
                "peak_piston_in": {ax: from_si(float(np.max(np.abs(th.piston_m[k]))), "m", "in") for k, ax in enumerate(axes)},
                "peak_friction_torque_Nm": {ax: float(np.max(np.abs(th.friction_torque_Nm[k]))) for k, ax in enumerate(axes)},
                "peak_load_force_N": {ax: float(np.max(np.abs(th.load_force_N[k]))) for k, ax in enumerate(axes)}},
        "sine_dwell": {ax: _response_rows(model, ax, frs) for ax, frs in result.dwell.items()},
        "run_dwell": {ax: _response_rows(model, ax, frs) for ax, frs in result.run.items()},
        "figures_of_merit": info["figures_of_merit"],
    }
    if result.spec:
        s["spec"] = {ax: r.to_dict() for ax, r in result.spec.items()}
        s["spec_pass"] = all(r.passed for r in result.spec.values())
    if getattr(result, "verdict", None) is not None:
        s.update(result.verdict.to_dict())
    if result.measured:
        s["test_data"] = _test_data(result.measured, {ax: result.dwell_grid(ax) for ax in result.dwell}, model)
    return s
