"""Visualiser interface (Pinocchio ``BaseVisualizer`` style): a scene description + a backend.

A backend draws the static scene once (:meth:`load_scene`), shows one frame
(:meth:`display`) and hands a whole recorded run to the viewer's own player
(:meth:`play`). :class:`taos.viewer.meshcat_backend.MeshcatVisualizer` is the one backend.
"""

from __future__ import annotations

import abc

from .geometry import EngineDrawing
from .kinematics import ViewerFrames

#: scene node names shared by all backends
NODES = {
    "structure": "taos/structure",
    "upper_gimbal": "taos/structure/upper_gimbal",
    "engine": "taos/engine",
    "powerhead": "taos/engine/powerhead",
    "nozzle": "taos/engine/nozzle",
    "lower_gimbal": "taos/engine/lower_gimbal",
}


def actuator_node(axis: str, part: str) -> str:
    """Node of an actuator part: body, rod, attach (structure side), clevis, ghost (undeflected attach)."""
    return f"taos/actuators/{axis}/{part}"


def pin_node(axis: str) -> str:
    return f"taos/structure/pins/{axis}"


class BaseVisualizer(abc.ABC):
    """Backend-independent part: the display geometry."""

    def __init__(self, geometry: EngineDrawing | None = None):
        self.geometry = geometry or EngineDrawing()

    @abc.abstractmethod
    def load_scene(self) -> None:
        """Draw the static scene (engine, gimbal halves, actuators, attach points)."""

    @abc.abstractmethod
    def display(self, frames: ViewerFrames, i: int) -> None:
        """Show frame ``i`` of ``frames``."""

    @abc.abstractmethod
    def play(self, frames: ViewerFrames, *, autoplay: bool = True) -> None:
        """Load the whole run into the viewer's player (play/pause/speed in the viewer)."""
