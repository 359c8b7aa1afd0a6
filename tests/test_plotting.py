"""Plots check their content: axis labels with units, curve counts, the notch marker at the
computed notch, the load-resonance line at w_L, unit conversions of the plotted data."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from taos.planar.freqresp import FrequencyResponse, linear_freqresp  # noqa: E402
from taos.plotting import bode, compare, save, timehist  # noqa: E402
from taos.planar.simplex import load_resonance_from_notch  # noqa: E402
from taos.planar.simulate import TimeHistory  # noqa: E402

F = np.logspace(-1, math.log10(30), 300)


def gid_lines(ax, gid):
    return [ln for ln in ax.lines if ln.get_gid() == gid]


def dwell_like(lin: FrequencyResponse, amp_deg: float, loss_db: float, extra_phase_deg: float) -> FrequencyResponse:
    """A synthetic amplitude-dependent response: the linear one at a few points, scaled."""
    idx = np.searchsorted(lin.freq_hz, [0.5, 1, 2, 4, 7, 10, 14])
    k = 10 ** (-loss_db / 20) * np.exp(1j * math.radians(extra_phase_deg))
    return FrequencyResponse(lin.freq_hz[idx], lin.piston[idx], lin.engine[idx] * k, math.radians(amp_deg),
                             friction_model="dahl")


@pytest.fixture(scope="module")
def lin(hotfire):
    return linear_freqresp(hotfire, F, "pitch")


def test_bode_families_have_units_and_one_curve_per_amplitude(lin, hotfire):
    rs = [lin, dwell_like(lin, 0.4, 2.0, -10), dwell_like(lin, 0.8, 1.0, -5)]
    fig = bode.plot_freqresp(rs, resonance_hz=hotfire.load_resonance_hz("pitch"), length_unit="in",
                             moment_arm_m=hotfire.actuator.moment_arm_m)
    ax = np.array(fig.axes).reshape(2, 2)
    for a in ax.flat:
        assert len(gid_lines(a, "response")) == 3
        assert a.get_xscale() == "log"
    assert "[dB]" in ax[0, 0].get_ylabel() and "in/deg" in ax[0, 0].get_ylabel()
    assert "[dB]" in ax[0, 1].get_ylabel()
    assert ax[1, 0].get_ylabel() == "phase [deg]" and ax[1, 1].get_ylabel() == "phase [deg]"
    assert ax[1, 0].get_xlabel() == "frequency [Hz]"
    labels = [t.get_text() for t in ax[0, 0].get_legend().get_texts()]
    assert "linear" in labels and any(t.startswith("0.4 deg") for t in labels) and any(t.startswith("0.8 deg") for t in labels)
    # the DC piston gain in in/deg is R (pi/180) / 0.0254 (piston follows the command at DC)
    g0 = gid_lines(ax[0, 0], "response")[0].get_ydata()[0]
    assert g0 == pytest.approx(20 * math.log10(hotfire.actuator.moment_arm_m * math.pi / 180 / 0.0254), abs=0.05)
    plt.close(fig)


def test_notch_marker_sits_at_the_computed_notch_and_resonance_line_at_w_L(lin, hotfire):
    wl = hotfire.load_resonance_hz("pitch")
    notch = load_resonance_from_notch(hotfire, "pitch")
    # located on the plotted grid (no notch given) it agrees with the bounded search
    fig = bode.plot_freqresp([lin], resonance_hz=wl)
    ax = np.array(fig.axes).reshape(2, 2)
    (mk,) = gid_lines(ax[0, 0], "notch")
    assert mk.get_xdata()[0] == pytest.approx(notch, rel=2e-3)
    # it is the minimum of the drawn piston gain
    curve = gid_lines(ax[0, 0], "response")[0]
    assert mk.get_ydata()[0] == pytest.approx(np.min(curve.get_ydata()), abs=3.0)
    for a in ax.flat:
        (vl,) = gid_lines(a, "load-resonance")
        assert vl.get_xdata()[0] == pytest.approx(wl)
    # the notch is the load resonance (paper sec. 2.2): with the piston still the engine is the
    # oscillator J, K_L R^2 + K_n, with the 0.5 % load-path damping a damped zero ~1e-4 from w_L
    assert notch == pytest.approx(wl, rel=3e-4)
    plt.close(fig)
    fig = bode.plot_freqresp([lin], notch_hz=notch)
    (mk,) = gid_lines(fig.axes[0], "notch")
    assert mk.get_xdata()[0] == notch
    assert f"notch {notch:.2f} Hz" == mk.get_label()
    plt.close(fig)


def test_piston_unit_change_shifts_gain_by_the_unit_ratio(lin, hotfire):
    R = hotfire.actuator.moment_arm_m
    ys = {}
    for u in ("in", "mm"):
        fig = bode.plot_freqresp([lin], length_unit=u, moment_arm_m=R)
        ys[u] = gid_lines(fig.axes[0], "response")[0].get_ydata()
        assert f"{u}/deg" in fig.axes[0].get_ylabel()
        plt.close(fig)
    assert np.allclose(ys["mm"] - ys["in"], 20 * math.log10(25.4))


def test_sparse_dwell_phase_is_aligned_with_the_linear_curve(lin):
    d = dwell_like(lin, 0.4, 0.0, 0.0)
    fig = bode.plot_freqresp([lin, d])
    ax = np.array(fig.axes).reshape(2, 2)
    ref, pts = gid_lines(ax[1, 1], "response")
    expect = np.interp(np.log10(pts.get_xdata()), np.log10(ref.get_xdata()), ref.get_ydata())
    assert np.allclose(pts.get_ydata(), expect, atol=5.0)
    plt.close(fig)


def synthetic_run(n=2001, T=4.0) -> TimeHistory:
    t = np.linspace(0, T, n)
    th = np.vstack([np.radians(0.4) * np.sin(2 * np.pi * t), np.radians(0.4) * np.sin(3 * np.pi * t)])
    tf = 16270.0 * np.tanh(np.gradient(th, t, axis=1) / 1e-3)
    return TimeHistory(t_s=t, axes=("pitch", "yaw"), command_rad=th, command_avionics_rad=0.95 * th,
                       piston_m=0.8 * th + 1e-4, engine_rad=th, friction_torque_Nm=tf,
                       friction_state_rad=np.zeros_like(th), load_force_N=2e4 * th, moment_arm_m=0.8,
                       provenance={"model_name": "synthetic", "profile": "two sines", "friction_model": "coulomb-smooth"})


def test_time_history_panels_units_and_conversions():
    run = synthetic_run()
    figs = {u: timehist.plot_timehistory(run, u, "deg") for u in ("in", "mm")}
    ax = figs["in"].axes
    assert [a.get_ylabel() for a in ax] == ["command [deg]", "piston x_p [in]", "engine angle θ [deg]",
                                             "friction torque T_f [in*lbf]"]
    assert ax[3].get_xlabel() == "time [s]"
    assert figs["mm"].axes[1].get_ylabel() == "piston x_p [mm]"
    assert figs["mm"].axes[3].get_ylabel() == "friction torque T_f [N*m]"
    # two axes: commands (FCS + avionics) 4 lines, the others 2 each
    assert [len(a.lines) for a in ax] == [4, 2, 2, 2]
    get = lambda fig, k, gid: next(ln for ln in fig.axes[k].lines if ln.get_gid() == gid).get_ydata()  # noqa: E731
    assert np.allclose(get(figs["mm"], 1, "piston:pitch"), 25.4 * get(figs["in"], 1, "piston:pitch"))
    assert np.allclose(get(figs["in"], 2, "engine:yaw"), np.degrees(run.engine_rad[1]))
    # 1 in*lbf = 0.1129848 N*m
    assert np.allclose(get(figs["mm"], 3, "friction:pitch"), 0.1129848 * get(figs["in"], 3, "friction:pitch"),
                       rtol=1e-6)
    one = timehist.plot_timehistory(run, "in", "deg", axes=["yaw"], t_range_s=(1.0, 2.0))
    x = one.axes[1].lines[0].get_xdata()
    assert len(one.axes[1].lines) == 1 and x[0] >= 1.0 and x[-1] <= 2.0 + 1e-9
    for f in list(figs.values()) + [one]:
        plt.close(f)


def test_compare_ambient_hotfire_marks_each_notch_and_the_stiffer_one_is_higher(ambient, hotfire, tmp_path):
    sets = {"ambient": [linear_freqresp(ambient, F)], "hot fire": [linear_freqresp(hotfire, F)]}
    wl = {"ambient": ambient.load_resonance_hz("pitch"), "hot fire": hotfire.load_resonance_hz("pitch")}
    nt = {"ambient": load_resonance_from_notch(ambient), "hot fire": load_resonance_from_notch(hotfire)}
    fig = compare.plot_compare_freqresp(sets, resonance_hz=wl, notch_hz=nt, length_unit="mm",
                                        moment_arm_m=hotfire.actuator.moment_arm_m)
    ax = np.array(fig.axes).reshape(2, 2)
    marks = {m.get_label().split(":")[0]: m.get_xdata()[0] for m in gid_lines(ax[0, 0], "notch")}
    assert marks == pytest.approx(nt)
    assert len(gid_lines(ax[1, 1], "load-resonance")) == 2
    assert len(gid_lines(ax[0, 1], "response")) == 2
    # paper eq. 1 with K_n small: the notch ratio is about sqrt(205000 / 115000)
    assert marks["hot fire"] / marks["ambient"] == pytest.approx(math.sqrt(205 / 115), rel=0.03)
    save(fig, tmp_path / "cmp.svg")
    svg = (tmp_path / "cmp.svg").read_text()
    assert "frequency [Hz]" in svg and "mm/deg" in svg
    plt.close(fig)
    run = synthetic_run()
    fig = compare.plot_compare_timehist({"ambient": run, "hot fire": run}, "yaw", "in")
    assert [len(a.lines) for a in fig.axes] == [2, 2, 2]
    save(fig, tmp_path / "cmp.png")
    assert (tmp_path / "cmp.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    plt.close(fig)


@pytest.mark.parametrize("span_hz", [(0.1, 40.0), (0.5, 3.0)])
def test_frozen_log_axes_draw_the_same_minor_ticks_and_grid_as_matplotlib(span_hz, monkeypatch):
    """freeze_layout draws the unlabelled minor ticks of log x axes as one artist per axes: the
    saved pixels are those of matplotlib's own minor ticks (a span over a decade: merged; under
    one, where minor ticks carry labels: left to matplotlib)."""
    import io

    from PIL import Image

    from taos.plotting import _common

    def png(merge: bool):
        fig, ax = plt.subplots(2, 2, figsize=(5, 4), sharex=True)
        _common.use_grid_layout(fig, ax)
        f = np.logspace(*np.log10(span_hz), 50)
        for a in ax.flat:
            a.plot(f, np.sin(np.log(f)), "k-")
        _common.finish_bode_axes(ax)
        with monkeypatch.context() as m:
            if not merge:
                m.setattr(_common, "merge_log_minor_ticks", lambda fig: None)
            _common.freeze_layout(fig)
        merged = sum(isinstance(c, _common._MergedTicks) for a in fig.axes for c in a.get_children())
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=60)
        plt.close(fig)
        return np.asarray(Image.open(buf)), merged

    (mine, n_mine), (theirs, n_theirs) = png(True), png(False)
    assert n_theirs == 0 and n_mine == (4 if span_hz[1] / span_hz[0] > 10 else 0)
    assert mine.shape == theirs.shape and (mine == theirs).all()
