"""The C dwell kernels (:mod:`taos.planar._cdwell`) against numba's, their reference.

The C is the translation of the numba kernels' own source, compiled with IEEE arithmetic; numba
compiles the dwell kernels with reassociation and FMA contraction. Measured (rs25_flight, six
dwells 0.05-0.8 deg, 0.2-10 Hz, each built-in law): the complex piston and engine responses agree
to 7e-15 relative for the smooth laws (none, coulomb-smooth, Dahl, LuGre, modified LuGre) and to
3.1e-8 for the switching Coulomb law (its stick band switches on a comparison, which a rounding
difference can move by a step); the matrix exponential (not fast-math in numba either) and the
step plan are the same bits.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from taos.friction._builtin import modules
from taos.model import load_model
from taos.planar import _cdwell
from taos.planar._expcoef import _balance, exp_steps_per_cycle
from taos.planar.freqresp import sine_dwell_points

pytestmark = pytest.mark.skipif(_cdwell.compiler() is None, reason="no C compiler (the C dwells fall back to numba)")

#: relative agreement of the responses: smooth laws / the switching Coulomb law (module docstring)
TOL = {"coulomb-switching": 1e-6}
TOL_SMOOTH = 5e-14
AMPS_DEG = (0.05, 0.2, 0.8, 0.05, 0.2, 0.8)
FREQS_HZ = (0.2, 1.0, 5.0, 2.0, 0.5, 10.0)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A private library cache (XDG_CACHE_HOME) for this module's builds."""
    d = tmp_path_factory.mktemp("xdg")
    old = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(d)
    _cdwell._LOADED.clear()
    yield d
    _cdwell._LOADED.clear()
    if old is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = old


def _points(model, engine, monkeypatch):
    monkeypatch.setenv(_cdwell.ENV, engine)
    return sine_dwell_points(model, np.radians(AMPS_DEG), np.array(FREQS_HZ))


@pytest.mark.parametrize("law", sorted(modules()))
def test_c_dwells_agree_with_numba(cache, law, monkeypatch):
    m = load_model("rs25_flight", friction=law)
    c, n = _points(m, "c", monkeypatch), _points(m, "numba", monkeypatch)
    assert c.solver["kernels"] == "c" and n.solver["kernels"] == "numba"
    tol = TOL.get(law, TOL_SMOOTH)
    for k in ("piston", "engine"):
        a, b = getattr(c, k), getattr(n, k)
        assert np.all(np.abs(a - b) <= tol * np.abs(b)), (k, np.max(np.abs(a - b) / np.abs(b)))


def test_expm_and_step_plan_are_the_same_bits(cache, monkeypatch):
    from taos.planar import _expplan, _expstep
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import kernel_args

    m = load_model("rs25_flight", friction="lugre")
    ck = _cdwell.load("lugre")
    plant = simplex_plant(m, "pitch")
    args = kernel_args(plant, m)
    W = np.zeros((4 * 8, 4 * 8))
    W[:8, :8] = 1e-3 * args.A[:8, :8]
    W[:8, 8:16] = np.eye(8)
    assert np.array_equal(ck.expm(W), _expstep.expm_small(W))
    A, F = np.radians(AMPS_DEG), np.array(FREQS_HZ)
    plan = [exp_steps_per_cycle(args, m, plant.inertia_kgm2, A, F, 2e-4, 64, ks) for ks in (ck, _expplan.NUMBA)]
    assert np.array_equal(*plan)


def test_balance_is_lapack_gebal_on_every_shipped_model():
    """The numpy dgebal (no scipy on the C path) gives scipy's scaling, bit for bit."""
    from scipy.linalg import matrix_balance

    from taos.planar.simplex import simplex_plant
    from taos.shipped import shipped_names

    for name in shipped_names():
        try:
            m = load_model(name)
        except Exception:   # a 3-D or vehicle file: not a planar model
            continue
        for ax in ("pitch", "yaw"):
            A = simplex_plant(m, ax).ss.A
            assert np.array_equal(_balance(A), matrix_balance(A, permute=False, separate=True)[1][0]), (name, ax)


def test_balance_is_lapack_gebal_on_wide_ranging_matrices():
    from scipy.linalg import matrix_balance

    rng = np.random.default_rng(1)
    for _ in range(200):
        n = int(rng.integers(2, 12))
        A = rng.standard_normal((n, n)) * 10.0 ** rng.uniform(-6, 10, (n, n))
        A[rng.random((n, n)) < 0.4] = 0.0
        assert np.array_equal(_balance(A), matrix_balance(A, permute=False, separate=True)[1][0])


def test_cache_key_names_sources_compiler_and_machine(monkeypatch):
    cc = _cdwell.compiler()
    k = _cdwell.cache_key("lugre", cc)
    assert k != _cdwell.cache_key("dahl", cc)
    monkeypatch.setattr(_cdwell, "_cpu", lambda: "another CPU")
    assert _cdwell.cache_key("lugre", cc) != k
    monkeypatch.setattr(_cdwell, "CFLAGS", _cdwell.CFLAGS + ("-O3",))
    assert _cdwell.cache_key("lugre", cc) != k


