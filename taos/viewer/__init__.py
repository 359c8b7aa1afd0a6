"""3-D gimbal view of a recorded run (meshcat): live on loopback, or one offline HTML file.

>>> th = TimeHistory.from_hdf5("run.h5")                          # doctest: +SKIP
>>> write_html(th, "run.html", angle_scale=5)                     # doctest: +SKIP
>>> serve(th)          # prints the URL, blocks until Ctrl-C      # doctest: +SKIP

Modules: :mod:`.geometry` (display geometry, meshes), :mod:`.kinematics` (run -> poses and
colours), :mod:`.base` (backend interface), :mod:`.meshcat_backend` (meshcat).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..bounds import MAX_VIEW_FPS, MAX_VIEW_SCALE   # the view's argument bounds
from ..errors import InputError
from ..results import atomic_write

if TYPE_CHECKING:
    from .geometry import EngineDrawing
    from ..planar.simulate import TimeHistory
    from ..taos3d.simulate import TaosTimeHistory

__all__ = ["BaseVisualizer", "EngineDrawing", "MeshcatVisualizer", "OfflineWindow", "ViewerFrames",
           "load_run", "offline_html", "serve", "viewer_frames", "write_html"]

#: the drawing side's names, imported on first use (PEP 562): trimesh and meshcat cost about
#: 0.5 s, which a refused run file (load_run) or a bad argument need not pay
_LAZY = {"BaseVisualizer": ".base", "EngineDrawing": ".geometry", "geometry_for_run": ".geometry",
         "ViewerFrames": ".kinematics", "viewer_frames": ".kinematics", "MeshcatVisualizer": ".meshcat_backend",
         "OfflineWindow": ".meshcat_backend", "legend_html": ".meshcat_backend", "live_visualizer": ".meshcat_backend"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")



def check_view_args(th, angle_scale=1.0, deflection_scale=None, fps=100.0, gimbal_scale=None, **_) -> None:
    """The viewer's arguments, checked as the command line's ``taos view`` checks them: ``th`` a
    run (:func:`taos.simulate`, :func:`taos.simulate_taos`, :func:`load_run`), every scale a
    finite number in (0, :data:`MAX_VIEW_SCALE`], ``fps`` in (0, :data:`MAX_VIEW_FPS`] 1/s;
    :class:`InputError` naming the argument otherwise."""
    from ..bounds import check_instance, check_number
    from ..planar.simulate import TimeHistory

    check_instance(th, "th", TimeHistory, "a run (taos.simulate, taos.simulate_taos or taos.load_run)")
    from ..errors import InputError, as_argument

    try:   # (the same values are taos view's --angle-scale, ... : the line names both)
        name = "angle_scale"
        for name, v in (("angle_scale", angle_scale), ("deflection_scale", deflection_scale),
                        ("gimbal_scale", gimbal_scale)):
            check_number(v, name, 0.0, MAX_VIEW_SCALE, lo_open=True, optional=name != "angle_scale")
        name = "fps"
        check_number(fps, "fps", 0.0, MAX_VIEW_FPS, "1/s", lo_open=True)
    except InputError as e:
        raise as_argument(e, name, "--" + name.replace("_", "-")) from None


def load_run(path: str | Path) -> TimeHistory | TaosTimeHistory:
    """Read a ``taos simulate`` HDF5 run, validated by the run-file reader
    (:mod:`taos.planar.runfile`: layout, real finite arrays of one length, increasing times,
    magnitudes, moment arm, engine name); InputError (one line) if it is not one."""
    from ..errors import check_input_file
    from ..planar.runfile import has, open_hdf5
    from ..planar.simulate import TimeHistory

    check_input_file(path, "an existing HDF5 run written by taos simulate")   # a path, not None or a number
    p = Path(path)
    if not p.is_file():
        raise InputError(str(path), "(file)", "an existing HDF5 run written by taos simulate", got="no such file")
    with open_hdf5(p, str(path), "an HDF5 run file written by taos simulate") as h5:
        three_d = has(h5, "taos", str(path))
    if three_d:
        from ..taos3d.simulate import TaosTimeHistory
        return TaosTimeHistory.from_hdf5(p)
    return TimeHistory.from_hdf5(p)


def _title(th) -> str:
    prov = th.provenance or {}
    return f"TAOS gimbal view: {prov.get('model_name', 'run')} / {prov.get('profile', '')}".rstrip(" /")


def offline_html(th, *, angle_scale: float = 1.0, deflection_scale: float | None = None, fps: float = 100.0,
                 paused_at_s: float | None = None, geometry: EngineDrawing | None = None,
                 gimbal_scale: float | None = None) -> str:
    """Self-contained HTML (meshcat viewer + scene + animation) of run ``th``.

    ``angle_scale``, ``deflection_scale`` and ``gimbal_scale`` exaggerate the engine angle, the
    load-path deflection and (3-D runs) the gimbal halves' deflections (see
    :mod:`taos.viewer.kinematics`); ``fps`` is the keyframe rate [1/s];
    ``paused_at_s`` opens the page paused at that time [s] (else it plays; ``?t=`` in the URL
    also selects a time)."""
    from .geometry import geometry_for_run
    from .kinematics import viewer_frames
    from .meshcat_backend import MeshcatVisualizer, OfflineWindow, legend_html

    fr = viewer_frames(th, geometry, angle_scale=angle_scale, deflection_scale=deflection_scale, fps=fps,
                       gimbal_scale=gimbal_scale)
    v = MeshcatVisualizer(geometry or geometry_for_run(th),
                          window=OfflineWindow(title=_title(th), legend_html=legend_html(fr)))
    v.load_scene()
    v.play(fr, autoplay=paused_at_s is None)
    return v.static_html(paused_at_s=paused_at_s)


def write_html(th: TimeHistory | TaosTimeHistory, path: str | Path, **kwargs: Any) -> None:
    """Write :func:`offline_html` to ``path`` atomically."""
    from ..errors import check_path_arg
    from ..results import check_output_file

    check_view_args(th, **kwargs)
    check_output_file(check_path_arg(path, "path", "an output file name"), "path")   # before the page is made
    text = offline_html(th, **kwargs)
    atomic_write(path, lambda p: Path(p).write_text(text, encoding="utf-8"), "path")


def serve(th: TimeHistory | TaosTimeHistory, *, angle_scale: float = 1.0, deflection_scale: float | None = None,
          fps: float = 100.0, on_ready: Callable[[str], object] = print, stop: threading.Event | None = None, gimbal_scale: float | None = None) -> int:
    """Serve the animated run on 127.0.0.1 until SIGINT/SIGTERM (or ``stop`` is set).

    Calls ``on_ready(url)`` once the scene is loaded; returns 0 after shutting the server down."""
    check_view_args(th, angle_scale, deflection_scale, fps, gimbal_scale)
    from .geometry import geometry_for_run
    from .kinematics import viewer_frames
    from .meshcat_backend import live_visualizer

    fr = viewer_frames(th, angle_scale=angle_scale, deflection_scale=deflection_scale, fps=fps,
                       gimbal_scale=gimbal_scale)
    vis, proc = live_visualizer(geometry_for_run(th))
    stop = stop or threading.Event()
    old = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is not signal.SIG_IGN:  # a background job's ignored Ctrl-C stays ignored
                old[sig] = signal.signal(sig, lambda *a: stop.set())
    try:
        vis.load_scene()
        vis.play(fr, autoplay=True)
        on_ready(vis.url())
        while not stop.wait(0.2):
            if proc.poll() is not None:
                raise RuntimeError(f"meshcat server exited ({proc.returncode})")
    finally:
        for sig, h in old.items():
            signal.signal(sig, h)
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(5)
            except Exception:
                proc.kill()
                proc.wait()
        try:
            vis.window.zmq_socket.close(linger=0)
        except Exception:
            pass
    return 0
