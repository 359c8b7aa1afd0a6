"""3-D view: display kinematics identities, the offline HTML's self-containment, and real
renders in headless Chromium (offline file at two animation times; the live loopback server).

Chromium (Debian package ``chromium``) is required: missing, these tests FAIL with the
install command (``make browser`` installs it)."""

from __future__ import annotations

import math
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from taos.planar.simulate import TimeHistory
from taos.viewer import EngineDrawing, load_run, offline_html, viewer_frames
from taos.viewer.kinematics import AXES

from . import _forkserver
from .conftest import MODELS

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--disable-quic",
                  # WebGL in headless Chromium without a GPU: SwiftShader through ANGLE
                  "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--hide-scrollbars"]
W, H = 800, 600


# -- helpers (also used by tests/test_report.py) ---------------------------------------------

def chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.fail("headless Chromium not found: install it with 'apt-get install -y chromium' "
                    "(or 'make browser'); the browser tests need it and are never skipped")
    return exe


def screenshot(url: str, out_png: Path, *, budget_ms: int = 3000, offline: bool = False,
               size: tuple[int, int] = (W, H)) -> np.ndarray:
    """Render ``url`` in headless Chromium with a fresh profile; returns the RGB image (H, W, 3) uint8."""
    from PIL import Image

    profile = out_png.with_suffix(".profile")
    profile.mkdir(parents=True, exist_ok=True)
    args = [chromium(), *CHROMIUM_FLAGS, f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
            f"--virtual-time-budget={budget_ms}", f"--screenshot={out_png}"]
    if offline:  # any network request would fail
        args += ["--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=127.0.0.1:9"]
    r = subprocess.run(args + [url], capture_output=True, text=True, timeout=60)
    assert out_png.is_file(), f"chromium wrote no screenshot (exit {r.returncode}): {r.stderr[-800:]}"
    return np.asarray(Image.open(out_png).convert("RGB"))


def engine_mask(img: np.ndarray) -> np.ndarray:
    """Pixels of the nozzle's copper colour (hue 12-40 deg, saturated, not dark) under any shading."""
    x = img.astype(float) / 255.0
    mx, mn = x.max(axis=2), x.min(axis=2)
    r, g, b = x[..., 0], x[..., 1], x[..., 2]
    with np.errstate(invalid="ignore", divide="ignore"):
        hue = np.degrees(np.arctan2(math.sqrt(3) * (g - b), 2 * r - g - b)) % 360
        sat = np.where(mx > 0, (mx - mn) / mx, 0)
    return (hue > 12) & (hue < 40) & (sat > 0.4) & (mx > 0.25) & (r >= g) & (g >= b)


def nozzle_region(a: np.ndarray) -> np.ndarray:
    return a[int(0.40 * H):int(0.90 * H), int(0.25 * W):int(0.75 * W)]


def big_motion_run(T: float = 4.0, n: int = 2001) -> TimeHistory:
    """Two-axis run with large, easily seen angles: pitch 4 deg sin(pi t), yaw 3 deg cos(pi t)."""
    t = np.linspace(0.0, T, n)
    th = np.vstack([math.radians(4) * np.sin(np.pi * t), math.radians(3) * np.cos(np.pi * t)])
    R = 0.8
    delta = 5e-4 * np.vstack([np.sin(np.pi * t - 0.3), np.cos(np.pi * t - 0.3)])
    tf = np.vstack([16000 * np.sign(np.cos(np.pi * t)), 16000 * np.sign(-np.sin(np.pi * t))])
    return TimeHistory(t_s=t, axes=("pitch", "yaw"), command_rad=th, command_avionics_rad=th,
                       piston_m=R * th + delta, engine_rad=th, friction_torque_Nm=tf,
                       friction_state_rad=np.zeros_like(th), load_force_N=3.6e7 * delta, moment_arm_m=R,
                       provenance={"model_name": "synthetic", "profile": "big motion", "friction_model": "coulomb"})


# -- kinematics --------------------------------------------------------------------------------