def test_a_foreign_library_is_not_loaded(cache):
    """A library under another key (another machine, compiler or source) is never looked up:
    the cache's own key is rebuilt."""
    _cdwell._LOADED.clear()
    folder = _cdwell.cache_dir()
    key = _cdwell.cache_key("dahl", _cdwell.compiler())
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "0123456789abcdef0123456789abcdef.so").write_bytes(b"not a library")
    ks = _cdwell.load("dahl")
    assert ks.name == "c" and (folder / f"{key}.json").is_file()
    man = json.loads((folder / f"{key}.json").read_text())
    src, _ = _cdwell.c_source("dahl")
    assert man["c_sha256"] == __import__("hashlib").sha256(src.encode()).hexdigest()


def test_a_damaged_library_is_rebuilt_and_a_failed_build_remembered(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))   # paths this process has not loaded
    monkeypatch.setattr(_cdwell, "_LOADED", {})
    folder = _cdwell.cache_dir()
    key = _cdwell.cache_key("none", _cdwell.compiler())
    _cdwell.build("none", folder)
    (folder / f"{key}.so").write_bytes(b"damaged")
    assert _cdwell.load("none").name == "c"          # rebuilt
    assert (folder / f"{key}.so").read_bytes() != b"damaged"
    _cdwell._LOADED.clear()
    (folder / f"{key}.json").unlink()
    calls, real_build = [], _cdwell.build

    def failing(law, folder=None):
        calls.append(law)
        raise _cdwell.CUnavailable("the compiler failed")
    monkeypatch.setattr(_cdwell, "build", failing)
    for _ in range(2):
        with pytest.raises(_cdwell.CUnavailable, match="the compiler failed"):
            _cdwell.load("none")
    assert calls == ["none"] and (folder / f"{key}.failed").is_file()   # tried once, then remembered
    monkeypatch.setattr(_cdwell, "build", real_build)
    assert _cdwell.load("none", retry=True).name == "c" and not (folder / f"{key}.failed").exists()


def test_fallbacks_say_why(cache, monkeypatch):
    m = load_model("rs25_flight", friction="dahl")
    monkeypatch.setenv(_cdwell.ENV, "numba")
    assert _cdwell.dwell_kernels(m).provenance == {"kernels": "numba"}
    monkeypatch.setenv(_cdwell.ENV, "c")
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setattr(_cdwell, "_LOADED", {})
    ks = _cdwell.dwell_kernels(m)
    assert ks.provenance["kernels"] == "numba" and "nonexistent" in ks.provenance["c_unavailable"]
    pts = sine_dwell_points(m, [math.radians(0.2)], [1.0])
    assert pts.solver["kernels"] == "numba"


def test_the_command_output_matches_and_names_its_kernels(cache, tmp_path):
    out = {}
    for eng in ("c", "numba"):
        env = dict(os.environ, TAOS_KERNELS=eng)
        r = subprocess.run([sys.executable, "-m", "taos", "freqresp", "rs25_flight", "--friction", "lugre",
                            "--freq-hz", "0.2,1,5", "--amplitude-deg", "0.05,0.4", "--json", str(tmp_path / f"{eng}.json")],
                           capture_output=True, text=True, env=env, timeout=600)
        assert r.returncode == 0, r.stderr
        out[eng] = json.loads((tmp_path / f"{eng}.json").read_text())
    c, n = out["c"], out["numba"]
    assert c["provenance"]["solver"].pop("kernels") == "c" and "ctypes" in c["provenance"]["solver"].pop("kernels_how")
    assert n["provenance"]["solver"].pop("kernels") == "numba"
    for k in ("piston", "engine"):
        for q in ("gain_db", "phase_deg"):
            assert np.allclose(c[k][q], n[k][q], rtol=0, atol=1e-11), (k, q)
    for d in (c, n):
        for k in ("piston", "engine"):
            d.pop(k)
    assert c == n


def test_a_build_prunes_libraries_unused_for_30_days_and_nothing_else(tmp_path, monkeypatch):
    """The cache does not grow with every kernel change: a build removes the libraries (all
    their files) whose newest file is older than PRUNE_AFTER_S, and killed builds' folders as
    old; a recently used library, the one just built and files not of this module stay. A load
    marks the manifest it used, so a library in use is never the oldest."""
    import time

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(_cdwell, "_LOADED", {})
    folder = _cdwell.cache_dir()
    folder.mkdir(parents=True)
    old = time.time() - _cdwell.PRUNE_AFTER_S - 86400.0
    stale, fresh = "a" * 32, "b" * 32
    for k in (stale, fresh):
        for ext in ("so", "json", "failed"):
            (folder / f"{k}.{ext}").write_text(k)
    (folder / "notes.txt").write_text("not ours")
    (folder / ".build-killed").mkdir()
    for f in [*folder.glob(f"{stale}.*"), folder / "notes.txt", folder / ".build-killed", folder / f"{fresh}.so"]:
        os.utime(f, (old, old))   # the fresh library: its .so old, its manifest used recently
    key = _cdwell.cache_key("none", _cdwell.compiler())
    _cdwell.build("none", folder)
    left = sorted(p.name for p in folder.iterdir())
    assert left == sorted(["notes.txt", f"{fresh}.so", f"{fresh}.json", f"{fresh}.failed", f"{key}.so", f"{key}.json"])
    # a load marks its manifest: made old, loaded, it is recent again
    os.utime(folder / f"{key}.json", (old, old))
    assert _cdwell.load("none").name == "c"
    assert time.time() - (folder / f"{key}.json").stat().st_mtime < 60
    assert _cdwell.prune(folder, keep="none of these") == []   # nothing older than 30 days is left
