"""Ambient vs hot-fire comparison: the table (K_L ratio, notch shifted up, breakaway
deflection), the CLI folder, the figure-2/figure-11 plots with data, and bad input."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from taos.identify.compare import compare_models, comparison_curves
from taos.plotting.fit import plot_compare_overlay, plot_compare_side_by_side
from taos.identify.estimation import MeasuredResponse

from .conftest import MODELS, run_cli

DEG = math.pi / 180


def test_table_shows_stiffer_hot_fire_notch_up_and_breakaway_T_over_K(ambient, hotfire):
    c = compare_models(ambient, hotfire, labels=("ambient", "hot fire"))
    ka, kb = c.value("load_stiffness")
    assert (ka, kb) == (pytest.approx(115000, rel=1e-6), pytest.approx(205000, rel=1e-6))
    na, nb = c.value("notch_frequency_pitch_hz")
    wa, wb = c.value("load_resonance_pitch_hz")
    assert nb > na and wa == pytest.approx(ambient.load_resonance_hz()) and wb == pytest.approx(hotfire.load_resonance_hz())
    # the notch of the state-space response (an independent computation) sits at w_L, and
    # w^2 - K_n/J scales with K_L (paper eq. 1); the 0.5 % load-path damping moves the (damped)
    # zero by ~1e-4 w_L (exact damped zero: tests/test_load_path.py)
    assert na == pytest.approx(wa, rel=3e-4) and nb == pytest.approx(wb, rel=3e-4)
    J, Kn = ambient.engine.inertia_pitch_kgm2, ambient.engine.rotational_stiffness_Nm_per_rad
    g = lambda w: (2 * math.pi * w) ** 2 - Kn / J  # noqa: E731
    assert g(nb) / g(na) == pytest.approx(kb / ka, rel=2e-4)  # damped zeros: ~1e-4
    ba, bb = c.value("breakaway_deflection_deg")
    # T_c / (K_L R^2): the torque levels differ with the bearing normal load (issue 12.1)
    tc = hotfire.friction.coulomb_torque_Nm / ambient.friction.coulomb_torque_Nm
    assert bb / ba == pytest.approx(tc * ka / kb, rel=1e-9)
    row = next(r for r in c.rows if r.name == "load_stiffness")
    assert row.ratio == pytest.approx(205000 / 115000)
    assert "load_stiffness" in c.table() and "ratio" in c.table()


def test_compare_cli_writes_table_json_and_both_figures(tmp_path):
    out = tmp_path / "cmp"
    r = run_cli("compare", MODELS / "rs25_ambient.toml", MODELS / "rs25_hotfire.toml", "--out", out,
                "--labels", "ambient,hot fire", "--json", "-")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["labels"] == ["ambient", "hot fire"]
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == ["bode_overlay.png", "comparison.json",
                                                     "piston_side_by_side.png", "table.txt"]
    assert json.loads((out / "comparison.json").read_text())["rows"]


def test_plots_overlay_data_and_model_curves(ambient, hotfire):
    """Side-by-side (fig. 2) and overlay (fig. 11) figures carry data, model and notch artists."""
    f = np.array([1.0, 4.0, 10.0])
    d = MeasuredResponse("pitch", f, np.full(3, 0.8 * DEG), np.full(3, 0.8 + 0j), np.full(3, 1 + 0j), np.ones(3),
                         np.ones(3), np.full(3, 0.01), np.full(3, 0.01))
    amb = ambient.with_friction("none")
    c = compare_models(amb, amb.replace(structure=hotfire.structure), [d], [d], ("ambient", "hot fire"))
    curves = comparison_curves(c)
    assert [cc.notch_hz for cc in curves] == list(c.value("notch_frequency_pitch_hz"))
    for fig in (plot_compare_side_by_side(curves), plot_compare_overlay(curves)):
        gids = {ln.get_gid() for a in fig.axes for ln in a.lines}
        assert {"data", "linear", "model", "notch"} <= gids


def test_compare_with_bad_data_gives_one_line_and_no_folder(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time [s],pitch_command [deg],pitch_piston [in]\n" +
                   "\n".join(f"{1 - 0.01 * i},{i},{i}" for i in range(40)) + "\n")
    out = tmp_path / "cmp"
    r = run_cli("compare", MODELS / "rs25_ambient.toml", MODELS / "rs25_hotfire.toml", "--data", bad, bad,
                "--out", out)
    assert r.returncode == 2 and "strictly increasing time" in r.stderr
    assert len([x for x in r.stderr.splitlines() if x.startswith("taos:")]) == 1
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]
