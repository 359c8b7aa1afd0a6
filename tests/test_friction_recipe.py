"""Adding a built-in friction law touches only ``taos/friction/`` (issue 38, point 3).

The test follows the recipe of ``docs/developer/adding_a_friction_law.md`` on a copy of the
package: it writes a throwaway law's two files into the copy's ``taos/friction/`` (its
parameter class in ``_params_throwaway.py``, its kernels and registry entry in
``_law_throwaway.py``) and changes nothing else. Run from the copy, the new law is then listed
by the CLI help (``taos lco --help``, ``taos freqresp --help``), the law ids of the registry and
the docs' model-file key reference (its new key with the meaning its parameter declares), and
it runs end to end: a ``taos freqresp`` sine dwell, planar and 3-D, and its describing function
in the three forms (analytic, numeric, fit) through the Python API.

The throwaway law is T = c v + T_c v / sqrt(v^2 + v_eps^2), viscous damping plus the smooth
Coulomb law; with c = 0 it is exactly the built-in ``coulomb-smooth`` law, so its runs must
reproduce that law's runs (the physics reference). The copy keeps the package's ``__pycache__``
(numba's on-disk cache, valid for sources whose time stamp the copy keeps), so only the new
law's own kernels compile.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import taos

from . import _forkserver
from .conftest import ROOT

pytestmark = pytest.mark.slow

LAW = "throwaway-viscous-coulomb"

PARAMS = textwrap.dedent('''\
    """Throwaway test law (tests/test_friction_recipe.py): its parameter class (no numba here)."""

    from __future__ import annotations

    import math
    from dataclasses import dataclass
    from typing import ClassVar

    import numpy as np

    from ..errors import InputError
    from . import _slots as K
    from ._laws import FrictionLaw, param


    @dataclass(frozen=True)
    class ThrowawayViscousCoulomb(FrictionLaw):
        """T = c v + T_c v / sqrt(v^2 + v_eps^2)."""

        name: ClassVar[str] = "throwaway-viscous-coulomb"
        kernels: ClassVar[str] = "_law_throwaway"

        throwaway_damping_Nms_per_rad: float = param(0.0, "throwaway_damping", "rotational_damping", K.SLOT_SIGMA2,
                                                     torque_like=True, meaning="viscous damping c of the throwaway law")
        regularization_velocity_rad_s: float = param(1e-3, "regularization_velocity", "angular_velocity",
                                                     K.SLOT_VEPS)

        def steady_state(self, v):
            v = np.asarray(v, float)
            e = self.regularization_velocity_rad_s
            return self.throwaway_damping_Nms_per_rad * v + self.coulomb_torque_Nm * v / np.sqrt(v * v + e * e)

        def describing_function(self, rate_amplitude, omega_rad_s=None):
            return complex(self.throwaway_damping_Nms_per_rad + 4 * self.coulomb_torque_Nm / (math.pi * rate_amplitude))

        def check_step(self, inertia_kgm2, dt_s, source, section="friction"):
            slope = self.throwaway_damping_Nms_per_rad + self.coulomb_torque_Nm / self.regularization_velocity_rad_s
            if dt_s * slope / inertia_kgm2 > 2.0:
                raise InputError(source, f"{section}.regularization_velocity", "dt (c + T_c / v_eps) / J below 2")

        def validate(self, source, section="friction"):
            if not self.regularization_velocity_rad_s > 0:
                raise InputError(source, f"{section}.regularization_velocity", "a positive angular velocity")
    ''')

KERNELS = textwrap.dedent('''\
    """Throwaway test law (tests/test_friction_recipe.py): its kernels and registry entry."""

    from __future__ import annotations

    import math

    from numba import njit

    from . import _kernels as K
    from . import _vector as V
    from ._builtin import kernel
    from ._law_zero import zero_zdot3
    from ._params_throwaway import ThrowawayViscousCoulomb
    from .registry import FrictionLawEntry


    @njit(cache=True, inline="always")
    def _coeffs(s, p, dt, kappa):   # T = a(|w|) w, memoryless
        e = p[K.SLOT_VEPS]
        return p[K.SLOT_SIGMA2] + p[K.SLOT_TC] / math.sqrt(s * s + e * e), 0.0


    @kernel("RATES_SIG")
    def throwaway_rates(v, z, t_app, p):
        e = p[K.SLOT_VEPS]
        return 0.0, p[K.SLOT_SIGMA2] * v + p[K.SLOT_TC] * v / math.sqrt(v * v + e * e)


    @kernel("TORQUE3_SIG")
    def throwaway_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
        a, _ = _coeffs(math.sqrt(w0 * w0 + w1 * w1), p, 0.0, 1.0)
        return a * w0, a * w1


    @kernel("BEARING_SIG")
    def throwaway_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
        return V.coeff_bearing_step(_coeffs, V.lugre_rho, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


    def _fit_df(law, X, w):
        return law.throwaway_damping_Nms_per_rad + 4 * law.coulomb_torque_Nm / (math.pi * w * X), 0.0


    ENTRIES = (FrictionLawEntry("throwaway-viscous-coulomb", ThrowawayViscousCoulomb, throwaway_rates, zero_zdot3,
                                throwaway_torque3, throwaway_bearing, fit_describing_function=_fit_df,
                                fit_parameters=("coulomb_torque",)),)
    ''')

API_PROBE = textwrap.dedent('''\
    import json, math, sys
    import taos
    from taos import friction
    from taos.model import load_model

    e = friction.get(sys.argv[1])
    law = load_model(sys.argv[2], friction=sys.argv[1]).friction
    law = type(law)(coulomb_torque_Nm=law.coulomb_torque_Nm, throwaway_damping_Nms_per_rad=2e5,
                    regularization_velocity_rad_s=1e-6)
    V, f = 0.05, 1.0
    w = 2 * math.pi * f
    n = law.rate_describing_function(V, w)
    num = law.numeric_describing_function(V, f)
    fit = e.fit_describing_function(law, V / w, w)
    print(json.dumps({"file": taos.__file__, "ids": list(friction.ids()), "builtin": e.builtin,
                      "analytic": [n.real, n.imag], "numeric": [num.real, num.imag], "fit": list(map(float, fit))}))
    ''')

KEYS_PROBE = textwrap.dedent('''\
    import json
    from taosdocs import reference
    missing = []
    text = reference.model_keys_markdown(missing)
    print(json.dumps({"missing": missing, "stale": reference.stale_meanings(), "text": text}))
    ''')


def _source_files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*")
            if p.is_file() and "__pycache__" not in p.parts}


@pytest.fixture(scope="module")
def copy(tmp_path_factory):
    """A copy of the package with the throwaway law's two files added to taos/friction/, beside
    links to the shipped models (read from the package's parent folder in a source checkout)."""
    root = tmp_path_factory.mktemp("recipe")
    shutil.copytree(Path(taos.__file__).parent, root / "taos", copy_function=shutil.copy2)
    for name in ("models", "fem_data"):
        (root / name).symlink_to(ROOT / name, target_is_directory=True)
    (root / "taos" / "friction" / "_params_throwaway.py").write_text(PARAMS, encoding="utf-8")
    (root / "taos" / "friction" / "_law_throwaway.py").write_text(KERNELS, encoding="utf-8")
    return root


def _run(copy: Path, *argv, extra_path: str = "") -> subprocess.CompletedProcess:
    """``python ARGV`` in the copy with the copy (and ``extra_path``) on PYTHONPATH, as a new
    process: forked from a fork server started with that environment (the copy's commands share
    it: :func:`tests._forkserver.run`, ``env``), a real process for the one run with ``extra_path``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in (str(copy), extra_path) if p))
    if not extra_path:
        r = _forkserver.run([sys.executable, *argv], copy, timeout=900, env=env)
    else:
        r = subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=copy, env=env, timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    return r


def _words(text: str) -> str:
    """Help text with argparse's line wrapping undone (it breaks lines after a hyphen)."""
    return re.sub(r"-\s+", "-", " ".join(text.split()))


def test_only_taos_friction_changed(copy):
    """The copy differs from the package by the two new files in taos/friction/ alone."""
    a, b = _source_files(Path(taos.__file__).parent), _source_files(copy / "taos")
    changed = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    assert changed == ["friction/_law_throwaway.py", "friction/_params_throwaway.py"]


HELP_COMMANDS = ("info", "freqresp", "simulate", "greenrun", "fit", "lco", "sweep", "fmu")
#: each command's ``--help`` text through the console script's entry, one process for them all
HELP_PROBE = textwrap.dedent('''
    import contextlib, io, json, sys
    from taos.cli import main
    out = {}
    for command in sys.argv[1:]:
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            try:
                main([command, "--help"])
            except SystemExit as e:
                assert e.code in (0, None), e.code
        out[command] = buf.getvalue()
    print(json.dumps(out))
''')


@pytest.fixture(scope="module")
def helps(copy):
    """{command: its --help text} of the copy, one process for every command (the same texts as
    ``python -m taos COMMAND --help`` each, without eight interpreter start-ups)."""
    return json.loads(_run(copy, "-c", HELP_PROBE, *HELP_COMMANDS).stdout.splitlines()[-1])


@pytest.mark.parametrize("command", HELP_COMMANDS)
def test_the_cli_help_lists_the_new_law(helps, command):
    out = _words(helps[command])
    assert LAW in out and "coulomb-smooth" in out


def test_the_docs_key_reference_has_the_new_law_and_its_key(copy):
    d = json.loads(_run(copy, "-c", KEYS_PROBE, extra_path=str(ROOT / "docs" / "_ext")).stdout.strip().splitlines()[-1])
    assert d["missing"] == [] and d["stale"] == []
    model_row = next(ln for ln in d["text"].splitlines() if ln.startswith("| `model` | name |"))
    assert LAW in model_row
    key_row = next(ln for ln in d["text"].splitlines() if ln.startswith("| `throwaway_damping` |"))
    assert LAW in key_row and "viscous damping c of the throwaway law" in key_row


def test_the_python_api_has_the_law_and_its_describing_function(copy):
    d = json.loads(_run(copy, "-c", API_PROBE, LAW, str(ROOT / "models" / "rs25_hotfire.toml")).stdout.splitlines()[-1])
    assert Path(d["file"]).resolve().parent == (copy / "taos").resolve()
    assert d["ids"][-1] == LAW and d["builtin"]   # after the shipped laws: their order is unchanged
    ana, num, fit = (complex(*d[k]) for k in ("analytic", "numeric", "fit"))
    assert fit == pytest.approx(ana, rel=1e-12)
    assert abs(num - ana) <= 3e-3 * abs(ana)


@pytest.mark.parametrize("engine", ["simplex", "taos"])
def test_a_sine_dwell_with_the_new_law_equals_coulomb_smooth_at_zero_damping(copy, tmp_path, engine):
    """``taos freqresp --friction LAW`` runs (planar and 3-D) and, with c = 0 (the shipped
    file has no ``throwaway_damping``), gives the built-in coulomb-smooth law's response."""
    runs = {}
    for law in (LAW, "coulomb-smooth"):
        out = tmp_path / f"{law}.json"
        _run(copy, "-m", "taos", "freqresp", "rs25_hotfire", "--engine", engine, "--freq-hz", "2",
             "--amplitude-deg", "0.2", "--friction", law, "--json", str(out))
        runs[law] = json.loads(out.read_text())
    a, b = runs[LAW], runs["coulomb-smooth"]

    def numbers(d):
        if isinstance(d, dict):
            return [x for k, v in sorted(d.items()) if k not in ("provenance", "friction_model") for x in numbers(v)]
        if isinstance(d, list):
            return [x for v in d for x in numbers(v)]
        return [d] if isinstance(d, float) else []

    na, nb = numbers(a), numbers(b)
    assert len(na) == len(nb) > 0
    assert na == pytest.approx(nb, rel=1e-9, abs=1e-12)
