"""Time-history plots of a recorded run (:class:`~taos.planar.simulate.TimeHistory`).

Four panels sharing the time axis [s]: command (FCS command, solid; after avionics
quantisation and crossover gain, dashed) in ``angle_unit``; piston position x_p in
``length_unit``; engine angle theta in ``angle_unit``; gimbal friction torque T_f in in*lbf
(``length_unit`` 'in') or N*m. One colour per axis (pitch, yaw). Curves carry the ``gid``
"<quantity>:<axis>" (e.g. "piston:yaw").
"""

from __future__ import annotations

import numpy as np

from ._common import LENGTH_UNITS, use_grid_layout, wrapped_title
from ..errors import InputError
from ..units import ureg

import matplotlib.pyplot as plt  # noqa: E402

ANGLE_UNITS = {"deg": np.pi / 180.0, "rad": 1.0}
AXIS_COLOURS = {"pitch": "tab:blue", "yaw": "tab:orange"}
#: torque unit shown with each length unit: name, N*m per unit (pint)
TORQUE_UNITS = {"in": ("in*lbf", float(ureg.Quantity(1, "inch*lbf").to("N*m").magnitude)),
                "mm": ("N*m", 1.0), "m": ("N*m", 1.0)}


def units(length_unit: str, angle_unit: str) -> tuple[float, float, str, float]:
    """(metres per length unit, rad per angle unit, torque unit, N*m per torque unit)."""
    if length_unit not in LENGTH_UNITS:
        raise InputError("plot", "length_unit", f"one of {', '.join(LENGTH_UNITS)}", got=repr(length_unit))
    if angle_unit not in ANGLE_UNITS:
        raise InputError("plot", "angle_unit", f"one of {', '.join(ANGLE_UNITS)}", got=repr(angle_unit))
    tname, tscale = TORQUE_UNITS[length_unit]
    return LENGTH_UNITS[length_unit], ANGLE_UNITS[angle_unit], tname, tscale


def _window(t, t_range_s):
    if t_range_s is None:
        return slice(None)
    lo, hi = np.searchsorted(t, [t_range_s[0], t_range_s[1]])
    return slice(int(lo), int(max(hi, lo + 1)))


def plot_timehistory(th, length_unit: str = "in", angle_unit: str = "deg", *, t_range_s=None,
                     axes=None, title: str | None = None):
    """Commands, pistons, engine angles and friction torque of run ``th``.

    Parameters
    ----------
    th : TimeHistory
    length_unit : {'in', 'mm', 'm'}
        Piston position unit (and torque unit: in*lbf for 'in', else N*m).
    angle_unit : {'deg', 'rad'}
    t_range_s : (float, float), optional
        Time window [s].
    axes : sequence of str, optional
        Which of the run's axes to draw (default all).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    m_per, rad_per, tname, nm_per = units(length_unit, angle_unit)
    names = list(th.axes if axes is None else axes)
    for n in names:
        if n not in th.axes:
            raise InputError("plot", "axes", f"axes of the run ({', '.join(th.axes)})", got=repr(n))
    t = np.asarray(th.t_s)
    w = _window(t, t_range_s)
    fig, ax = plt.subplots(4, 1, figsize=(11, 9), sharex=True)
    use_grid_layout(fig, ax)
    for n in names:
        i = th.axes.index(n)
        c = AXIS_COLOURS.get(n, None)
        ax[0].plot(t[w], th.command_rad[i][w] / rad_per, color=c, gid=f"command:{n}", label=f"{n} FCS command")
        ax[0].plot(t[w], th.command_avionics_rad[i][w] / rad_per, color=c, linestyle="--", linewidth=0.8,
                   gid=f"command_avionics:{n}", label=f"{n} after avionics")
        ax[1].plot(t[w], th.piston_m[i][w] / m_per, color=c, gid=f"piston:{n}", label=n)
        ax[2].plot(t[w], th.engine_rad[i][w] / rad_per, color=c, gid=f"engine:{n}", label=n)
        ax[3].plot(t[w], th.friction_torque_Nm[i][w] / nm_per, color=c, gid=f"friction:{n}", label=n)
    ax[0].set_ylabel(f"command [{angle_unit}]")
    ax[1].set_ylabel(f"piston x_p [{length_unit}]")
    ax[2].set_ylabel(f"engine angle θ [{angle_unit}]")
    ax[3].set_ylabel(f"friction torque T_f [{tname}]")
    ax[3].set_xlabel("time [s]")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8, loc="upper right")
    prov = getattr(th, "provenance", {}) or {}
    fig.suptitle(wrapped_title(fig, title or f"{prov.get('model_name', '')}  {prov.get('profile', '')}  "
                                        f"(friction {prov.get('friction_model', '?')})".strip()))
    return fig
