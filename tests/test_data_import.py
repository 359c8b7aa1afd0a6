"""Test-data import: CSV with unit headers or a sidecar TOML, HDF5 (our own simulate files),
validation, resampling, and one-line errors that leave nothing written."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.identify.data import load_test_data
from taos.errors import InputError

from .conftest import MODELS, run_cli

DEG = math.pi / 180


def _write_csv(path, t, cols: dict, meta: str = ""):
    names = ["time [s]"] + list(cols)
    arr = np.column_stack([t] + list(cols.values()))
    path.write_text(meta + ",".join(names) + "\n" + "\n".join(",".join(f"{v:.10g}" for v in row) for row in arr) + "\n")


def _record(n=400, fs=100.0):
    t = np.arange(n) / fs
    c = 0.4 * np.sin(2 * np.pi * 2.0 * t)
    return t, c


def test_csv_with_unit_headers_converts_to_si(tmp_path):
    t, c = _record()
    p = tmp_path / "run.csv"
    _write_csv(p, t, {"pitch_command [deg]": c, "pitch_piston [in]": 0.2 * c, "pitch_engine [deg]": c + 0.03},
               meta='# condition = "hot fire"\n# synthetic = true\n')
    d = load_test_data(p)
    assert d.axes == ("pitch",)
    np.testing.assert_allclose(d.command_rad[0], c * DEG, rtol=1e-9)
    np.testing.assert_allclose(d.piston_m[0], 0.2 * c * 0.0254, rtol=1e-9)
    assert d.condition == "hot fire" and d.synthetic and not d.engine_absolute
    assert d.sample_rate_hz == pytest.approx(100.0)
    # our own writer round-trips
    p2 = tmp_path / "again.csv"
    d.to_csv(p2)
    d2 = load_test_data(p2)
    np.testing.assert_allclose(d2.piston_m, d.piston_m, rtol=1e-7)
    assert d2.condition == "hot fire"


def test_sidecar_toml_maps_any_column_names_and_units(tmp_path):
    t, c = _record()
    p = tmp_path / "rig.csv"
    _write_csv(p, t * 1000, {"cmdP": c * DEG, "xp": 5.0 * c, "cmdY": 0 * c, "xy": 0 * c})
    (tmp_path / "rig.toml").write_text(
        'sidecar_for = "rig.csv"\ncondition = "ambient"\nengine_angle_reference = "absolute"\n[columns]\n'
        'time = {signal = "time", unit = "ms"}\ncmdP = {signal = "pitch_command", unit = "rad"}\n'
        'xp = {signal = "pitch_piston", unit = "mm"}\ncmdY = {signal = "yaw_command", unit = "rad"}\n'
        'xy = {signal = "yaw_piston", unit = "mm"}\n')
    p.write_text(p.read_text().replace("time [s]", "time"))
    d = load_test_data(p)
    assert d.axes == ("pitch", "yaw") and d.engine_rad is None and d.engine_absolute
    np.testing.assert_allclose(d.t_s, t, rtol=1e-12)
    np.testing.assert_allclose(d.piston_m[0], 5e-3 * c, rtol=1e-9)


def test_taos_simulate_hdf5_is_read_with_absolute_engine_angles(tmp_path, ambient):
    from taos.profiles import SineDwell
    from taos.planar.simulate import simulate

    th = simulate(ambient, SineDwell(0.4 * DEG, 2.0, 2), dt_s=2e-4, record_every=10)
    th.to_hdf5(tmp_path / "run.h5")
    d = load_test_data(tmp_path / "run.h5")
    assert d.axes == ("pitch",) and d.engine_absolute
    np.testing.assert_array_equal(d.piston_m[0], th.piston_m[0])


def test_irregular_time_is_resampled_onto_the_median_interval(tmp_path):
    t, c = _record()
    t = t.copy()
    t[100:] += 0.003  # one long gap
    p = tmp_path / "gap.csv"
    _write_csv(p, t, {"pitch_command [deg]": np.sin(t), "pitch_piston [in]": np.sin(t)})
    d = load_test_data(p)
    assert d.resampled
    assert np.ptp(np.diff(d.t_s)) < 1e-9
    np.testing.assert_allclose(d.command_rad[0], np.sin(d.t_s) * DEG, atol=2e-6)
    with pytest.raises(InputError, match="regular sample interval"):
        load_test_data(p, resample=False)


@pytest.mark.parametrize("case, field, expected", [
    ("nan", "pitch_piston [in]", "finite numbers"),
    ("reversed", "time [s]", "strictly increasing time"),
    ("missing", "pitch_piston", "piston position column"),
    ("unit", "pitch_piston [deg]", "length unit"),
])
def test_bad_data_gives_one_line_and_writes_nothing(tmp_path, case, field, expected):
    t, c = _record(64)
    cols = {"pitch_command [deg]": c, "pitch_piston [in]": 0.2 * c}
    if case == "nan":
        cols["pitch_piston [in]"] = cols["pitch_piston [in]"].copy()
        cols["pitch_piston [in]"][10] = np.nan
    if case == "reversed":
        t = t[::-1].copy()
    if case == "missing":
        del cols["pitch_piston [in]"]
    if case == "unit":
        cols["pitch_piston [deg]"] = cols.pop("pitch_piston [in]")
    p = tmp_path / "bad.csv"
    _write_csv(p, t, cols)
    with pytest.raises(InputError) as e:
        load_test_data(p)
    msg = str(e.value)
    assert "\n" not in msg and str(p) in msg and field in msg and expected in msg
    if case not in ("nan", "unit"):
        return
    out_model, out_json = tmp_path / "fitted.toml", tmp_path / "fit.json"
    r = run_cli("fit", p, "--model", MODELS / "rs25_ambient.toml", "--free", "load_stiffness",
                "--out-model", out_model, "--json", out_json)
    assert r.returncode == 2
    lines = [x for x in r.stderr.splitlines() if x.strip() and "Warning" not in x and "warn" not in x]
    assert len(lines) == 1 and field in lines[0], r.stderr
    assert not out_model.exists() and not out_json.exists()
    assert sorted(x.name for x in tmp_path.iterdir()) == ["bad.csv"]
