"""The pictures' cosmetic defects of issue 29 (point 3), each checked on the drawn artists: the
"engine held" notes do not overlap, a curve is one legend entry (static and interactive Bode), the
Nichols chart has one marker per kind of harmonic-balance solution, a long title is wrapped inside
the figure, ``taos compare`` labels a m/s quantity m/s, and ``taos fit`` prints its adequacy
warning once."""

from __future__ import annotations

import math
from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402

from taos.planar.freqresp import FrequencyResponse, linear_freqresp  # noqa: E402
from taos.plotting import bode, interactive, nichols  # noqa: E402

from .conftest import MODELS, run_cli  # noqa: E402

F = np.logspace(-1, math.log10(30), 120)
DWELL_F = np.array([0.5, 1.0, 2.0, 4.0])


@pytest.fixture(scope="module")
def lin(hotfire):
    return linear_freqresp(hotfire, F, "pitch")


def held_dwell(lin, amp_deg: float) -> FrequencyResponse:
    """Dwell-like response (the linear one at 0.5, 1, 2 and 4 Hz) whose engine does not move at
    0.5 and 1 Hz (friction holds it)."""
    p = np.interp(np.log(DWELL_F), np.log(lin.freq_hz), lin.piston.real) + 0j
    e = np.interp(np.log(DWELL_F), np.log(lin.freq_hz), lin.engine.real) + 0j
    e[:2] = 1e-6
    return FrequencyResponse(DWELL_F.copy(), p, e, math.radians(amp_deg), friction_model="lugre")


def test_engine_held_notes_do_not_overlap(lin):
    fig = bode.plot_freqresp([lin, held_dwell(lin, 0.05), held_dwell(lin, 0.1), held_dwell(lin, 0.2)])
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    notes = [t for t in fig.axes[1].texts if t.get_gid() == "engine-held"]
    assert len(notes) == 3
    boxes = [t.get_window_extent(r) for t in notes]
    for i in range(3):
        for j in range(i + 1, 3):
            assert not boxes[i].overlaps(boxes[j]), (notes[i].get_text(), notes[j].get_text())
    plt.close(fig)


def test_static_bode_has_one_legend_with_each_curve_once(lin, hotfire):
    fig = bode.plot_freqresp([lin, held_dwell(lin, 0.1)], resonance_hz=hotfire.load_resonance_hz("pitch"))
    legends = [a.get_legend() for a in fig.axes if a.get_legend() is not None]
    assert len(legends) == 1
    labels = [t.get_text() for t in legends[0].get_texts()]
    assert len(labels) == len(set(labels)) and "linear" in labels and any(x.startswith("0.1 deg") for x in labels)
    plt.close(fig)


def test_interactive_bode_shows_each_curve_once_in_its_legend(lin, hotfire):
    fig = interactive.bode_figure([lin, held_dwell(lin, 0.1), held_dwell(lin, 0.4)], data=[held_dwell(lin, 0.1)],
                                  resonance_hz=hotfire.load_resonance_hz("pitch"), notch_hz=6.93)
    shown = [t.name for t in fig.data if t.showlegend is not False]
    assert len(shown) == len(set(shown))
    # every curve is on the four panels, one legend entry; held points are left out and named
    groups = {}
    for t in fig.data:
        if t.legendgroup:
            groups.setdefault(t.legendgroup, []).append(t)
    held = [g for g in groups if "engine held at 0.5, 1 Hz" in g]
    assert len(held) == 3 and all(len(groups[g]) == 4 for g in held)
    assert all(sum(t.showlegend is not False for t in ts) == 1 for ts in groups.values())
    # the hover of the piston gain says what it shows, in dB
    assert "piston gain = %{y:.2f} dB" in groups["linear"][0].hovertemplate


def fake_prediction(n_unstable: int = 18):
    """A prediction-like object (the chart only reads these): L0 = 3 e^{-j pi f / 0.1} / f,
    N(A) = 1 / (1 + A / 0.01 rad), and ``n_unstable`` solutions clustered near 0.1 Hz."""
    df = SimpleNamespace(freq_hz=np.array([0.03, 2.0]), amplitude_rad=np.radians([0.01, 0.03, 0.1, 0.3, 1.0]),
                         friction_model="lugre")
    loop = lambda f: 3 * np.exp(-1j * np.pi * np.asarray(f) / 0.1) / np.asarray(f)  # noqa: E731
    cycles = [SimpleNamespace(stable=False, amplitude_rad=math.radians(0.01 + 0.001 * k), freq_hz=0.1 + 1e-4 * k)
              for k in range(n_unstable)] + [SimpleNamespace(stable=True, amplitude_rad=math.radians(0.2), freq_hz=0.12)]
    return SimpleNamespace(df=df, loop=loop, open_loop=lambda a, f: loop(f) / (1 + a / 0.01 * 0 + a / 1e-2),
                           cycles=cycles)


def test_nichols_shows_one_marker_per_kind_of_solution():
    pred = fake_prediction(18)
    fig = nichols.plot_lco_nichols(pred)
    ax = fig.axes[0]
    (unstable,) = [ln for ln in ax.lines if ln.get_gid() == "unstable-lco"]
    (stable,) = [ln for ln in ax.lines if ln.get_gid() == "stable-lco"]
    assert unstable.get_label().startswith("18 unstable solution (threshold)s: 0.01-0.027 deg")
    assert stable.get_label() == "stable LCO: 0.2 deg, 0.12 Hz"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(labels) == len(set(labels)) and len(labels) <= 8
    plt.close(fig)
    ifig = interactive.nichols_figure(pred)
    marks = [t for t in ifig.data if t.x is not None and tuple(t.x) == (-180,) and "solution" in (t.name or "")]
    assert len(marks) == 1 and marks[0].hovertemplate.count("<br>") >= 18   # every solution in the hover


def test_a_long_title_is_wrapped_inside_the_figure(lin):
    title = "pitch: command → piston and engine (" + "a very long model name, " * 8 + ")"
    fig = bode.plot_freqresp([lin], title=title)
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent(fig.canvas.get_renderer())
    assert "\n" in fig._suptitle.get_text()
    assert box.x0 >= 0 and box.x1 <= fig.bbox.width
    plt.close(fig)


def test_compare_labels_a_rate_in_m_per_s(ambient, hotfire):
    from taos.identify.compare import compare_models

    c = compare_models(ambient, hotfire)
    units = {r.name: r.unit for r in c.rows}
    assert units["max_rate_m_per_s"] == "m/s" and units["loop_gain_per_s"] == "1/s"


@pytest.mark.slow
def test_fit_prints_its_adequacy_warning_once(tmp_path):
    """A deliberately wrong structure (engine inertia x 1.5) fitted to the hot-fire record: the
    INADEQUATE warning appears once across standard output and error."""
    text = (MODELS / "rs25_hotfire.toml").read_text()
    import re
    out = []
    for line in text.splitlines():
        m = re.match(r'^(inertia_(pitch|yaw)\s*=\s*")([0-9.eE+-]+)(\s*[^"]*")(.*)$', line)
        out.append(f"{m.group(1)}{float(m.group(3)) * 1.5:g}{m.group(4)}" if m else line)
    model = tmp_path / "wrong.toml"
    model.write_text("\n".join(out) + "\n")
    p = run_cli("fit", MODELS / "data" / "greenrun_hotfire_synthetic.csv", "--model", model,
                "--free", "load_stiffness,coulomb_torque", "--starts", "1")
    assert p.returncode == 0, p.stderr
    assert (p.stdout + p.stderr).count("model adequacy: INADEQUATE") == 1
    assert "residual rms" in p.stdout
