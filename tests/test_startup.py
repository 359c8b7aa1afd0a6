"""Start-up stays light: what ``taos --help`` and ``taos info`` import (a structural guard, not
a timing; the times are in benchmarks/RESULTS.md, ``benchmarks/bench_maps.py``).

``taos info`` is linear analysis: it must not import numba (compiled kernels), scipy, pint
(its unit table is remembered after the first run), h5py, casadi or matplotlib. A simulation
command loads the compiled kernels of its own friction law only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

HEAVY = ("numba", "scipy", "pint", "h5py", "casadi", "matplotlib", "meshcat", "pinocchio", "dask")

PROBE = """
import contextlib, io, json, sys
from taos.cli import main
with contextlib.redirect_stdout(io.StringIO()):
    rc = main(sys.argv[1:])
print(json.dumps({"rc": rc, "loaded": [m for m in %r if m in sys.modules],
                  "laws": sorted(m for m in sys.modules if m.startswith("taos.friction._law_"))}))
""" % (HEAVY,)


def _loaded(tmp_path, *argv, **env_more):
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"), **env_more)   # a fresh unit table
    r = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_help_imports_nothing_heavy(tmp_path):
    d = _loaded(tmp_path, "--help")
    assert d["loaded"] == [] and d["laws"] == []


def test_info_is_linear_analysis_without_kernels(tmp_path):
    first = _loaded(tmp_path, "info", "rs25_hotfire")   # a cold unit table asks pint once
    assert first["rc"] == 0 and "numba" not in first["loaded"]
    again = _loaded(tmp_path, "info", "rs25_hotfire")
    assert again == {"rc": 0, "loaded": [], "laws": []}


def test_a_dwell_command_loads_the_kernels_of_its_own_friction_law_only(tmp_path):
    """``taos freqresp`` on a modified-LuGre model with numba's dwell kernels
    (``TAOS_KERNELS=numba``) loads (from numba's cache) the LuGre kernel set only, not every
    built-in law's C callbacks (:mod:`taos.friction._builtin`)."""
    d = _loaded(tmp_path, "freqresp", "rs25_hotfire", "--freq-hz", "1", "--amplitude-deg", "0.1",
                "--json", str(tmp_path / "fr.json"), TAOS_KERNELS="numba")
    assert d["rc"] == 0 and d["laws"] == ["taos.friction._law_lugre"] and "numba" in d["loaded"]


def test_a_dwell_command_on_the_c_kernels_imports_no_numba(tmp_path):
    """With its law's C library in the cache (:mod:`taos.planar._cdwell`; the first run builds
    it, translating the LuGre kernels, so it loads them), ``taos freqresp`` imports none of the
    heavy packages: no numba, no scipy, no law kernels; the result says it ran the C kernels."""
    from taos.planar._cdwell import compiler

    if compiler() is None:
        import pytest

        pytest.skip("no C compiler: the dwells run on numba")
    argv = ("freqresp", "rs25_hotfire", "--freq-hz", "1,3", "--amplitude-deg", "0.1", "--json", str(tmp_path / "fr.json"))
    first = _loaded(tmp_path, *argv, TAOS_KERNELS="c")
    assert first["rc"] == 0 and first["laws"] == ["taos.friction._law_lugre"]
    again = _loaded(tmp_path, *argv, TAOS_KERNELS="c")
    assert again == {"rc": 0, "loaded": [], "laws": []}
    assert json.loads((tmp_path / "fr.json").read_text())["provenance"]["solver"]["kernels"] == "c"


def test_info_steps_adds_the_simulated_figures(tmp_path):
    out = tmp_path / "info.json"
    r = subprocess.run([sys.executable, "-m", "taos", "info", "rs25_hotfire", "--steps", "--json", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    fm = json.loads(out.read_text())["figures_of_merit"]["pitch"]
    assert fm["step"]["threshold_deg"] > 0 and fm["engine"]["bandwidth_3db_hz"] > 0


def test_unit_table_gives_what_pint_gives():
    """The remembered conversion (a value + b per unit) equals pint's own parse of the string."""
    import pint

    from taos.units import DIMENSIONS, to_si
    ureg = pint.UnitRegistry()
    for text, kind in (("115000 lbf/in", "stiffness"), ("144000 in*lbf", "torque"), ("3000 psi", "pressure"),
                       ("15 in**2", "area"), ("-0.4 deg", "angle"), ("40 1/s", "rate"), ("1e-12 m**3/s/Pa",
                       "flow_pressure"), ("0.02 s", "time"), ("120 Hz", "frequency")):
        ref = ureg.Quantity(text).to(DIMENSIONS[kind][1]).magnitude
        assert abs(to_si(text, kind, source="t", field="f") - ref) <= 4e-16 * abs(ref)


def _imports(code: str, names: tuple[str, ...]) -> list[str]:
    probe = f"import json, sys\n{code}\nprint(json.dumps([m for m in {names!r} if m in sys.modules]))"
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_a_monte_carlo_worker_imports_only_what_a_flight_run_uses():
    """A Dask worker of a flight campaign imports the task function and its run kind
    (:func:`taos.montecarlo.engine.run_task`, :class:`taos.montecarlo.run.FlightRuns`): the FCS
    filter's state space is written out (no scipy.signal, which pulls scipy.stats), and the LCO
    root finder (scipy.optimize), the describing-function files (h5py), the flight-file units
    (pint), the fit (casadi) and the plots load where they are used, not with the modules."""
    heavy = ("scipy.signal", "scipy.stats", "scipy.optimize", "h5py", "pint", "casadi", "matplotlib")
    assert _imports("import taos.montecarlo.engine, taos.montecarlo.run", heavy) == []


def test_the_sweep_client_starts_without_kernels():
    """``taos sweep`` imports its driver without numba (the package names resolve on first use;
    numba comes with the first simulation); ``taos lco`` imports the flight loop without
    scipy.signal."""
    assert _imports("import taos.montecarlo.sweep", ("numba", "scipy.signal")) == []
    assert _imports("import taos.flight.lco", ("scipy.signal", "scipy.stats", "h5py", "pint")) == []