def test_drawn_rod_stroke_is_the_recorded_piston_position_at_true_scale():
    run = big_motion_run()
    fr = viewer_frames(run, angle_scale=1.0, deflection_scale=1.0, fps=1e9)
    assert fr.t_s.size == run.t_s.size  # fps above the record rate keeps the run's own samples
    # stroke = |C - S'| - L0 = R theta + delta to second order in theta (4 deg: theta^2 R/2 ~ 2 mm)
    err = np.abs(fr.stroke_m - fr.piston_m)
    assert err.max() < 0.5 * 0.8 * math.radians(4) ** 2 + 1e-4
    # the structure attach moves by k |delta| along the actuator line
    fr100 = viewer_frames(run, deflection_scale=100.0, fps=1e9)
    g = EngineDrawing(moment_arm_m=0.8)
    for i, ax in enumerate(AXES):
        moved = np.linalg.norm(fr100.structure_attach_m[i] - g.structure_attach_m(ax), axis=1)
        assert np.allclose(moved, 100 * np.abs(fr100.deflection_m[i]), rtol=1e-9, atol=1e-12)
        # the engine clevis moves along the actuator by R theta (moment arm R about the pivot)
        along = -(fr.clevis_m[i][:, 2] - g.engine_attach_m(ax)[2])
        assert np.allclose(along, 0.8 * np.sin(run.engine_rad[i]), atol=2e-3)


def test_automatic_deflection_exaggeration_draws_the_peak_near_15_cm():
    from taos.viewer.kinematics import auto_deflection_scale

    assert auto_deflection_scale(6e-3) == 20.0 and auto_deflection_scale(5e-4) == 200.0
    assert auto_deflection_scale(1.0) == 1.0 and auto_deflection_scale(0.0) == 1.0
    run = big_motion_run()
    fr = viewer_frames(run, fps=1e9)
    assert 0.05 < fr.deflection_scale * np.abs(fr.deflection_m).max() <= 0.15


def test_engine_meshes_have_the_rs25_public_dimensions():
    """Shipped meshes (models/meshes, when present) and the procedural fallback alike: nozzle
    exit diameter 2.4 m, engine 4.3 m from the gimbal bearing top (+0.145 m) to the exit."""
    from taos.viewer.geometry import engine_meshes

    g = EngineDrawing()
    for use_files in (True, False):
        m = engine_meshes(g, use_files)
        lo, hi = m["nozzle"].bounds
        assert hi[0] - lo[0] == pytest.approx(2.4, abs=0.05)
        assert -lo[2] + g.gimbal_height_m / 2 == pytest.approx(4.3, abs=1e-5)
        assert m["powerhead"].bounds[1][2] <= 1e-9  # below the gimbal pivot


def test_friction_state_colours_stuck_only_when_friction_holds_the_engine():
    t = np.linspace(0, 2, 1001)
    theta = np.where(t < 1, 0.0, np.radians(1) * (t - 1))  # held still, then slides at 1 deg/s
    z = np.zeros((1, t.size))
    mk = lambda tf: TimeHistory(t_s=t, axes=("pitch",), command_rad=theta[None], command_avionics_rad=theta[None],  # noqa: E731
                                piston_m=0.8 * theta[None], engine_rad=theta[None], friction_torque_Nm=tf,
                                friction_state_rad=z, load_force_N=z, moment_arm_m=0.8)
    fr = viewer_frames(mk(np.full((1, t.size), 1.6e4)), fps=1e9)
    assert fr.stuck[0, t < 0.95].all() and not fr.stuck[0, t > 1.05].any()
    assert not fr.stuck[1].any()  # the absent yaw axis
    assert np.allclose(fr.pin_rgb()[0, 0], [0.86, 0.12, 0.08]) and np.allclose(fr.pin_rgb()[0, -1], [0.12, 0.72, 0.25])
    free = viewer_frames(mk(z.copy()), fps=1e9)
    assert not free.stuck.any()  # no friction torque: never "stuck"


