"""Issue 40, "parameter sets and files": the friction parameter-set bounds
(:data:`taos.friction.bounds.FRICTION_BOUNDS`), the stiffness file's dtype, and the theory page
against the loader.

Hostile cases run the command line in-process as ``tests/test_hostile.py`` does: exit 2, one
line on standard error naming the file and the field, no traceback, not one file of the user's
changed (SHA-256 before and after). They are counted in docs/verification.md."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import taos
import taos.units
from taos.bounds import MODEL_BOUNDS
from taos.errors import InputError
from taos.friction import _builtin
from taos.friction.bounds import FRICTION_BOUNDS, check_friction_values, loader_bound

from .hostile_cases import edited_toml, model_copy, setting, write
from .test_hostile import fingerprint

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
SETS = sorted((MODELS / "friction").glob("*.toml"))
RS25_SET = MODELS / "friction" / "rs25_gimbal.toml"
DEG = math.pi / 180.0


def test_every_key_of_every_builtin_law_has_a_bound_with_a_reason():
    keys = {f.metadata["key"] for cls in _builtin.discover().values() for f in dataclasses.fields(cls)}
    missing = sorted(k for k in keys if f"friction.{k}" not in FRICTION_BOUNDS and f"friction.{k}" not in MODEL_BOUNDS)
    assert not missing, missing
    assert "friction.reference_torque" in FRICTION_BOUNDS
    for fld, (lo, hi, unit, why) in FRICTION_BOUNDS.items():
        assert 0 <= lo < hi < math.inf and unit and len(why) > 30, fld


def test_the_bounds_page_lists_every_friction_bound():
    text = (ROOT / "docs" / "reference" / "bounds.md").read_text()
    missing = [f for f in FRICTION_BOUNDS if f"`{f}`" not in text]
    assert not missing, missing


# -- what the bounds admit: the shipped sets, the laws' defaults, the published values -------------

@pytest.mark.parametrize("path", SETS, ids=lambda p: p.name)
def test_every_shipped_set_is_within_the_bounds(path):
    import tomllib

    check_friction_values(tomllib.loads(path.read_text())["friction"], str(path))


@pytest.mark.parametrize("law", list(_builtin.discover()))
@pytest.mark.parametrize("model", ["rs25_ambient.toml", "rs25_hotfire.toml", "rs25_flight.toml",
                                   "generic_upper_engine.toml"])
def test_every_shipped_model_loads_with_every_law(model, law):
    m = taos.load_model(MODELS / model, friction=law)
    assert m.friction.name == law


def test_the_laws_default_values_are_within_the_bounds():
    """The documented defaults of every parameter class (a key left out takes it) that are
    positive lie within the bounds (a zero default means "set it": bristle stiffness)."""
    for cls in _builtin.discover().values():
        for f in dataclasses.fields(cls):
            b = FRICTION_BOUNDS.get(f"friction.{f.metadata['key']}")
            if b is not None and f.default > 0:
                assert b[0] <= f.default <= b[1], (cls.name, f.name, f.default)


def _inline(tmp_path, values: dict, law: str) -> Path:
    """The ambient model with its own [friction] table of ``values`` (no parameter set)."""
    def edit(doc):
        t = doc["friction"]
        del t["parameter_set"]
        t["model"] = law
        for k, v in values.items():
            t[k] = v
    return model_copy(tmp_path, edit=edit)


def test_published_lugre_values_load(tmp_path):
    """Canudas de Wit et al. (1995) simulation values (sigma_0 1e5 N/m, sigma_1 sqrt(1e5) N s/m,
    sigma_2 0.4 N s/m, F_s 1.5 N over F_c 1 N, v_s 1e-3 m/s, delta 2) at the 0.11 m bearing radius
    r (torque F r, stiffness and damping times r^2, rates over r) are within the bounds, and the
    law holds them."""
    r = 0.11
    ref = 2185.5 * taos.units.NM_PER_IN_LBF   # keep the model's level (mu N r_b checked at load)
    k = ref / (1.0 * r)                        # the published forces scaled to the model's level
    vals = {"bristle_stiffness": f"{1e5 * r * r * k!r} N*m/rad",
            "bristle_damping": f"{math.sqrt(1e5) * r * r * k!r} N*m*s/rad",
            "viscous_damping": f"{0.4 * r * r * k!r} N*m*s/rad",
            "static_torque": f"{1.5 * ref!r} N*m", "stribeck_velocity": f"{1e-3 / r!r} rad/s",
            "stribeck_exponent": 2.0, "damping_decay_velocity": f"{0.01 / r!r} rad/s"}
    m = taos.load_model(_inline(tmp_path, vals, "lugre"))
    assert m.friction.bristle_stiffness_Nm_per_rad == pytest.approx(1e5 * r * r * k, rel=1e-12)
    assert m.friction.stribeck_velocity_rad_s == pytest.approx(1e-3 / r, rel=1e-12)


# -- hostile values, per key: exit 2, one line naming the file and the field -------------------

def _run(argv, work: Path, capsys, monkeypatch) -> tuple[int, str]:
    from taos.cli import main

    monkeypatch.chdir(work)
    before = fingerprint(work)
    rc = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert fingerprint(work) == before, "a refused run changed a file"
    return rc, err


def _hostile_values(fld: str) -> list[tuple[str, object]]:
    lo, hi, unit, _ = FRICTION_BOUNDS[fld]
    text = {"rad/s": lambda v: f"{v / DEG:.6g} deg/s", "1": lambda v: v}.get(unit, lambda v: f"{v:.6g} {unit}")
    nan = math.nan if unit == "1" else f"nan {unit if unit != 'rad/s' else 'deg/s'}"
    inf = math.inf if unit == "1" else f"1e999 {unit if unit != 'rad/s' else 'deg/s'}"
    return [("below", text(lo / 100 if lo > 0 else -1.0)), ("above", text(hi * 100)), ("nan", nan),
            ("inf", inf), ("wrong unit", "3 kg"), ("wrong type", [1, 2])]


HOSTILE = [(fld, label, v) for fld in FRICTION_BOUNDS for label, v in _hostile_values(fld)]


@pytest.mark.parametrize("fld,label,value", HOSTILE, ids=[f"{f} {lab}" for f, lab, _ in HOSTILE])
def test_a_hostile_set_value_is_refused_naming_the_set_and_the_field(fld, label, value, tmp_path, capsys,
                                                                       monkeypatch):
    key = fld.split(".")[1]
    s = write(tmp_path, "s.toml", edited_toml(RS25_SET.read_text(), setting("friction", key, value)))
    m = model_copy(tmp_path, edit=setting("friction", "parameter_set", "s.toml"))
    rc, err = _run(["info", m], tmp_path, capsys, monkeypatch)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert fld in lines[0] and str(s) in lines[0] and "internal error" not in lines[0], lines[0]


INLINE = [k for k in FRICTION_BOUNDS if k != "friction.reference_torque"]


@pytest.mark.parametrize("fld", INLINE)
def test_a_value_beyond_its_bound_in_the_model_file_is_refused(fld, tmp_path, capsys, monkeypatch):
    """The same bounds hold for a model file's own [friction] keys (no parameter set)."""
    key = fld.split(".")[1]
    m = _inline(tmp_path, {key: _hostile_values(fld)[1][1]}, "modified-lugre")
    text = m.read_text()
    with pytest.raises(InputError) as e:   # the Python API: InputError naming the file and field
        taos.load_model(m)
    assert fld in str(e.value) and str(m) in str(e.value)
    rc, err = _run(["info", m], tmp_path, capsys, monkeypatch)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and fld in err, err
    assert m.read_text() == text


