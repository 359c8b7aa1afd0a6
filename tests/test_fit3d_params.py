"""The 3-D fit's less travelled paths (issue 39): a free friction coefficient fitted back, one
fit over two records, a fitted law parameter written inline and read back, a pair of parameters
that enter the record only through their series combination refused as correlated, and the
planar options with ``--engine taos`` (``--starts`` and ``--bounds`` used, ``--no-correction``
refused in one line)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests._records3d import IN_LBF, LBF_PER_IN, ROOT, write_record3d
from tests.conftest import run_cli

HOT = ROOT / "models" / "rs25_hotfire.toml"
TRUE_KL, TRUE_TC = 180000.0 * LBF_PER_IN, 100000.0 * IN_LBF


@pytest.fixture(scope="module")
def hot3d():
    from taos.model import load_model
    from taos.taos3d import taos_model
    return taos_model(load_model(HOT))


def _truth(tm, kl=TRUE_KL, tc=TRUE_TC):
    from taos.taos3d import with_values
    from taos.taos3d.model import normal_load_N
    mu = tc / (normal_load_N(tm.base) * tm.gimbal.bearing_radius_m)
    return with_values(tm, {"structure.load_stiffness": kl, "friction.coulomb_torque": tc,
                            "gimbal.friction_coefficient": mu})


@pytest.fixture(scope="module")
def records(hot3d, tmp_path_factory):
    """Two records of the same truth (other noise seeds and offsets)."""
    from taos.identify.data import load_test_data
    d = tmp_path_factory.mktemp("rec3d2")
    truth = _truth(hot3d)
    paths = [write_record3d(truth, d / "a.csv", seed=3),
             write_record3d(truth, d / "b.csv", seed=4, offsets_deg=(-0.01, 0.03))]
    return paths, [load_test_data(p) for p in paths]


def _within(res, name, truth, k=3.0):
    i = res.names.index(name)
    assert abs(res.values[i] - truth) <= k * res.std_errors[i], (name, res.values[i], truth, res.std_errors[i])


@pytest.mark.slow
def test_friction_coefficient_fitted_back(hot3d, records):
    from taos.identify.fit3d import fit_taos
    from taos.taos3d.model import normal_load_N

    res = fit_taos(hot3d, [records[1][0]], ["load_stiffness", "friction_coefficient"])
    mu = TRUE_TC / (normal_load_N(hot3d.base) * hot3d.gimbal.bearing_radius_m)
    _within(res, "load_stiffness", TRUE_KL)
    _within(res, "friction_coefficient", mu)
    assert res.identifiable and res.model.friction.coulomb_torque_Nm == pytest.approx(
        res.values[1] * normal_load_N(hot3d.base) * hot3d.gimbal.bearing_radius_m, rel=1e-9)


@pytest.mark.slow
def test_two_records_one_fit(hot3d, records):
    from taos.identify.fit3d import Replay, fit_taos

    one = fit_taos(hot3d, [records[1][0]], ["load_stiffness", "coulomb_torque"], global_stage=False)
    two = fit_taos(hot3d, records[1], ["load_stiffness", "coulomb_torque"], global_stage=False)
    _within(two, "load_stiffness", TRUE_KL)
    _within(two, "coulomb_torque", TRUE_TC)
    assert two.n_residuals == sum(Replay(d).n_residuals for d in records[1]) == 2 * one.n_residuals
    assert [s.rsplit("/", 1)[-1] for s in two.sources] == ["a.csv", "b.csv"] and len(two.data) == 2 * len(one.data)
    assert two.std_errors[0] < one.std_errors[0]          # twice the data: a smaller standard error


@pytest.mark.slow
def test_fitted_law_parameter_written_inline_and_read_back(hot3d, records, tmp_path):
    import tomllib

    from taos.identify.fit3d import fit_taos
    from taos.model import load_model
    from taos.taos3d import taos_model

    res = fit_taos(hot3d, [records[1][0]], ["load_stiffness", "bristle_stiffness"], global_stage=False,
                   max_nfev=4, refuse=False)
    out = tmp_path / "fitted.toml"
    res.write_model(out, data_label="a.csv")
    ftab = tomllib.loads(out.read_text())["friction"]
    assert "parameter_set" not in ftab and ftab["model"] == "modified-lugre" and "bristle_stiffness" in ftab
    back = taos_model(load_model(out))
    for i, p in enumerate(res.params):
        assert p.get(back) == pytest.approx(res.values[i], rel=1e-8), p.name
    law, fit_law = back.base.friction, res.model.friction
    for f in ("coulomb_torque_Nm", "static_torque_Nm", "vibration_velocity_rad_s"):
        assert getattr(law, f) == pytest.approx(getattr(fit_law, f), rel=1e-8), f


@pytest.mark.slow
def test_series_pair_refused_as_correlated(hot3d, tmp_path):
    """Equal FEM halves: the record sees s_u and s_l only through K_s = (1/s_u + 1/s_l)^-1 K,
    so their Jacobian columns are the same and the fit refuses the pair as correlated."""
    from taos.identify.data import load_test_data
    from taos.identify.fit3d import Unidentifiable, fit_taos
    from taos.model import load_model
    from taos.taos3d import taos_model

    K = 0.3 * hot3d.K_upper
    np.savez(tmp_path / "equal_halves.npz", K_upper=K, K_lower=K)
    text = HOT.read_text().replace('stiffness_file = "../fem_data/gimbal_thrust.npz"',
                                   f'stiffness_file = "{(tmp_path / "equal_halves.npz").as_posix()}"')
    assert "equal_halves" in text
    (tmp_path / "m.toml").write_text(text)
    tm = taos_model(load_model(tmp_path / "m.toml"))
    data = load_test_data(write_record3d(_truth(tm), tmp_path / "r.csv", seed=5))
    free = ["load_stiffness", "upper_stiffness_scale", "lower_stiffness_scale"]
    with pytest.raises(Unidentifiable, match="upper_stiffness_scale and lower_stiffness_scale: correlation|"
                                             "lower_stiffness_scale and upper_stiffness_scale: correlation"):
        fit_taos(tm, [data], free, global_stage=False, max_nfev=3)


def test_no_correction_refused_with_engine_taos(records, tmp_path):
    j = tmp_path / "x.json"
    r = run_cli("fit", records[0][0], "--engine", "taos", "--model", HOT, "--free", "load_stiffness",
                "--no-correction", "--json", j)
    assert r.returncode == 2 and "--no-correction" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not j.exists()
    r = run_cli("fit", records[0][0], "--engine", "taos", "--model", HOT, "--free", "load_stiffness",
                "--starts", "0", "--json", j)
    assert r.returncode == 2 and "--starts" in r.stderr and not j.exists()
    r = run_cli("fit", records[0][0], "--engine", "taos", "--model", HOT, "--free", "load_stiffness",
                "--bounds", "coulomb_torque=1 in*lbf:2 in*lbf", "--json", j)
    assert r.returncode == 2 and "--bounds" in r.stderr and not j.exists()


@pytest.mark.slow
def test_starts_and_bounds_with_engine_taos(records, tmp_path):
    j = tmp_path / "fit.json"
    r = run_cli("fit", records[0][0], "--engine", "taos", "--model", HOT, "--free", "load_stiffness,coulomb_torque",
                "--starts", "2", "--bounds", "load_stiffness=150000 lbf/in:250000 lbf/in", "--json", j, timeout=600)
    assert r.returncode == 0, r.stderr
    d = json.loads(j.read_text())
    kl = d["parameters"]["load_stiffness"]
    assert d["solver"]["local_starts"] == 2 and kl["bounds_basis"] == "given (--bounds)"
    assert kl["bounds_si"] == pytest.approx([150000 * LBF_PER_IN, 250000 * LBF_PER_IN], rel=1e-9)
    assert abs(kl["value_si"] - TRUE_KL) <= 3 * kl["std_error_si"]
