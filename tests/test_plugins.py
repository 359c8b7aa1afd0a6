"""Friction laws as plug-ins (issue 29 point 5): a law in an installed package, registered through
the entry-point group ``taos.friction_laws``, used as ``--friction NAME`` from the command line.

The test builds a tiny plug-in package as a wheel (a zip with its ``.dist-info``), installs it
with pip into a temporary target folder (offline: ``--no-index``), and runs ``taos`` commands in
subprocesses with that folder on ``PYTHONPATH``; the folder goes with the test's temporary
directory. The plug-in law is smooth Coulomb friction, T = T_c v / sqrt(v^2 + v_eps^2), written
in the plug-in's own code: its runs must equal the built-in ``coulomb-smooth`` law's (other
kernels, same physics) to round-off, which is the independent reference. The built-in law's
reference runs need no plug-in: they go through the console script's entry in this process
(:mod:`tests.inprocess`, no second process start-up).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from . import _forkserver
from .conftest import MODELS, ROOT
from .inprocess import taos_json, taos_main

LAW = "plugin-smooth-coulomb"
PKG = "taos_plugin_demo"

PLUGIN_SOURCE = '''"""A friction-law plug-in for taos: smooth Coulomb friction written here."""
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from taos import friction
from taos.errors import InputError
from taos.friction._slots import SLOT_TC, SLOT_VEPS

LAW_ID = "plugin-smooth-coulomb"


@dataclass(frozen=True)
class PluginSmoothCoulomb(friction.FrictionLaw):
    """T = T_c v / sqrt(v^2 + v_eps^2) [N m]; v [rad/s]."""

    name: ClassVar[str] = LAW_ID
    regularization_velocity_rad_s: float = friction.param(1e-3, "regularization_velocity", "angular_velocity",
                                                          SLOT_VEPS)

    def steady_state(self, v):
        v = np.asarray(v, float)
        return self.coulomb_torque_Nm * v / np.sqrt(v * v + self.regularization_velocity_rad_s ** 2)

    def describing_function(self, rate_amplitude, omega_rad_s=None):
        return complex(4.0 * self.coulomb_torque_Nm / (math.pi * rate_amplitude))

    def check_step(self, inertia_kgm2, dt_s, source, section="friction"):
        if dt_s * self.coulomb_torque_Nm / (self.regularization_velocity_rad_s * inertia_kgm2) > 2.0:
            raise InputError(source, f"{section}.regularization_velocity", "dt T_c / (v_eps J) below 2")


def _rates(v, z, t_app, p):
    e = p[SLOT_VEPS]
    return 0.0, p[SLOT_TC] * v / math.sqrt(v * v + e * e)


def _zdot3(w0, w1, z0, z1, p):
    return 0.0, 0.0


def _torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    e = p[SLOT_VEPS]
    a = p[SLOT_TC] / math.sqrt(w0 * w0 + w1 * w1 + e * e)
    return a * w0, a * w1


def entry():
    """The registry entry (the entry point's object): kernels made here, compiled by taos."""
    from numba import njit

    @njit
    def coeffs(s, p, dt, kappa):
        e = p[SLOT_VEPS]
        return p[SLOT_TC] / math.sqrt(s * s + e * e), 0.0

    def bearing(p, Kc, d0, d1, z0, z1, dt, s0):
        return friction.coeff_bearing_step(coeffs, coeffs, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)

    return friction.FrictionLawEntry(
        LAW_ID, PluginSmoothCoulomb, _rates, _zdot3, _torque3, bearing,
        fit_describing_function=lambda law, X, w: (4.0 * law.coulomb_torque_Nm / (math.pi * w * X), 0.0),
        fit_parameters=("coulomb_torque",))
'''


def _wheel(tmp: Path, name: str, files: dict[str, str], entry_points: str) -> Path:
    """A pure-Python wheel (PEP 427) of ``files`` with ``entry_points.txt``."""
    dist = f"{name}-0.1.dist-info"
    files = {**files, f"{dist}/METADATA": f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.1\n",
             f"{dist}/WHEEL": "Wheel-Version: 1.0\nGenerator: taos-test\nRoot-Is-Purelib: true\nTag: py3-none-any\n",
             f"{dist}/entry_points.txt": entry_points}
    files[f"{dist}/RECORD"] = "".join(f"{k},,\n" for k in files) + f"{dist}/RECORD,,\n"
    whl = tmp / f"{name}-0.1-py3-none-any.whl"
    with zipfile.ZipFile(whl, "w") as z:
        for k, v in files.items():
            z.writestr(k, v)
    return whl


def _install(whl: Path, target: Path) -> Path:
    r = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-index", "--no-deps",
                        "--target", str(target), str(whl)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return target


@pytest.fixture(scope="module")
def plugin_path(tmp_path_factory):
    """The plug-in installed by pip into a temporary target folder (removed with the temporary
    directory); returned is that folder, to go on PYTHONPATH."""
    tmp = tmp_path_factory.mktemp("plugin")
    whl = _wheel(tmp, PKG, {f"{PKG}/__init__.py": PLUGIN_SOURCE},
                 f"[taos.friction_laws]\n{LAW} = {PKG}:entry\n")
    target = _install(whl, tmp / "site")
    assert (target / PKG / "__init__.py").is_file()
    assert (target / f"{PKG}-0.1.dist-info" / "entry_points.txt").is_file()
    return target


def taos_with(path: Path, *args, fork: bool = True) -> subprocess.CompletedProcess:
    """``taos ARGS`` as a new process with ``path`` first on PYTHONPATH: forked from a fork server
    started with that environment (:func:`tests._forkserver.run`, ``env``: the plug-in fixture's
    commands share one), or (``fork=False``, a folder used by one test alone) a real process."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(path), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    argv = [str(Path(sys.executable).parent / "taos"), *map(str, args)]
    if fork:
        return _forkserver.run(argv, ROOT, timeout=600, env=env)
    return subprocess.run(argv, capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)


def test_the_installed_plugin_is_listed_and_used_by_info(plugin_path):
    r = taos_with(plugin_path, "info", MODELS / "rs25_hotfire.toml", "--friction", LAW)
    assert r.returncode == 0, r.stderr
    assert f"friction          {LAW}" in r.stdout
    # an unknown law's message lists the plug-in among the known ids (without importing it)
    r = taos_with(plugin_path, "info", MODELS / "rs25_hotfire.toml", "--friction", "no-such-law")
    assert r.returncode == 2 and LAW in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_plugin_law_in_freqresp_equals_the_builtin_law_it_reimplements(plugin_path, tmp_path):
    """Sine dwells (planar integrator, the plug-in's compiled kernel) with the plug-in law against
    the built-in coulomb-smooth law: the same physics in other code, so the same numbers."""
    dwells = ("freqresp", MODELS / "rs25_hotfire.toml", "--amplitude-deg", "0.1", "--freq-hz", "2,6")
    r = taos_with(plugin_path, *dwells, "--friction", LAW, "--json", "-")
    assert r.returncode == 0, r.stderr
    a = json.loads(r.stdout)
    b = taos_json(tmp_path / "builtin.json", *dwells, "--friction", "coulomb-smooth")
    for resp in ("piston", "engine"):
        for k in range(2):
            assert a[resp]["gain_db"][k] == pytest.approx(b[resp]["gain_db"][k], abs=1e-6)
            assert a[resp]["phase_deg"][k] == pytest.approx(b[resp]["phase_deg"][k], abs=1e-5)
    # friction matters here: the frictionless dwell differs (so the agreement is not vacuous)
    none = taos_json(tmp_path / "none.json", *dwells, "--friction", "none")
    assert abs(none["engine"]["gain_db"][0] - b["engine"]["gain_db"][0]) > 0.1


@pytest.mark.slow
def test_plugin_law_in_the_lco_prediction(plugin_path, tmp_path):
    """``taos lco --friction NAME``: the describing-function map uses the plug-in law's kernel."""
    lco = ("lco", MODELS / "rs25_flight.toml", "--flight", MODELS / "flight" / "core_stage.toml", "--no-time-domain",
           "--amplitudes-deg", "0.03,0.3", "--freq-hz", "0.1,0.5,1.5")
    r = taos_with(plugin_path, *lco, "--friction", LAW, "--json", "-")
    assert r.returncode == 0, r.stderr
    res = {LAW: json.loads(r.stdout), "coulomb-smooth": taos_json(tmp_path / "builtin.json", *lco, "--friction",
                                                                  "coulomb-smooth")}
    mt = [x["low_gain_margin_db"] for x in res[LAW]["verdict"]["margin_table"]]
    ref = [x["low_gain_margin_db"] for x in res["coulomb-smooth"]["verdict"]["margin_table"]]
    assert mt == pytest.approx(ref, abs=1e-6)


def test_a_broken_plugin_stops_with_one_line_naming_it(tmp_path):
    whl = _wheel(tmp_path, "taos_broken_plugin", {"taos_broken_plugin/__init__.py": "raise ImportError('missing dep')\n"},
                 "[taos.friction_laws]\nbroken-law = taos_broken_plugin:entry\n")
    target = _install(whl, tmp_path / "site")
    r = taos_with(target, "info", MODELS / "rs25_hotfire.toml", "--friction", "broken-law", fork=False)
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "taos_broken_plugin" in r.stderr and "missing dep" in r.stderr
    # a broken plug-in does not touch models using other laws
    r = taos_with(target, "info", MODELS / "rs25_hotfire.toml", fork=False)
    assert r.returncode == 0, r.stderr


@pytest.mark.slow
def test_plugin_law_in_simulate_fit_and_the_3d_model(plugin_path, tmp_path):
    """The same law through the planar run (``simulate``), the fit's describing function
    (``fit --friction``: the plug-in's fit entry) and the 3-D model's bearing kernel
    (``freqresp --engine taos``), each against the built-in coulomb-smooth law."""
    prof = tmp_path / "dwell.toml"
    prof.write_text('type = "sine_dwell"\namplitude = "0.2 deg"\nfrequency = "2 Hz"\ncycles = 6\n')
    from taos.planar.simulate import TimeHistory
    runs = {}
    for law in (LAW, "coulomb-smooth"):
        out = tmp_path / f"{law}.h5"
        cmd = ("simulate", MODELS / "rs25_hotfire.toml", "--friction", law, "--profile", prof, "--out", out)
        if law == LAW:
            r = taos_with(plugin_path, *cmd)
            assert r.returncode == 0, r.stderr
        else:
            assert taos_main(*cmd) == 0
        runs[law] = TimeHistory.from_hdf5(out).engine_rad
    assert runs[LAW] == pytest.approx(runs["coulomb-smooth"], abs=1e-9)
    fit = ("fit", MODELS / "data" / "greenrun_hotfire_synthetic.csv", "--model", MODELS / "rs25_hotfire.toml",
           "--free", "coulomb_torque", "--starts", "1", "--no-correction")
    r = taos_with(plugin_path, *fit, "--friction", LAW, "--json", "-")
    assert r.returncode == 0, r.stderr
    fits = {LAW: json.loads(r.stdout),
            "coulomb-smooth": taos_json(tmp_path / "fit.json", *fit, "--friction", "coulomb-smooth")}
    fits = {law: d["parameters"]["coulomb_torque"]["value"] for law, d in fits.items()}
    assert fits[LAW] == pytest.approx(fits["coulomb-smooth"], rel=1e-6)
    dwell3 = ("freqresp", MODELS / "rs25_hotfire.toml", "--engine", "taos", "--amplitude-deg", "0.2", "--freq-hz", "3")
    r = taos_with(plugin_path, *dwell3, "--friction", LAW, "--json", "-")
    assert r.returncode == 0, r.stderr
    three = {LAW: json.loads(r.stdout)["engine"]["gain_db"][0],
             "coulomb-smooth": taos_json(tmp_path / "three.json", *dwell3, "--friction", "coulomb-smooth")["engine"]
             ["gain_db"][0]}
    assert three[LAW] == pytest.approx(three["coulomb-smooth"], abs=1e-4)