def test_offline_html_is_self_contained_and_selects_time(tmp_path):
    run = big_motion_run()
    page = offline_html(run, fps=20, paused_at_s=1.25)
    assert "<script src" not in page.lower() and "<link" not in page.lower()
    urls = set(re.findall(r"https?://[^\s\"'()<>]+", page))
    assert urls <= {"http://www.w3.org/1999/xhtml"}, urls  # XML namespace strings only, never fetched
    assert "MeshCat.Viewer" in page and "handle_command_bytearray" in page
    assert "var t = 1.25;" in page and "[?&]t=" in page
    # scene commands replay in order, the animation last, on the run's own time base
    import base64
    import json

    import umsgpack
    cmds = [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(re.search(r"var cmds = (\[.*?\]);", page).group(1))]
    kinds = [c["type"] for c in cmds]
    assert kinds[-1] == "set_animation" and kinds.count("set_animation") == 1 and "set_object" in kinds
    eng = next(a for a in cmds[-1]["animations"] if a["path"].endswith("taos/engine"))
    times = [k["time"] for k in eng["clip"]["tracks"][0]["keys"]]
    assert eng["clip"]["fps"] == 1 and times[0] == 0.0 and times[-1] == pytest.approx(run.t_s[-1])
    assert np.allclose(np.diff(times)[:-1], 1 / 20)


def test_view_cli_rejects_a_bad_run_file_with_one_line(tmp_path):
    from taos.cli import main

    bad = tmp_path / "bad.h5"
    bad.write_text("not hdf5")
    out = tmp_path / "x.html"
    assert main(["view", str(bad), "--html", str(out)]) == 2
    assert not out.exists() and not list(tmp_path.glob(".x.html*"))
    with pytest.raises(Exception) as e:
        load_run(tmp_path / "missing.h5")
    assert "missing.h5" in str(e.value) and "\n" not in str(e.value)


# -- browser -----------------------------------------------------------------------------------

def test_offline_html_renders_the_engine_and_it_moves_between_two_times(tmp_path):
    from taos.cli import main

    h5 = tmp_path / "run.h5"
    big_motion_run().to_hdf5(h5)
    html_path = tmp_path / "view.html"
    assert main(["view", str(h5), "--html", str(html_path), "--fps", "50"]) == 0
    url = html_path.as_uri()
    a = screenshot(url + "?t=0.5", tmp_path / "a.png", offline=True)   # pitch +4 deg, yaw 0
    b = screenshot(url + "?t=1.5", tmp_path / "b.png", offline=True)   # pitch -4 deg, yaw 0
    for img in (a, b):
        m = engine_mask(img)
        region = nozzle_region(m)
        assert region.mean() > 0.10, f"engine not drawn: {region.mean():.3f} of the region is nozzle-coloured"
        assert m.sum() < 1.5 * region.sum() + 50, "nozzle colour far outside the expected region"
    # the engine swings 8 deg in pitch between the two frames: its pixels move
    ma, mb = nozzle_region(engine_mask(a)), nozzle_region(engine_mask(b))
    changed = (ma ^ mb).mean()
    assert changed > 0.02, f"only {changed:.4f} of the nozzle region changed"
    cols = np.arange(ma.shape[1])
    ca, cb = (cols * ma.sum(axis=0)).sum() / ma.sum(), (cols * mb.sum(axis=0)).sum() / mb.sum()
    assert abs(ca - cb) > 5, f"nozzle centroid moved only {abs(ca - cb):.1f} px"


def _listen_addresses(port: int) -> set[str]:
    out = set()
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(name).read_text().splitlines()[1:]:
            f = line.split()
            addr, p = f[1].rsplit(":", 1)
            if int(p, 16) == port and f[3] == "0A":
                out.add(addr)
    return out