@pytest.mark.parametrize("key,value", [("stribeck_exponent", -2), ("damping_decay_velocity", "0 deg/s"),
                                       ("stick_velocity", "1e6 deg/s"), ("bristle_stiffness", "1e30 N*m/rad")])
def test_the_issues_cases_exit_2_naming_the_field(key, value, tmp_path, capsys, monkeypatch):
    """Issue 40: these ran (or ended as exit 3) with the shipped hot-fire model."""
    s = write(tmp_path, "s.toml", edited_toml(RS25_SET.read_text(), setting("friction", key, value)))
    m = write(tmp_path, "m.toml", (MODELS / "rs25_hotfire.toml").read_text()
              .replace('"friction/rs25_gimbal.toml"', f'"{s}"')
              .replace('"actuators/', f'"{MODELS}/actuators/').replace('"../fem_data/', f'"{ROOT}/fem_data/'))
    rc, err = _run(["info", m], tmp_path, capsys, monkeypatch)
    assert rc == 2 and f"friction.{key}" in err and str(s) in err and len(err.strip().splitlines()) == 1, err


def test_bristle_damping_without_a_decay_rate_is_refused(tmp_path):
    """A constant sigma_1 (damping_decay_velocity left out: v_1 = 0) makes LuGre active at high
    rates (Barabanov and Ortega 2000): refused naming the key; passive without bristle damping."""
    set_text = edited_toml(RS25_SET.read_text(), lambda d: d["friction"].pop("damping_decay_velocity"))
    write(tmp_path, "s.toml", set_text)
    m = model_copy(tmp_path, edit=setting("friction", "parameter_set", "s.toml"))
    with pytest.raises(InputError, match="friction.damping_decay_velocity"):
        taos.load_model(m)
    no_damping = edited_toml(set_text, setting("friction", "bristle_damping", "0 N*m*s/rad"))
    write(tmp_path, "s.toml", no_damping)
    assert taos.load_model(m).friction.bristle_damping_Nms_per_rad == 0.0


