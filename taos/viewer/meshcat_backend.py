"""meshcat backend: live viewer (loopback server) and self-contained offline HTML.

Live: :func:`start_loopback_server` runs meshcat's ZMQ/websocket bridge (``meshcat`` 0.3.2)
in a subprocess whose web server listens on 127.0.0.1 only (meshcat's own ``app.listen(port)``
would listen on every interface), and :class:`MeshcatVisualizer` talks to it through
meshcat's ``ViewerWindow``.

Offline: :class:`OfflineWindow` stands in for the ``ViewerWindow``; it keeps the scene tree as
meshcat's server does and :meth:`OfflineWindow.get_scene` writes the same kind of static page
as meshcat's ``Visualizer.static_html()`` (the viewer's ``main.min.js`` inlined, scene commands
embedded as base64 msgpack), with two changes: commands are decoded synchronously in order with
the animation last (meshcat's ``fetch(data:...)`` chain is asynchronous), and a small script
selects the animation time: ``file.html?t=2.5`` (or ``#t=2.5``) opens paused at t = 2.5 s.
The page references no external resource.
"""

from __future__ import annotations

import base64
import html
import json
import os
import subprocess
import sys
from pathlib import Path

import meshcat
import meshcat.geometry as mg
import numpy as np
import umsgpack
from meshcat.animation import Animation, AnimationClip, AnimationTrack
from meshcat.servers.tree import SceneTree, find_node, walk

from . import geometry as geo
from .base import NODES, BaseVisualizer, actuator_node, pin_node
from .kinematics import AXES, IDLE_RGB, SLIP_RGB, ViewerFrames

MAIN_JS = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"

#: static colours (0xRRGGBB)
NOZZLE_RGB = 0xC4692E
POWERHEAD_RGB = 0x9AA0A8
STRUCTURE_RGB = 0x4D5259
ATTACH_RGB = 0x202020

#: the scene root sits this high so the assembly (z from +1.1 m to -4.3 m) is centred in view
ROOT_OFFSET_M = (0.0, 0.0, 1.6)


def _rgb_int(rgb) -> int:
    r, g, b = (int(round(255 * float(c))) for c in rgb)
    return (r << 16) | (g << 8) | b


def _geometry(mesh, flat: bool = False) -> mg.TriangularMeshGeometry:
    m = mesh.copy()
    if flat:
        m.unmerge_vertices()
    return mg.TriangularMeshGeometry(np.asarray(m.vertices, np.float32), np.asarray(m.faces, np.uint32))


def _translation(p) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _pose(quat_xyzw, p) -> np.ndarray:
    from scipy.spatial.transform import Rotation
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(quat_xyzw).as_matrix()
    T[:3, 3] = p
    return T


class OfflineWindow:
    """A meshcat ``ViewerWindow`` stand-in that records the scene (no server) for static HTML."""

    def __init__(self, title: str = "TAOS gimbal view", legend_html: str = ""):
        self.tree = SceneTree()
        self.animation: bytes | None = None
        self.title = title
        self.legend_html = legend_html
        self.paused_at_s: float | None = None
        self.web_url = None

    def send(self, command) -> None:
        d = command.lower()
        data = umsgpack.packb(d)
        kind = d["type"]
        if kind == "set_animation":
            self.animation = data
            return
        path = [p for p in d.get("path", "").split("/") if p]
        node = find_node(self.tree, path)
        if kind == "set_object":
            node.object, node.properties = data, []
        elif kind == "set_transform":
            node.transform = data
        elif kind == "set_property":
            node.properties.append(data)
        elif kind == "delete":
            if path:
                find_node(self.tree, path[:-1]).pop(path[-1], None)

    def commands(self) -> list[bytes]:
        """Scene commands in replay order: objects, properties, transforms, then the animation."""
        out = []
        for node in walk(self.tree):
            if node.object is not None:
                out.append(node.object)
            out.extend(node.properties)
            if node.transform is not None:
                out.append(node.transform)
        if self.animation is not None:
            out.append(self.animation)
        return out

    def get_scene(self) -> str:
        """The self-contained HTML page (viewer JS and scene inlined, no external resource)."""
        cmds = json.dumps([base64.b64encode(c).decode("ascii") for c in self.commands()])
        paused = "null" if self.paused_at_s is None else repr(float(self.paused_at_s))
        return _PAGE.format(title=html.escape(self.title), mainjs=MAIN_JS.read_text(), commands=cmds,
                            paused=paused, legend=self.legend_html)


_PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ margin: 0; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#taos-legend {{ position: absolute; left: 8px; bottom: 8px; font: 12px sans-serif; color: #222;
  background: rgba(255,255,255,0.8); padding: 4px 8px; border-radius: 4px; pointer-events: none; }}
#taos-legend i {{ display: inline-block; width: 10px; height: 10px; margin: 0 3px 0 8px; }}
</style></head>
<body>
<div id="meshcat-pane"></div>
<div id="taos-legend">{legend}</div>
<script>
{mainjs}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  function bytes(s) {{ var b = atob(s), u = new Uint8Array(b.length);
    for (var i = 0; i < b.length; i++) u[i] = b.charCodeAt(i); return u; }}
  var cmds = {commands};
  for (var i = 0; i < cmds.length; i++) viewer.handle_command_bytearray(bytes(cmds[i]));
  // animation time: ?t=SECONDS or #t=SECONDS opens paused at that time
  var t = {paused};
  var m = (location.search + "&" + location.hash.replace("#", "&")).match(/[?&]t=([0-9.eE+-]+)/);
  if (m) t = parseFloat(m[1]);
  if (t !== null && viewer.animator.actions.length) {{
    viewer.animator.play(); viewer.animator.pause(); viewer.animator.seek(t);
    viewer.animator.display_progress(t);
  }}
  window.taosReady = true;
}})();
</script>
</body>
</html>
"""


def legend_html(frames: ViewerFrames | None) -> str:
    sw = lambda rgb: f'<i style="background:#{_rgb_int(rgb):06x}"></i>'  # noqa: E731
    from .kinematics import PULL_RGB, PUSH_RGB, STUCK_RGB
    scale = "" if frames is None else (f"engine angle &times;{frames.angle_scale:g}, "
                                       f"load-path deflection &times;{frames.deflection_scale:g}"
                                       + (f", gimbal-half deflection &times;{frames.gimbal_scale:g}"
                                          if frames.gimbal_scale else "") + "<br>")
    return (scale + f"gimbal friction:{sw(STUCK_RGB)}stuck{sw(SLIP_RGB)}slipping &nbsp; "
            f"actuator load:{sw(PUSH_RGB)}push{sw(PULL_RGB)}pull{sw(IDLE_RGB)}none")


class MeshcatVisualizer(BaseVisualizer):
    """meshcat backend; ``window`` is a meshcat ``ViewerWindow`` (live) or :class:`OfflineWindow`."""

    def __init__(self, geometry: geo.EngineDrawing | None = None, window=None, use_mesh_files: bool = True):
        super().__init__(geometry)
        self.window = window if window is not None else OfflineWindow()
        self.vis = meshcat.Visualizer(window=self.window)
        self.use_mesh_files = use_mesh_files

    # -- scene ---------------------------------------------------------------------------
    def _mesh(self, node: str, mesh, rgb, flat=False, opacity=1.0, wireframe=False):
        mat = mg.MeshLambertMaterial(color=rgb if isinstance(rgb, int) else _rgb_int(rgb),
                                     opacity=opacity, wireframe=wireframe)
        self.vis[node].set_object(_geometry(mesh, flat), mat)

    def load_scene(self) -> None:
        g = self.geometry
        v = self.vis
        v["/Grid"].set_property("visible", False)
        v["/Axes"].set_property("visible", False)
        v["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
        v["/Background"].set_property("bottom_color", [0.80, 0.83, 0.87])
        # camera in meshcat's y-up "rotated" frame: world (x, y, z) -> (x, z, -y); looking from +x+y
        v["/Cameras/default/rotated/<object>"].set_property("position", [4.6, 0.9, -4.6])
        v["taos"].set_transform(_translation(ROOT_OFFSET_M))
        meshes = geo.engine_meshes(g, self.use_mesh_files)
        self._mesh(NODES["powerhead"], meshes["powerhead"], POWERHEAD_RGB, flat=True)
        self._mesh(NODES["nozzle"], meshes["nozzle"], NOZZLE_RGB)
        self._mesh(NODES["lower_gimbal"], geo.gimbal_half(g, upper=False), SLIP_RGB)
        self._mesh(NODES["upper_gimbal"], geo.gimbal_half(g, upper=True), SLIP_RGB)
        self._mesh(NODES["structure"] + "/beams", geo.thrust_structure(g), STRUCTURE_RGB, flat=True)
        for ax in AXES:
            self._mesh(pin_node(ax), geo.axis_pin(g, ax), SLIP_RGB)
            self._mesh(actuator_node(ax, "body"), geo.actuator_body(g), IDLE_RGB)
            self._mesh(actuator_node(ax, "rod"), geo.actuator_rod(g), (0.85, 0.85, 0.88))
            self._mesh(actuator_node(ax, "attach"), geo.attach_point(), ATTACH_RGB)
            self._mesh(actuator_node(ax, "ghost"), geo.attach_point(0.09), (1.0, 1.0, 1.0), wireframe=True)
            self.vis[actuator_node(ax, "ghost")].set_transform(_translation(g.structure_attach_m(ax)))
            # engine-side clevis and its bracket ride with the engine
            self._mesh(f"{NODES['engine']}/bracket_{ax}", geo.clevis_bracket(g, ax), STRUCTURE_RGB)
            self._mesh(f"{NODES['engine']}/clevis_{ax}", geo.attach_point(), ATTACH_RGB)
            self.vis[f"{NODES['engine']}/clevis_{ax}"].set_transform(_translation(g.engine_attach_m(ax)))

    # -- one frame -----------------------------------------------------------------------
    def display(self, frames: ViewerFrames, i: int) -> None:
        v = self.vis
        eo = (0, 0, 0) if frames.engine_offset_m is None else frames.engine_offset_m[i]
        v[NODES["engine"]].set_transform(_pose(frames.engine_quat_xyzw[i], eo))
        if frames.upper_gimbal_m is not None:
            v[NODES["upper_gimbal"]].set_transform(_translation(frames.upper_gimbal_m[i]))
        for k, ax in enumerate(AXES):
            q = frames.actuator_quat_xyzw[k, i]
            v[actuator_node(ax, "body")].set_transform(_pose(q, frames.structure_attach_m[k, i]))
            v[actuator_node(ax, "rod")].set_transform(_pose(q, frames.clevis_m[k, i]))
            v[actuator_node(ax, "attach")].set_transform(_translation(frames.structure_attach_m[k, i]))

    # -- whole run -----------------------------------------------------------------------
    def play(self, frames: ViewerFrames, *, autoplay: bool = True) -> None:
        """Keyframes at the run's own times (clip fps 1, so key times are seconds)."""
        t = frames.t_s.tolist()
        anim = Animation(default_framerate=1)

        def clip(node, **tracks):
            tr = {}
            for name, (jstype, values) in tracks.items():
                tr[name] = AnimationTrack(name, jstype, list(t), np.asarray(values, float).tolist())
            anim.clips[self.vis[node].path] = AnimationClip(tracks=tr, fps=1, name="default")

        colour = lambda node: node + "/<object>"  # noqa: E731  (the mesh itself carries the material)
        if frames.engine_offset_m is None:
            clip(NODES["engine"], quaternion=("quaternion", frames.engine_quat_xyzw))
        else:  # 3-D run: the gimbal halves' deflections move the engine and the upper half
            clip(NODES["engine"], quaternion=("quaternion", frames.engine_quat_xyzw),
                 position=("vector3", frames.engine_offset_m))
            clip(NODES["upper_gimbal"], position=("vector3", frames.upper_gimbal_m))
        grgb = frames.gimbal_rgb()
        for node in (NODES["lower_gimbal"], NODES["upper_gimbal"]):
            anim.clips[self.vis[colour(node)].path] = AnimationClip(
                tracks={"material.color": AnimationTrack("material.color", "color", list(t), grgb.tolist())},
                fps=1, name="default")
        prgb, argb = frames.pin_rgb(), frames.actuator_rgb()
        for k, ax in enumerate(AXES):
            q = frames.actuator_quat_xyzw[k]
            clip(actuator_node(ax, "body"), position=("vector3", frames.structure_attach_m[k]), quaternion=("quaternion", q))
            clip(actuator_node(ax, "rod"), position=("vector3", frames.clevis_m[k]), quaternion=("quaternion", q))
            clip(actuator_node(ax, "attach"), position=("vector3", frames.structure_attach_m[k]))
            anim.clips[self.vis[colour(actuator_node(ax, "body"))].path] = AnimationClip(
                tracks={"material.color": AnimationTrack("material.color", "color", list(t), argb[k].tolist())},
                fps=1, name="default")
            anim.clips[self.vis[colour(pin_node(ax))].path] = AnimationClip(
                tracks={"material.color": AnimationTrack("material.color", "color", list(t), prgb[k].tolist())},
                fps=1, name="default")
        self.display(frames, 0)
        self.vis.set_animation(anim, play=autoplay, repetitions=1)

    # -- output --------------------------------------------------------------------------
    def static_html(self, paused_at_s: float | None = None) -> str:
        """Self-contained page (offline window only); ``paused_at_s`` opens paused at that time."""
        if not isinstance(self.window, OfflineWindow):
            return self.vis.static_html()
        self.window.paused_at_s = paused_at_s
        return self.window.get_scene()

    def url(self) -> str | None:
        return getattr(self.window, "web_url", None)