@pytest.mark.slow
def test_live_view_serves_on_loopback_renders_and_stops_on_sigint(tmp_path):
    h5 = tmp_path / "run.h5"
    big_motion_run().to_hdf5(h5)
    exe = Path(sys.executable).parent / "taos"
    # the command as a new process, forked from the test process's fork server (Popen-like)
    proc = _forkserver.popen([str(exe), "view", str(h5)], tmp_path)
    try:
        url, lines, t_end = None, [], time.time() + 40
        while url is None and time.time() < t_end:
            r, _, _ = select.select([proc.stdout], [], [], 1.0)
            if r:
                line = proc.stdout.readline()
                lines.append(line)
                m = re.search(r"(http://127\.0\.0\.1:\d+/static/)", line)
                url = m.group(1) if m else None
            assert proc.poll() is None, f"taos view exited early: {''.join(lines)} {proc.stderr.read()}"
        assert url, f"no URL printed: {lines}"
        port = int(re.search(r":(\d+)/", url).group(1))
        assert _listen_addresses(port) == {"0100007F"}, "web server must listen on 127.0.0.1 only"
        children = Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
        assert children, "the meshcat server subprocess is missing"
        img = screenshot(url, tmp_path / "live.png", budget_ms=4000)
        region = nozzle_region(engine_mask(img))
        assert region.mean() > 0.10, f"engine not drawn in the live view ({region.mean():.3f})"
    finally:
        os.kill(proc.pid, signal.SIGINT)
        try:
            rc = proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            raise
    out = proc.stdout.read()
    assert rc == 0, proc.stderr.read()
    assert "stopped" in out
    for c in children:
        stat = Path(f"/proc/{c}/stat")
        assert not stat.exists() or stat.read_text().split()[2] == "Z", f"server {c} still running"


def test_3d_run_draws_gimbal_half_deflections(tmp_path):
    """A TAOS run file carries the gimbal halves' deflections; the viewer moves the upper half by
    g u_upper and the engine (with the lower half) by g (u_upper + u_lower)."""
    import math

    from taos.profiles import Circular
    from taos.taos3d import load_taos_model, simulate_taos
    from taos.viewer import load_run, offline_html, viewer_frames

    models = Path(__file__).resolve().parents[1] / "models"
    th = simulate_taos(load_taos_model(models / "rs25_hotfire.toml"), Circular(math.radians(0.4), 2.0, 2))
    path = tmp_path / "t.h5"
    th.to_hdf5(path)
    back = load_run(path)
    assert set(back.extra) >= {"upper_deflection", "lower_deflection"}
    fr = viewer_frames(back, gimbal_scale=500.0, fps=1e9)
    uu = np.asarray(back.extra["upper_deflection"])[:3]
    ul = np.asarray(back.extra["lower_deflection"])[:3]
    np.testing.assert_allclose(fr.upper_gimbal_m, 500.0 * uu.T, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fr.engine_offset_m, 500.0 * (uu + ul).T, rtol=1e-9, atol=1e-12)
    assert np.max(np.abs(fr.engine_offset_m)) > 1e-4
    assert "gimbal-half deflection &times;" in offline_html(back)


def test_viewer_reads_actuator_attach_points_from_the_model_geometry():
    """Issue 12.9: the viewer's actuator attach points are the model file's [geometry] (one
    definition), and a recorded run finds them through its provenance."""
    import types

    from taos.model import load_model
    from taos.taos3d.model import parse_geometry
    from taos.viewer.geometry import geometry_for_run, geometry_from_model
    m = load_model(MODELS / "rs25_hotfire.toml")
    geo = parse_geometry(m)
    g = geometry_from_model(m)
    for i, ax in enumerate(("pitch", "yaw")):
        np.testing.assert_allclose(g.structure_attach_m(ax), geo.structure_attach_m[i], atol=1e-12)
        np.testing.assert_allclose(g.engine_attach_m(ax), geo.engine_attach_m[i], atol=1e-12)
    run = types.SimpleNamespace(provenance={"model_file": str(MODELS / "rs25_hotfire.toml")}, moment_arm_m=0.8)
    assert geometry_for_run(run) == g
    gone = types.SimpleNamespace(provenance={"model_file": "/nonexistent/m.toml"}, moment_arm_m=0.7)
    assert geometry_for_run(gone).moment_arm_m == 0.7