def test_a_set_scaled_beyond_a_bound_is_refused_naming_the_model_file(tmp_path):
    """The set's values are scaled to the file's coulomb_torque (reference_torque): a tiny
    reference torque pushes the scaled bristle stiffness beyond its bound, refused on the merged
    table naming the model file."""
    write(tmp_path, "s.toml", edited_toml(RS25_SET.read_text(), setting("friction", "reference_torque", "0.02 N*m")))
    m = model_copy(tmp_path, edit=setting("friction", "parameter_set", "s.toml"))
    with pytest.raises(InputError) as e:
        taos.load_model(m)
    assert str(m) in str(e.value) and "friction." in str(e.value)


# -- variants and fits hold the same bounds ------------------------------------------------------

def test_variants_hold_the_friction_bounds():
    m = taos.load_model(MODELS / "rs25_hotfire.toml")
    ok = m.with_values({"friction.bristle_stiffness": "2e7 N*m/rad", "friction.stribeck_exponent": 1.5})
    assert ok.friction.bristle_stiffness_Nm_per_rad == 2e7 and ok.friction.stribeck_exponent == 1.5
    for key, bad in (("friction.bristle_stiffness", "1e30 N*m/rad"), ("friction.stribeck_exponent", -2.0),
                     ("friction.stick_velocity", "1e6 deg/s"), ("friction.vibration_velocity", float("nan"))):
        with pytest.raises(InputError, match=key.replace(".", r"\.")):
            m.with_values({key: bad})


def test_fit_and_reduction_search_only_what_the_loader_admits():
    """A fit's range (start x PARAMETERS lo/hi) and a reduction's (start x FREE_KEYS factors) are
    clipped to the loader's bounds, so neither returns a set the loader refuses."""
    from taos.identify.reduce import check_free
    from taos.identify.surrogate import PARAMETERS

    for p in PARAMETERS.values():
        if p.section == "friction":
            assert loader_bound(f"friction.{p.toml_key}") is not None, p.name
    m = taos.load_model(MODELS / "rs25_hotfire.toml").with_values({"friction.bristle_stiffness": "5e11 N*m/rad"})
    keys, start, lo, hi = check_free(m, ["friction.bristle_stiffness", "friction.stribeck_velocity"])
    assert hi[0] == FRICTION_BOUNDS["friction.bristle_stiffness"][1] and start[0] == 5e11
    for k, a, b in zip(keys, lo, hi):
        blo, bhi = loader_bound(k)
        assert blo <= a < b <= bhi


def test_a_fit_never_leaves_the_loader_bounds():
    """The fit's scaled bounds (taos.identify.fit) of the friction parameters, times the start,
    lie within the loader's bounds, even when the start is near one."""
    pytest.importorskip("casadi")
    from taos.identify.fit import FitProblem

    m = taos.load_model(MODELS / "rs25_hotfire.toml", friction="dahl").with_values(
        {"friction.bristle_stiffness": "5e11 N*m/rad"})
    prob = FitProblem(m, ("bristle_stiffness", "coulomb_torque"), np.array(["pitch"] * 2),
                      np.array([1.0, 2.0]), np.array([0.01, 0.01]) * DEG)
    lo, hi = prob.scaled_bounds()
    for p, a, b, r in zip(prob.params, lo, hi, prob.p_ref):
        blo, bhi = loader_bound(f"{p.section}.{p.toml_key}")
        assert blo <= a * r * (1 - 1e-12) and b * r <= bhi * (1 + 1e-12), (p.name, a * r, b * r)


