"""The spec mask on every basis and the cause of each shortfall (taos.report.verdict, issue 24.3).

References: the cause logic on its definition; a constructed avionics-only shortfall against
20 log10(gain); a friction shortfall whose friction-free dwell equals the exact linear response;
an impossible bound that only the servo itself can be blamed for; the shipped hot-fire and
ambient verdicts (measured, then pinned with tolerance: the paper's story, friction at hot fire
and the soft load path at ambient, with the linear servo passing at hot fire).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.errors import InputError
from taos.model import load_model
from taos.planar.avionics import Avionics
from taos.report.spec import SpecMask, SpecPoint, StepRequirement, load_spec
from taos.report.verdict import (CAUSES, LAB_LOAD_STIFFNESS_N_PER_M, cause_of, dwell_amplitude_rad,
                                 laboratory_model, remove_causes, spec_verdict)

DEG = math.pi / 180
SEG_04 = {ax: [(1.0, 0.4 * DEG), (7.0, 0.4 * DEG), (14.0, 0.8 * DEG)] for ax in ("pitch", "yaw")}


def _mask(*points, steps=()):
    return SpecMask("test mask", "<test>", tuple(points), tuple(steps))


@pytest.fixture(scope="module")
def hot():
    return load_model("rs25_hotfire")


@pytest.fixture(scope="module")
def amb():
    return load_model("rs25_ambient")


# -- the logic ---------------------------------------------------------------------------------

def test_cause_is_the_single_removals_that_pass_else_combined_else_servo():
    assert cause_of({"friction": True, "load_stiffness": False, "avionics": False}, None) == ("friction",)
    assert cause_of({"friction": True, "load_stiffness": True, "avionics": False}, None) == ("friction",
                                                                                            "load_stiffness")
    assert cause_of({c: False for c in CAUSES}, True) == ("combined",)
    assert cause_of({c: False for c in CAUSES}, False) == ("servo",)


def test_removals_change_only_their_factor(hot):
    m = remove_causes(hot, ("friction",))
    assert m.friction.name == "none" and m.structure == hot.structure and m.avionics == hot.avionics
    lab = remove_causes(hot, ("load_stiffness",))
    assert lab.structure.load_stiffness_N_per_m == LAB_LOAD_STIFFNESS_N_PER_M and lab.friction == hot.friction
    # a model stiffer than the laboratory load keeps its own K_L
    stiff = laboratory_model(lab.replace(structure=lab.structure.__class__(2e9, 0.005)))
    assert stiff.structure.load_stiffness_N_per_m == 2e9
    servo = remove_causes(hot, CAUSES)
    assert servo.avionics.lsb_rad == 0 and servo.avionics(0.3 * DEG) == pytest.approx(0.3 * DEG, rel=1e-12)
    with pytest.raises(ValueError):
        remove_causes(hot, ("gravity",))


def test_laboratory_load_is_rigid_at_the_mask_frequencies(hot):
    """The documented claim: K_L = 1e9 N/m is within 0.2 dB / 0.8 deg of a truly rigid load (1e12)
    at 5 Hz, 0.03 dB / 0.1 deg up to 2 Hz."""
    from taos.planar.freqresp import linear_freqresp

    f = np.array([0.1, 1.0, 2.0, 5.0])
    a = linear_freqresp(laboratory_model(hot), f).engine
    b = linear_freqresp(hot.replace(structure=hot.structure.__class__(1e12, 0.005)), f).engine
    dg, dp = np.abs(20 * np.log10(np.abs(a / b))), np.abs(np.degrees(np.angle(a / b)))
    assert dg[-1] < 0.25 and dp[-1] < 1.0                 # 0.19 dB, 0.8 deg measured at 5 Hz
    assert dg[:-1].max() < 0.03 and dp[:-1].max() < 0.1


def test_dwell_amplitude_is_the_profiles_band():
    segs = [(0.5, 0.4 * DEG), (7.0, 0.4 * DEG), (10.0, 0.8 * DEG), (14.0, 0.8 * DEG)]
    assert dwell_amplitude_rad(segs, 0.1) == 0.4 * DEG      # below every segment: the lowest one's
    assert dwell_amplitude_rad(segs, 7.0) == 0.4 * DEG      # 0.4 deg up to 7 Hz (paper sec. 3.2)
    assert dwell_amplitude_rad(segs, 8.0) == 0.8 * DEG
    assert dwell_amplitude_rad(segs, 30.0) == 0.8 * DEG     # above them all: the highest one's
    assert dwell_amplitude_rad([], 1.0) is None


def test_mask_step_table_is_read_and_checked(tmp_path):
    m = load_spec("models/specs/tvc_actuator_notional.toml")
    assert {s.figure: s.bounds for s in m.steps} == {"rise_time_s": (0.0, 0.1), "overshoot_pct": (0.0, 25.0)}
    assert m.steps[0].amplitude_rad == pytest.approx(0.5 * DEG)
    bad = tmp_path / "bad.toml"
    bad.write_text('[[point]]\nfrequency = "1 Hz"\ngain_db = [-1, 1]\nsource = "test"\n[step]\nrise_time = [0, 0.1]\n')
    with pytest.raises(InputError, match="step.rise_time"):
        load_spec(bad)


# -- constructed cases with known answers -------------------------------------------------------

def test_avionics_gain_0_89_fails_a_half_db_mask_and_the_cause_says_avionics(hot):
    """No friction, laboratory load, and a constant 0.89 avionics gain: the dwell's low-frequency
    engine gain is 20 log10(0.89) = -1.01 dB (plus the linear servo's own -0.03 dB): outside
    +-0.5 dB, and only the avionics is to blame."""
    from taos.planar.freqresp import linear_freqresp

    m = laboratory_model(hot.with_friction("none")).replace(
        avionics=Avionics(gain_table_rad=(0.0, 10.5 * DEG), gain_table=(0.89, 0.89)))
    mask = _mask(SpecPoint("engine", 0.1, (-0.5, 0.5), None))
    v = spec_verdict(m, mask, segments=SEG_04)
    lin, dw = [c for c in v.checks if c.basis == "linear"], [c for c in v.checks if c.basis == "dwell"]
    assert all(c.passed for c in lin)
    want = 20 * math.log10(0.89) + 20 * math.log10(abs(linear_freqresp(m, [0.1]).engine[0]))
    for c in dw:
        assert c.bounds[0].value == pytest.approx(want, abs=0.02)
        assert not c.passed and c.cause == ("avionics",)
        assert c.removed == {"friction": False, "load_stiffness": False, "avionics": True, "pressure_limit": False}
    assert "because of the avionics gain" in v.text() and "the linear servo passes" in v.text()


def test_friction_fails_where_the_friction_free_model_passes(hot):
    """Hot fire, 0.4 deg dwell at 1 Hz: friction lags the engine beyond the -25 deg bound; the
    same model without friction has the exact linear phase (the avionics is a static gain)."""
    from taos.planar.freqresp import linear_freqresp

    mask = _mask(SpecPoint("engine", 1.0, None, (-25.0, 5.0)))
    v = spec_verdict(hot, mask, segments=SEG_04, axes=("pitch",))
    (dw,) = [c for c in v.checks if c.basis == "dwell"]
    assert not dw.passed and dw.cause == ("friction",)
    free = spec_verdict(hot.with_friction("none"), mask, segments=SEG_04, axes=("pitch",))
    (dwf,) = [c for c in free.checks if c.basis == "dwell"]
    assert dwf.passed and free.passed
    lin_phase = float(linear_freqresp(hot, [1.0]).engine_phase_deg()[0])
    assert dwf.bounds[0].value == pytest.approx(lin_phase, abs=0.1)
    assert dw.bounds[0].value < lin_phase - 5.0


def test_an_impossible_bound_is_the_servo_itself(hot):
    mask = _mask(SpecPoint("engine", 0.1, (1.0, 2.0), None))
    v = spec_verdict(hot, mask, segments=SEG_04, axes=("pitch",))
    assert all(c.cause == ("servo",) for c in v.checks)
    assert v.checks[-1].removed["servo"] is False
    assert "because of the servo itself" in v.text()


def test_dwell_basis_is_the_reports_sine_dwell(hot):
    """The dwell basis is the same batched kernel at the same step: the report's sine_dwell rows,
    bit for bit at a shared frequency."""
    from taos.planar.freqresp import sine_dwell_grid

    mask = _mask(SpecPoint("engine", 1.0, (-3.0, 3.0), None))
    v = spec_verdict(hot, mask, segments=SEG_04, axes=("pitch",), attribute_causes=False)
    (dw,) = [c for c in v.checks if c.basis == "dwell"]
    _, e = sine_dwell_grid(hot, [0.4 * DEG], [1.0], "pitch", dt_max_s=2e-4)
    assert dw.bounds[0].value == 20 * math.log10(abs(e[0, 0]))


# -- the shipped models' verdicts ---------------------------------------------------------------

@pytest.fixture(scope="module")
def segments():
    from taos.report.analysis import DEFAULT_PROFILE, dwell_segments
    from taos.profiles import load_profile

    prof = load_profile(DEFAULT_PROFILE)
    return {ax: [(s.frequency_hz, s.amplitude_rad) for _, s in dwell_segments(getattr(prof, ax))]
            for ax in ("pitch", "yaw")}


@pytest.fixture(scope="module")
def shipped_mask():
    return load_spec("models/specs/tvc_actuator_notional.toml")


def _failing(v, basis):
    return {(c.axis, c.response, c.freq_hz): c for c in v.checks if c.basis == basis and not c.passed}


def test_hotfire_fails_its_mask_through_friction_and_the_linear_servo_passes(hot, segments, shipped_mask):
    """Measured (this servo, modified LuGre with the rational bristle-damping decay,
    117,525 in-lbf): the linear response and the step pass; the 0.4 deg dwells lag beyond the
    phase bounds at 0.5, 1 and 2 Hz (-19.9, -32.0, -51.9 deg against -15, -25, -45; the piston
    -26.3 at 1 Hz), and at 1 Hz the engine gain is also just below its bound (-1.52 dB against
    -1.5; it was -1.50, inside, with the former exponential decay): friction at every one, and
    the load stiffness too at 0.5 and 2 Hz (a rigid load leaves less deflection for friction
    to hold)."""
    v = spec_verdict(hot, shipped_mask, segments=segments)
    by = v.passed_by_basis()
    assert by == {"linear": True, "dwell": False, "step": True}
    fails = _failing(v, "dwell")
    assert {(ax, r, f) for ax, r, f in fails} == {(ax, r, f) for ax in ("pitch", "yaw")
                                                  for r, f in (("engine", 0.5), ("engine", 1.0),
                                                               ("engine", 2.0), ("piston", 1.0))}
    for (ax, r, f), c in fails.items():
        assert "friction" in c.cause and "avionics" not in c.cause
        assert [b.quantity for b in c.bounds if not b.passed] == (["gain_db", "phase_deg"]
                                                                 if (r, f) == ("engine", 1.0) else ["phase_deg"])
    assert fails[("pitch", "engine", 1.0)].bounds[0].value == pytest.approx(-1.52, abs=0.01)
    want = {0.5: -19.9, 1.0: -32.0, 2.0: -51.9}
    for f, ph in want.items():
        assert fails[("pitch", "engine", f)].bounds[1].value == pytest.approx(ph, abs=2.0)
    t = v.text()
    assert t.startswith("RS-25 hot fire") and "fails the mask" in t and "because of gimbal friction" in t
    assert t.endswith("the linear servo passes.")


def test_ambient_fails_its_mask_through_the_soft_load_path(amb, segments, shipped_mask):
    """Measured: the soft ambient load resonance (5.3 Hz) sits in the servo's band: engine +8.2 dB
    at 4 Hz linear (+6.3 dB dwell: the square-root valve law of the pressure-limited servo takes
    flow gain at the resonance's load pressure) against +6 dB, and the 0.5 deg step overshoots 41 % against
    25 %; every one is the load stiffness (the laboratory load passes), none is friction (ambient
    friction is 1.5 % of hot fire's) or the avionics."""
    v = spec_verdict(amb, shipped_mask, segments=segments)
    assert v.passed_by_basis() == {"linear": False, "dwell": False, "step": False}
    fails = [c for c in v.checks if not c.passed]
    assert {(c.basis, c.response, c.freq_hz) for c in fails} == {
        ("linear", "engine", 4.0), ("dwell", "engine", 4.0), ("step", "step", None)}
    assert all(c.cause == ("load_stiffness",) for c in fails)
    g = {c.basis: c.bounds[0].value for c in fails if c.basis != "step"}
    assert g["linear"] == pytest.approx(8.2, abs=0.5) and g["dwell"] == pytest.approx(6.3, abs=0.2)
    over = [b.value for c in fails if c.basis == "step" for b in c.bounds if b.quantity == "overshoot_pct"]
    assert over and all(o == pytest.approx(40.7, abs=6.0) for o in over)
    assert "because of the load stiffness (structure)" in v.text()
    assert "the linear servo passes" not in v.text()


def test_step_requirements_are_attributed(amb):
    mask = _mask(SpecPoint("engine", 0.1, (-3.0, 3.0), None),
                 steps=[StepRequirement("overshoot_pct", (0.0, 25.0), 0.5 * DEG)])
    v = spec_verdict(amb, mask, axes=("pitch",))
    (st,) = [c for c in v.checks if c.basis == "step"]
    assert not st.passed and st.cause == ("load_stiffness",)
    d = v.to_dict()
    (p,) = [x for x in d["spec_points"] if x["basis"] == "step"]
    assert p["overshoot_pct_bounds"] == [0.0, 25.0] and p["cause"] == ["load_stiffness"]
    assert d["spec_verdict_pass"] is False and d["spec_pass_by_basis"]["step"] is False
