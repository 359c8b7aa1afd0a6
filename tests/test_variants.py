"""One way to change a model (issue 38): variants through the loader, one meaning per key,
derived values never stale, and the modification recorded in every output.

References are independent of the variant code: a model file written with the new value and
loaded as any file is (the loader's own path), and the dataclasses' own fields."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
import tomlkit

from taos.errors import InputError
from taos.model import load_model
from taos.results import model_provenance, output_provenance
from taos.shipped import models_dir

LBF_IN = 4.4482216152605 / 0.0254   # N/m per lbf/in, from the exact definitions


@pytest.fixture(scope="module")
def hot():
    return load_model("rs25_hotfire")


def _copy_with(tmp_path, name, edit):
    """The shipped model ``name`` copied beside its shared files, with ``edit(doc)`` applied."""
    src = models_dir() / f"{name}.toml"
    doc = tomlkit.parse(src.read_text())
    edit(doc)
    dst = models_dir() / f"_variant_reference_{tmp_path.name}.toml"   # beside the shipped sets it names
    dst.write_text(tomlkit.dumps(doc))
    return dst


def test_a_variant_equals_the_model_file_that_holds_the_value(hot, tmp_path):
    """with_values is the loader: the same model as a file written with that value."""
    v = hot.with_values({"structure.load_stiffness": "160000 lbf/in", "engine.rotational_stiffness": 4e5})

    def edit(doc):
        doc["structure"]["load_stiffness"] = "160000 lbf/in"
        doc["engine"]["rotational_stiffness"] = "400000.0 N*m/rad"
    ref_path = _copy_with(tmp_path, "rs25_hotfire", edit)
    try:
        ref = load_model(ref_path)
    finally:
        ref_path.unlink()
    assert (v.engine, v.actuator, v.structure, v.friction, v.avionics) == \
        (ref.engine, ref.actuator, ref.structure, ref.friction, ref.avionics)
    assert v.structure.load_stiffness_N_per_m == pytest.approx(160000 * LBF_IN, rel=1e-12)


def test_load_stiffness_variant_keeps_the_files_damping_ratio(hot):
    """The stale `taos ascent --load-stiffness` bug: a new Structure dropped zeta_L to 0."""
    v = hot.with_values({"structure.load_stiffness": "115000 lbf/in"})
    assert hot.structure.load_damping_ratio == 0.005
    assert v.structure.load_damping_ratio == hot.structure.load_damping_ratio


def test_coulomb_torque_is_the_friction_level_as_the_model_file_defines_it(hot, tmp_path):
    """friction.coulomb_torque: the level; the torque-like parameters follow it exactly as a
    model file holding that coulomb_torque (and, as the file has it, static_torque equal to it)
    loads. At the shared set's reference torque the set's own bristle values come back."""
    level = 144000 * 0.0254 * 4.4482216152605   # N m
    v = hot.with_values({"friction.coulomb_torque": level})

    def edit(doc):
        doc["friction"]["coulomb_torque"] = f"{level!r} N*m"
        doc["friction"]["static_torque"] = f"{level!r} N*m"
    ref_path = _copy_with(tmp_path, "rs25_hotfire", edit)
    try:
        ref = load_model(ref_path)
    finally:
        ref_path.unlink()
    for f in ("coulomb_torque_Nm", "static_torque_Nm", "bristle_stiffness_Nm_per_rad", "bristle_damping_Nms_per_rad"):
        assert getattr(v.friction, f) == pytest.approx(getattr(ref.friction, f), rel=1e-14), f
    assert v.friction.bristle_stiffness_Nm_per_rad == pytest.approx(1.3e7, rel=1e-12)   # the set's value
    # the same meaning as the fit's friction level on the dataclasses (FrictionLaw.scaled)
    scaled = hot.friction.scaled(level / hot.friction.coulomb_torque_Nm)
    for f in ("coulomb_torque_Nm", "static_torque_Nm", "bristle_stiffness_Nm_per_rad", "stick_damping_Nms_per_rad"):
        if hasattr(scaled, f):
            assert getattr(v.friction, f) == pytest.approx(getattr(scaled, f), rel=1e-13), f


def test_a_torque_like_key_given_with_the_level_is_set_as_given(hot):
    v = hot.with_values({"friction.coulomb_torque": 2e4, "friction.bristle_stiffness": "2e7 N*m/rad"})
    assert v.friction.coulomb_torque_Nm == 2e4
    assert v.friction.bristle_stiffness_Nm_per_rad == 2e7
    assert v.friction.static_torque_Nm == pytest.approx(2e4, rel=1e-14)


def test_lco_sweep_and_sweep_set_make_the_same_model_for_the_same_value(hot):
    """`taos lco --sweep coulomb_torque=X` (apply_value) and `taos sweep --set
    friction.coulomb_torque=X` (load_model overrides) build the same TVC model: same cycle."""
    from taos.flight.lco_map import apply_value
    from taos.flight.vehicle import load_flight

    fl = load_flight("core_stage")
    x = 1.5e4
    _, a = apply_value(fl, hot, "coulomb_torque", x)
    b = load_model("rs25_hotfire", overrides={"friction.coulomb_torque": f"{x} N*m"})
    assert (a.friction, a.structure, a.avionics) == (b.friction, b.structure, b.avionics)
    _, k = apply_value(fl, hot, "load_stiffness", 2.0e7)
    assert k.structure.load_damping_ratio == hot.structure.load_damping_ratio


def test_monte_carlo_and_fit_make_their_variants_through_the_loader(hot):
    from taos.identify.surrogate import apply_values

    f = apply_values(hot, ["coulomb_torque", "load_stiffness"], [1.2e4, 3.0e7])
    ref = hot.with_values({"friction.coulomb_torque": 1.2e4, "structure.load_stiffness": 3.0e7})
    assert f.friction == ref.friction and f.structure == ref.structure
    assert dict(f.overrides) == {"friction.coulomb_torque": "12000.0 N*m", "structure.load_stiffness": "30000000.0 N/m"}


def test_a_modified_model_carries_its_own_hash_and_lists_its_overrides(hot):
    v = hot.with_values({"structure.load_stiffness": "160000 lbf/in"})
    assert v.sha256 != hot.sha256 and v.base_sha256 == hot.sha256 == hot.base_sha256
    p = model_provenance(v)
    assert p["model_sha256"] == v.sha256 and p["model_file_sha256"] == hot.sha256
    assert p["model_overrides"] == {"structure.load_stiffness": "160000 lbf/in"}
    assert "model_overrides" not in model_provenance(hot)
    o = output_provenance([v])
    assert o["model_sha256"] == v.sha256 and o["model_overrides"] == p["model_overrides"]
    # a friction swap is a modification too, and so is a change made in code
    assert model_provenance(hot.with_friction("dahl"))["model_overrides"] == {"friction.model": "dahl"}
    r = hot.replace(structure=v.structure)
    assert r.sha256 != hot.sha256 and "code.structure" in model_provenance(r)["model_overrides"]
    # variants accumulate; the same key again takes its new value
    w = v.with_values({"structure.load_stiffness": "170000 lbf/in", "friction.model": "lugre"})
    assert dict(w.overrides) == {"structure.load_stiffness": "170000 lbf/in", "friction.model": "lugre"}
    assert w.friction.name == "lugre"


def test_simulation_provenance_names_the_variant(hot):
    from taos.planar.simulate import SolverSettings, provenance

    v = hot.with_values({"structure.load_stiffness": "160000 lbf/in"})
    prov = provenance(v, SolverSettings())
    assert prov["model_sha256"] == v.sha256 != hot.sha256
    assert prov["model_overrides"] == {"structure.load_stiffness": "160000 lbf/in"}


@pytest.mark.parametrize("values, field", [
    ({"structure.load_stifness": "1 N/m"}, "structure.load_stifness"),
    ({"structure.load_stiffness": float("nan")}, "structure.load_stiffness"),
    ({"structure.load_stiffness": "-5 lbf/in"}, "structure.load_stiffness"),
    ({"structure.load_stiffness": "5 deg"}, "structure.load_stiffness"),
    ({"friction.model": "stiction-magic"}, "friction.model"),
    ({"actuator.supply_pressure": "1e12 Pa"}, "actuator.supply_pressure"),
    ({"nosection": 1.0}, "nosection"),
])
def test_a_bad_variant_is_one_input_error_naming_the_key(hot, values, field):
    with pytest.raises(InputError) as e:
        hot.with_values(values)
    assert field in str(e.value) and "\n" not in str(e.value)


def test_a_variant_keeps_the_code_changes_and_needs_no_file(hot, tmp_path):
    coded = hot.replace(structure=hot.structure.__class__(3e7, 0.0))
    kept = coded.with_values({"engine.rotational_stiffness": 4e5})   # another section: the code change stays
    assert kept.structure == coded.structure and kept.engine.rotational_stiffness_Nm_per_rad == 4e5
    assert kept.sha256 not in (hot.sha256, coded.sha256)
    over = coded.with_values({"structure.load_stiffness": 2e7})   # the key's field laid over the code's
    assert over.structure == hot.structure.__class__(2e7, 0.0)
    law = hot.replace(friction=hot.with_friction("dahl").friction)
    with pytest.raises(InputError, match="friction.model"):
        law.with_values({"friction.model": "lugre"})
    for sub in ("actuators", "friction"):   # a model file beside its own copies of the sets it names
        shutil.copytree(models_dir() / sub, tmp_path / sub)
    p = tmp_path / "m.toml"
    shutil.copy(models_dir() / "rs25_ambient.toml", p)
    m = load_model(p)
    sset = tmp_path / "friction" / "rs25_gimbal.toml"
    sset.write_text(sset.read_text().replace('bristle_stiffness = "1.3e7 N*m/rad"', 'bristle_stiffness = "1.4e7 N*m/rad"'))
    p.unlink()   # a model carries the files it was read from: its variants never read the disk
    shutil.rmtree(tmp_path / "actuators")
    v = m.with_values({"structure.load_stiffness": "120000 lbf/in"})
    assert v.structure.load_damping_ratio == m.structure.load_damping_ratio
    assert v.friction.bristle_stiffness_Nm_per_rad == m.friction.bristle_stiffness_Nm_per_rad   # the set as read
    assert v.base_sha256 == m.base_sha256 and v.input_files == m.input_files


def test_the_3d_line_stiffness_is_derived_for_each_variant_and_never_stale(hot):
    """The 3-D line stiffness puts the linear 3-D notch on the total's load resonance; a variant
    derives its own, and a model whose base changed in code refuses to use the old one."""
    import dataclasses

    from taos.taos3d import taos_model, with_values

    tm = taos_model(hot)
    soft = with_values(tm, {"structure.load_stiffness": "115000 lbf/in"})
    assert soft.line_load_stiffness_N_per_m < tm.line_load_stiffness_N_per_m
    # the line and the FEM gimbal in series give back (about) the total, stiffer than it alone
    assert soft.line_load_stiffness_N_per_m > soft.base.structure.load_stiffness_N_per_m
    stale = dataclasses.replace(tm, base=soft.base)
    with pytest.raises(InputError, match="gimbal.line_load_stiffness"):
        stale.line_load_stiffness_N_per_m
    assert tm.with_friction("dahl").line_load_stiffness_N_per_m == tm.line_load_stiffness_N_per_m


def test_describing_function_maps_are_reused_only_for_the_same_content(hot):
    from taos.flight.lco import analyse_lco, describing_function_map_for
    from taos.flight.vehicle import load_flight

    fl = load_flight("core_stage")
    amps, freqs = np.radians([0.05, 0.2]), np.array([0.15, 0.3])
    flight_model = load_model("rs25_flight")
    df = describing_function_map_for(flight_model, fl.axis, amplitudes_rad=amps, freq_hz=freqs)
    other = flight_model.with_values({"friction.bristle_stiffness": "2e7 N*m/rad"})   # same law name and axis
    with pytest.raises(InputError, match="describing-function map"):
        analyse_lco(fl, other, amplitudes_rad=amps, freq_hz=freqs, time_domain=False, df=df)
    rep = analyse_lco(fl, flight_model, amplitudes_rad=amps, freq_hz=freqs, time_domain=False, df=df)
    assert rep.prediction.df is df and math.isfinite(rep.prediction.df.engine[0, 0].real)


def test_ascent_load_stiffness_is_a_variant_that_keeps_the_files_damping_ratio(tmp_path):
    """`taos ascent --load-stiffness` once made a new Structure (zeta_L = 0) and kept the file's
    hash; now its runs name the variant: its own hash and only the overridden key (the damping
    ratio stays the file's), beside the friction swap and the bounding avionics made in code."""
    import json

    from .conftest import ROOT, run_cli

    p = run_cli("ascent", ROOT / "models" / "flight" / "ascent.toml", "--start", "120", "--end", "120.5",
                "--friction", "dahl", "--load-stiffness", "160000 lbf/in", "--out", tmp_path / "a", "--json", "-")
    assert p.returncode == 0, p.stderr
    prov = json.loads(p.stdout)["runs"][0]["provenance"]
    flight = load_model("rs25_flight")
    assert prov["model_file_sha256"] == flight.sha256 != prov["model_sha256"]
    over = prov["model_overrides"]
    assert over["friction.model"] == "dahl" and float(over["structure.load_stiffness"].split()[0]) == \
        pytest.approx(160000 * LBF_IN, rel=1e-12)
    assert not any(k.startswith(("structure.load_damping", "code.structure")) for k in over)
    assert flight.with_values({"structure.load_stiffness": "160000 lbf/in"}).structure.load_damping_ratio == \
        flight.structure.load_damping_ratio > 0