# -- live server --------------------------------------------------------------------------

def start_loopback_server(timeout_s: float = 20.0):
    """Start meshcat's bridge on 127.0.0.1 (:mod:`taos.viewer._server`); returns (proc, zmq_url, web_url)."""
    from meshcat.servers.zmqserver import match_web_url, match_zmq_url

    env = dict(os.environ)
    root = str(Path(__file__).resolve().parents[2])
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    env["TAOS_VIEWER_PARENT"] = str(os.getpid())  # the server ends when this process ends
    # bufsize=0: stdout unbuffered, so a line the server wrote is never held in a Python buffer
    # while select() below waits on the pipe for more (both URLs often arrive in one write)
    proc = subprocess.Popen([sys.executable, "-u", "-m", "taos.viewer._server"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env, start_new_session=True, bufsize=0)
    import select
    import time

    zmq_url = web_url = None
    deadline = time.monotonic() + timeout_s   # every wait bounded: a server that never answers is an error
    while zmq_url is None or web_url is None:
        if not select.select([proc.stdout], [], [], max(0.0, deadline - time.monotonic()))[0]:
            proc.kill()
            proc.wait(5)
            raise RuntimeError(f"meshcat server did not start within {timeout_s:g} s")
        line = proc.stdout.readline().decode("utf-8").strip()
        if not line and proc.poll() is not None:
            err = proc.stderr.read().decode("utf-8", "replace").strip().splitlines()
            raise RuntimeError(f"meshcat server exited ({proc.returncode}): {err[-1] if err else ''}")
        if line.startswith("zmq_url="):
            zmq_url = match_zmq_url(line)
        elif line.startswith("web_url="):
            web_url = match_web_url(line)
    return proc, zmq_url, web_url


def live_visualizer(geometry: geo.EngineDrawing | None = None):
    """(MeshcatVisualizer on a fresh loopback server, server process)."""
    import contextlib
    import io

    from meshcat.visualizer import ViewerWindow

    proc, zmq_url, web_url = start_loopback_server()
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # ViewerWindow prints its own banner
            window = ViewerWindow(zmq_url=zmq_url, start_server=False, server_args=[])
    except BaseException:
        proc.kill()
        proc.wait()
        raise
    window.web_url = web_url
    return MeshcatVisualizer(geometry, window=window), proc
