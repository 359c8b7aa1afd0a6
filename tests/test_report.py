"""``taos greenrun``: the report folder, its numbers, offline rendering, and atomicity."""

from __future__ import annotations

import json
import math
import re

import h5py
import numpy as np
import pytest

from tests.conftest import MODELS, ROOT, run_cli
from tests.test_viewer import engine_mask, screenshot

HOTFIRE = MODELS / "rs25_hotfire.toml"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("greenrun") / "report"
    r = run_cli("greenrun", HOTFIRE, "--out", out)
    assert r.returncode == 0, r.stderr
    return out, r


def test_greenrun_cli_writes_index_h5_and_shows_progress(report, hotfire):
    out, r = report
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == ["greenrun.h5", "index.html",
                                                                                   "summary.json"]
    assert "greenrun" in r.stderr and "6/6" in r.stderr  # tqdm progress on standard error
    assert "index.html" in r.stdout
    page = (out / "index.html").read_text()
    assert "<script src" not in page.lower() and "<link" not in page.lower()
    assert set(re.findall(r"https?://[^\s\"'()<>&]+", page)) <= {"http://www.w3.org/1999/xhtml"}
    assert len(re.findall(r'<img [^>]*src="data:image/png;base64,', page)) == 4
    assert page.count("<iframe") == 1 and "srcdoc=" in page and "MeshCat.Viewer" in page
    s = json.loads((out / "summary.json").read_text())
    from taos.simplex import load_resonance_from_notch
    assert s["load_resonance_hz"]["pitch"] == pytest.approx(hotfire.load_resonance_hz("pitch"))
    assert s["notch_frequency_hz"]["pitch"] == pytest.approx(load_resonance_from_notch(hotfire, "pitch"))
    assert s["breakaway_deflection_deg"] == pytest.approx(math.degrees(hotfire.breakaway_deflection_rad()))
    assert s["load_stiffness_lbf_per_in"] == pytest.approx(205000, rel=1e-9)
    assert f"{s['load_resonance_hz']['pitch']:.3f}" in page and "205,000 lbf/in" in page
    # the profile's amplitudes 0.4 / 0.8 deg at its frequencies (pitch 7, yaw 5)
    assert {round(x["amplitude_deg"], 6) for x in s["sine_dwell"]["pitch"]} == {0.4, 0.8}
    assert len(s["run_dwell"]["pitch"]) == 7 and len(s["run_dwell"]["yaw"]) == 5


def test_two_axis_run_dwells_agree_with_the_sine_dwell_kernel(report):
    """Two code paths: integrate_samples over the whole two-axis profile (response read off each
    dwell's last two cycles) and sine_dwell_batch (each dwell from rest, settled)."""
    out, _ = report
    s = json.loads((out / "summary.json").read_text())
    for ax in ("pitch", "yaw"):
        dw = {(round(x["amplitude_deg"], 6), x["freq_hz"]): x for x in s["sine_dwell"][ax]}
        for r in s["run_dwell"][ax]:
            d = dw[(round(r["amplitude_deg"], 6), r["freq_hz"])]
            # achieved: 0.006 dB (engine), 0.0013 dB (piston), 0.03 deg
            assert r["engine_gain_db"] == pytest.approx(d["engine_gain_db"], abs=0.02)
            assert r["piston_gain_db"] == pytest.approx(d["piston_gain_db"], abs=0.005)
            dp = (r["engine_phase_deg"] - d["engine_phase_deg"] + 180) % 360 - 180
            assert abs(dp) < 0.1


def test_greenrun_h5_holds_the_run_and_the_responses(report):
    from taos.simulate import TimeHistory

    out, _ = report
    th = TimeHistory.from_hdf5(out / "greenrun.h5")
    assert th.axes == ("pitch", "yaw") and th.t_s[-1] > 30
    # the profile commands 0.4 deg in the first pitch dwell
    assert np.degrees(np.max(np.abs(th.command_rad[0][th.t_s < 8]))) == pytest.approx(0.4, rel=1e-3)
    with h5py.File(out / "greenrun.h5") as h5:
        lin = h5["freqresp/pitch/linear"]
        assert lin["piston"].dtype.kind == "c" and lin["freq_hz"].shape == lin["piston"].shape
        assert h5["freqresp/yaw/sine_dwell/piston"].shape == (2, 5)


def test_report_opens_offline_with_the_3d_view_drawn(report, tmp_path):
    out, _ = report
    img = screenshot((out / "index.html").as_uri(), tmp_path / "report.png", budget_ms=4000, offline=True,
                     size=(1200, 1300))
    assert (img < 200).any(axis=2)[:250].mean() > 0.01  # title and summary text drawn
    # the 3-D view follows the summary table: a solid nozzle-coloured blob in the lower part
    rows = (engine_mask(img[600:]).sum(axis=1) >= 60).sum()
    assert rows >= 80, f"3-D view (engine) not drawn inside the report ({rows} nozzle rows)"


def test_failed_greenrun_leaves_the_previous_report_untouched(tmp_path, monkeypatch):
    import taos.cli.report as rep
    from taos.errors import InputError

    out = tmp_path / "gr"
    out.mkdir()
    (out / "index.html").write_text("previous")
    (out / ".taos-output.json").write_text('{"files": ["index.html"]}')  # a report this program wrote
    bad = tmp_path / "bad.toml"
    bad.write_text(HOTFIRE.read_text().replace('load_stiffness = "205000 lbf/in"', 'load_stiffness = "-1 lbf/in"'))
    with pytest.raises(InputError):
        rep.greenrun_report(bad, out, progress=False)
    assert (out / "index.html").read_text() == "previous" and len(list(out.iterdir())) == 2

    def boom(*a, **k):
        raise OSError("disk full")

    import matplotlib.pyplot as plt

    import taos.viewer
    monkeypatch.setattr(rep, "_write_h5", boom)  # fails while the new folder is being written
    monkeypatch.setattr(rep, "_png", lambda fig: (plt.close(fig), "data:,")[1])  # (speed only)
    monkeypatch.setattr(taos.viewer, "offline_html", lambda *a, **k: "<html></html>")
    with pytest.raises(InputError):  # an output place that cannot be written: exit 2
        rep.greenrun_report(HOTFIRE, out, progress=False)
    assert (out / "index.html").read_text() == "previous"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml", "gr"]  # no temp folder left
    r = run_cli("greenrun", bad, "--out", tmp_path / "new", cwd=ROOT)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "new").exists()


def test_greenrun_with_the_3d_engine(tmp_path):
    """taos greenrun --engine taos: the report is built from the 3-D model and says so."""
    import json as _json

    from taos.cli.report import greenrun_report

    out = greenrun_report(MODELS / "rs25_hotfire.toml", tmp_path / "gr", engine="taos", progress=False)
    s = _json.loads((out / "summary.json").read_text())
    assert s["engine_model"] == "taos"
    assert "taos engine model" in (out / "index.html").read_text()