# -- the stiffness file: complex, text or boolean arrays refused, never cast -----------------------

@pytest.mark.parametrize("label,edit,field", [
    ("complex", lambda z: z.update(K_upper=z["K_upper"] + 1e-3j), "K_upper"),
    ("complex, imaginary part zero", lambda z: z.update(K_lower=z["K_lower"].astype(complex)), "K_lower"),
    ("text", lambda z: z.update(K_lower=z["K_lower"].astype(str)), "K_lower"),
    ("booleans", lambda z: z.update(K_upper=z["K_upper"] > 0), "K_upper"),
    ("complex reference points", lambda z: z.update(ref_points_m=z["ref_points_m"] + 0j), "ref_points_m"),
    ("1e300 entries", lambda z: z.update(K_upper=z["K_upper"] / np.abs(z["K_upper"]).max() * 1e300), "K_upper"),
    ("NaN", lambda z: z["K_upper"].__setitem__((0, 0), np.nan), "K_upper"),
    ("5x5", lambda z: z.update(K_upper=z["K_upper"][:5, :5]), "K_upper"),
])
def test_a_bad_stiffness_file_is_refused_naming_the_field(label, edit, field, tmp_path, capsys, monkeypatch):
    import warnings

    from taos.taos3d.model import load_stiffness_file

    z = {k: v.copy() for k, v in np.load(ROOT / "fem_data" / "gimbal_thrust.npz").items()}
    edit(z)
    p = tmp_path / "k.npz"
    np.savez(p, **z)
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # no ComplexWarning, no overflow warning: one clear line
        with pytest.raises(InputError) as e:
            load_stiffness_file(str(p))
    msg = str(e.value)
    assert "\n" not in msg and field in msg and str(p) in msg, msg
    m = model_copy(tmp_path, edit=setting("gimbal", "stiffness_file", str(p)))
    rc, err = _run(["freqresp", m, "--engine", "taos", "--freq-hz", "1"],
                   tmp_path, capsys, monkeypatch)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and field in err, err


# -- the theory page and the loader agree: T_s >= T_c for every law --------------------------------

@pytest.mark.parametrize("law", ["modified-lugre", "lugre", "coulomb-switching"])
def test_static_torque_below_the_coulomb_torque_is_refused_for_every_law(law, tmp_path):
    def edit(doc):
        doc["friction"]["model"] = law
        doc["friction"]["static_torque"] = "1000 in*lbf"   # the set's own law values kept
    m = model_copy(tmp_path, edit=edit)
    with pytest.raises(InputError, match=r"friction\.static_torque.*Coulomb"):
        taos.load_model(m)


def test_the_theory_page_says_what_the_loader_does():
    text = (ROOT / "docs" / "theory" / "friction.md").read_text()
    assert "allowed *below*" not in text
    assert r"$T_s \ge T_c$ as for every" in text and "friction.static_torque" in text


def test_fit_bounds_beyond_the_loaders_are_refused():
    """``taos fit --bounds`` (planar and 3-D) may not reach past the model file's bounds."""
    from taos.cli._fit_args import _parse_bounds
    from taos.identify.params3d import PARAMETERS3D

    with pytest.raises(InputError, match="--bounds bristle_stiffness"):
        _parse_bounds(["bristle_stiffness=1e5 N*m/rad:1e13 N*m/rad"])
    assert _parse_bounds(["bristle_stiffness=1e5 N*m/rad:1e9 N*m/rad"])["bristle_stiffness"] == (1e5, 1e9)
    with pytest.raises(InputError, match="--bounds vibration_velocity"):
        _parse_bounds(["vibration_velocity=0.1 deg/s:1000 deg/s"], PARAMETERS3D)


def test_the_3d_fit_bounds_lie_within_the_loaders():
    from taos.identify.params3d import PARAMETERS3D, bounds3d
    from taos.taos3d import taos_model

    tm = taos_model(taos.load_model(MODELS / "rs25_hotfire.toml"))
    params = [PARAMETERS3D[n] for n in ("load_stiffness", "coulomb_torque", "bristle_stiffness",
                                        "vibration_velocity", "static_torque")]
    lo, hi, _ = bounds3d(tm, params, np.array([0.5, 5.0]), ("pitch",))
    for p, a, b in zip(params, lo, hi):
        blo, bhi = loader_bound(p.key)
        assert blo <= a < b <= bhi, (p.name, a, b)
