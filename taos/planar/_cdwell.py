"""The sine-dwell kernels as C, compiled once on this machine and loaded with ctypes: a dwell
command (``taos freqresp --amplitude-deg ...``) starts without importing numba.

What runs. The C is not a second copy of the dynamics: it is the translation
(:mod:`taos.cosim._ccode`, the standalone FMUs' translator) of the numba kernels' own Python
source, the same functions numba compiles: :func:`taos.planar._expstep.dwell_batch` (the ETDRK4
dwells, with the friction law's ``rates`` bound at translation time, the avionics and the
limits), :func:`taos.planar._expstep.expm_into` (the matrix exponential of the phi-functions and
the command table), :func:`taos.planar._expplan._friction_rate` and
:func:`taos.friction._kernels.prescribed_rate_fill` (the step plan). The Python around them is
:mod:`taos.planar._expcoef`, which both engines share (:class:`CKernels` is its kernel set).

Numbers. The C is compiled with standard IEEE arithmetic (``-O2 -ffp-contract=off``, no
fast-math); numba compiles the dwell kernels with reassociation and FMA contraction
(``taos.planar._expstep._FM``) and the matrix exponential and the step plan without. So the
coefficient matrices and the step plan are the same bits on both paths, and the dwells differ
at the rounding level only (``tests/test_cdwell.py`` states the figure and checks it).

The cache. One shared library per friction law in ``$XDG_CACHE_HOME/taos/ckernels`` (default
``~/.cache/taos/ckernels``), named by a SHA-256 (:func:`cache_key`) of everything the library
is made from: the Python source of every module the C is translated from (the kernels, the
law's module, the translator, this module), the C compiler (its resolved path, size and
modification time), the compiler flags, the machine and the CPU (``/proc/cpuinfo``'s model and
flags) and Python's version. A changed kernel, compiler or machine gives another name, so a
stale or foreign library is never loaded: it is rebuilt. Building (:func:`build`) imports numba
(the translator reads the kernels through their dispatchers), writes the C, runs the compiler
into a temporary file and renames it into place (a concurrent build or a kill leaves no half
library); the manifest beside it records the entries' argument kinds, the compiler's version
and the SHA-256 of the generated C. ``python -m taos.cli.warmup`` (run by ``make``) builds the built-in laws' libraries; a
command that finds none builds its own law's on first use (about a second), so the first run
works too. The warm-up builds ONE library holding every built-in law's entries instead
(:func:`build_all`, keyed by :func:`cache_key_all`; each law's entries carry the law's name as
a suffix): the code the laws share (the matrix exponential, the avionics, the limits, the step
plan's pieces) is compiled once, and the compiler started once, which halves the C compile's
CPU time. :func:`load` uses a law's own library when there is one, else that shared one. The C
of each function is the same text in both, compiled with the same flags (IEEE arithmetic, no
contraction): the same numbers either way.

Every load marks the library's manifest as used (its modification time); each build then removes
the libraries of this cache not used for :data:`PRUNE_AFTER_S` (:func:`prune`: those of a source,
compiler or machine no longer current), so the cache does not grow with every change of the
kernels. Only this module's own files are touched (``KEY.so``, ``KEY.json``, ``KEY.failed`` with
a 32-digit key, and its ``.build-*`` folders).

When numba runs instead (:func:`dwell_kernels` returns :data:`taos.planar._expplan.NUMBA`): the
environment sets ``TAOS_KERNELS=numba``; the law is not a built-in one (a plug-in or a law
registered at run time: its kernel may not be translatable); no C compiler (``$CC``, ``cc``,
``gcc``); or the build or the load fails. The results' ``solver.kernels`` provenance says which
engine produced the numbers (and, for numba after a failure, why).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

#: the environment variable choosing the dwell kernels: ``c`` (default) or ``numba``
ENV = "TAOS_KERNELS"
ENGINES = ("c", "numba")
#: the C compiler's flags: IEEE arithmetic (no fast-math, no FMA contraction)
CFLAGS = ("-std=c99", "-O2", "-fPIC", "-shared", "-ffp-contract=off", "-fno-math-errno")
#: the modules (relative to the ``taos`` package) the C is translated from, besides the law's own
#: (and those that define what the kernels read: the parameter packs, the limits' layout)
SOURCES = ("planar/_expstep.py", "planar/_expplan.py", "planar/dynamics.py", "planar/saturation.py",
           "planar/_limits_pack.py", "planar/_avionics_kernels.py", "planar/_avionics_slots.py",
           "friction/_kernels.py", "friction/_slots.py", "friction/_vector.py", "friction/_builtin.py",
           "friction/_laws.py", "cosim/_ccode.py", "cosim/_ccode_func.py",
           "cosim/_ccode_stmt.py", "planar/_cdwell.py")
ROOT = Path(__file__).resolve().parents[1]
#: a library not loaded for this long [s] (30 days) is removed by the next build (module docstring)
PRUNE_AFTER_S = 30 * 86400.0
_LOCK = threading.Lock()
_LOADED: dict[str, "CKernels"] = {}


class CUnavailable(Exception):
    """The C path cannot run (the message says why); numba's kernels run instead."""


def compiler() -> str | None:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on the PATH (None: none)."""
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


def _cpu() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            lines = f.read().split("\n\n", 1)[0].splitlines()
        return "|".join(ln for ln in lines if ln.split(":")[0].strip() in ("vendor_id", "model name", "flags"))
    except OSError:
        return platform.processor()


def law_module(law: str) -> str:
    """The module file (relative to ``taos``) of built-in law ``law``'s kernels; raises
    :class:`CUnavailable` for a law that is not built in."""
    from ..friction._builtin import modules

    mod = modules().get(law)
    if mod is None:
        raise CUnavailable(f"friction law {law!r} is not a built-in law (its kernel is not translated)")
    return "friction/" + mod.lstrip(".") + ".py"


def cache_key(law: str, cc: str) -> str:
    """SHA-256 naming the library of ``law`` built by ``cc`` on this machine (module docstring)."""
    return _key((law,), law, cc)


def cache_key_all(cc: str) -> str:
    """SHA-256 naming the library of every built-in law (:func:`build_all`) built by ``cc``: as
    :func:`cache_key`, over every law's name and module."""
    from ..friction._builtin import modules

    return _key(tuple(sorted(modules())), "all", cc)


def _key(laws: tuple[str, ...], name: str, cc: str) -> str:
    h = hashlib.sha256()
    for rel in SOURCES + tuple(dict.fromkeys(law_module(law) for law in laws)):
        h.update(rel.encode() + b"\0" + (ROOT / rel).read_bytes() + b"\0")
    exe = Path(shutil.which(cc) or cc).resolve()
    st = exe.stat()
    for part in (name, *(laws if len(laws) > 1 else ()), str(exe), str(st.st_size), str(st.st_mtime_ns),
                 " ".join(CFLAGS), platform.machine(), _cpu(), "%d.%d" % sys.version_info[:2]):
        h.update(part.encode() + b"\0")
    return h.hexdigest()[:32]


def _suffix(law: str) -> str:
    """The C-name suffix of law ``law``'s entries in the library of every law."""
    return "_" + "".join(ch if ch.isalnum() else "_" for ch in law)


def cache_dir() -> Path:
    from ..units import cache_folder

    return cache_folder() / "ckernels"


def _samples(law: str):
    """Sample arguments fixing each entry's argument kinds (:func:`taos.cosim._ccode.kind_of`)
    and the law's kernel (bound in the C)."""
    from ..friction import registry

    fid = registry.get(law).rates
    v, m2, m3, iv = np.zeros(8), np.zeros((8, 8)), np.zeros((1, 8, 8)), np.zeros(1, np.int64)
    plant = (m2, m2, v, v, v, v, v, v, v)                    # A, Br, bc, bf, cc, dc, cw, ca, lim
    return {
        "taos_expm": ("expm_into", (m2, m2, m2, m2, m2)),
        "taos_rate_fill": ("prescribed_rate_fill", (fid, v, v, 0.0, 0.0, v, v)),
        "taos_friction_rate": ("_friction_rate", (fid, v, v, v, v, 0.0, 0.0)),
        "taos_dwell_batch": ("dwell_batch", (*plant, m2, fid, v, v, *(m3,) * 6, m3, m3, iv, iv, iv, v, v, iv, iv, iv,
                                             m3, iv, 0, 0)),
    }


def c_source(law: str) -> tuple[str, dict]:
    """(C source, entries) of law ``law``'s dwell library; entries: C name -> its argument kinds
    (``arr1``, ``arr2``, ``arr3``, ``iarr1``, ``double``, ``long``, ``fn``: bound, no C
    argument) and its C return type. Imports the kernels (numba)."""
    src, entries = _c_source((law,), "")
    return src, entries[law]


def _c_source(laws: tuple[str, ...], suffix: str | None) -> tuple[str, dict]:
    """(C source, {law: entries}) of one library holding the entries of ``laws`` (:func:`c_source`);
    each law's entries named with ``suffix`` (``""``) or its :func:`_suffix` (None), their C
    symbol in ``"symbol"``. One translator: a function the laws share is written once."""
    from ..cosim._ccode import Translator
    from ..friction import _kernels as K
    from . import _expplan as _pl
    from . import _expstep as _ex

    where = {"expm_into": _ex, "prescribed_rate_fill": K, "_friction_rate": _pl, "dwell_batch": _ex}
    tr = Translator()
    out = {}
    for law in laws:
        entries = out[law] = {}
        sym = _suffix(law) if suffix is None else suffix
        for cname, (fn, samples) in _samples(law).items():
            spec = tr.entry(getattr(where[fn], fn), samples, cname + sym)
            entries[cname] = {"args": [k if isinstance(k, str) else k[0] for k in spec.kinds], "ret": spec.ret}
            if sym:   # an entry without the law's kernel (the matrix exponential) is the first law's
                entries[cname]["symbol"] = spec.cname
    head = (f"/* Generated by taos.planar._cdwell from the numba kernels' Python source (taos.cosim._ccode); "
            f"friction law{'s' if len(laws) > 1 else ''} {', '.join(laws)}. Do not edit. */\n")
    return head + tr.source(), out


def build(law: str, folder: Path | None = None) -> Path:
    """Translate, compile and store law ``law``'s library (module docstring); returns its path."""
    cc = compiler()
    if not cc:
        raise CUnavailable("no C compiler ($CC, cc or gcc)")
    src, entries = c_source(law)
    return _compile(cc, cache_key(law, cc), law, src, {"law": law, "entries": entries}, folder)


def build_all(folder: Path | None = None) -> Path:
    """Translate, compile and store the library of every built-in law (module docstring: one
    compile of the code the laws share); returns its path. Its manifest's ``laws`` holds each
    law's entries (:func:`c_source`'s, with their C ``symbol``)."""
    from ..friction._builtin import modules

    cc = compiler()
    if not cc:
        raise CUnavailable("no C compiler ($CC, cc or gcc)")
    src, laws = _c_source(tuple(sorted(modules())), None)
    return _compile(cc, cache_key_all(cc), "all", src, {"law": "all", "laws": laws}, folder)


def _compile(cc: str, key: str, name: str, src: str, manifest: dict, folder: Path | None) -> Path:
    """Compile ``src`` into ``folder``/KEY.so and write its manifest KEY.json (``manifest`` plus
    the compiler, flags, the C's SHA-256, the machine) last."""
    folder = cache_dir() if folder is None else folder
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder, prefix=".build-") as tmp:
        c, so = Path(tmp) / f"{name}.c", Path(tmp) / f"{key}.so"
        c.write_text(src)
        r = subprocess.run([cc, *CFLAGS, str(c), "-o", str(so), "-lm"], capture_output=True, text=True, check=False)
        if r.returncode != 0:
            raise CUnavailable(f"{cc} failed on the dwell kernels: {r.stderr.strip()[-500:]}")
        ver = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False).stdout.split("\n")[0]
        manifest = {**manifest, "compiler": ver, "cflags": list(CFLAGS),
                    "c_sha256": hashlib.sha256(src.encode()).hexdigest(), "machine": platform.machine()}
        (Path(tmp) / "m.json").write_text(json.dumps(manifest, indent=1))
        os.replace(so, folder / f"{key}.so")
        os.replace(Path(tmp) / "m.json", folder / f"{key}.json")   # written last: the library is complete
    prune(folder, keep=key)
    return folder / f"{key}.so"


def prune(folder: Path, keep: str, max_age_s: float = PRUNE_AFTER_S, now: float | None = None) -> list[str]:
    """Remove from ``folder`` every library (``KEY.so``, ``KEY.json``, ``KEY.failed``) other than
    ``keep`` whose newest file is older than ``max_age_s`` [s] at ``now`` [s, Unix time; default:
    the clock], and this module's ``.build-*`` folders as old (a killed build's); returns the keys
    removed. A load marks its manifest (:func:`_mark_used`), so a library in use stays; nothing
    else in ``folder`` is touched; a file another process removes first is skipped."""
    import re
    import time

    now = time.time() if now is None else now
    ages: dict[str, float] = {}
    try:
        names = list(folder.iterdir())
    except OSError:
        return []
    for f in names:
        m = re.fullmatch(r"([0-9a-f]{32})\.(so|json|failed)", f.name)
        try:
            if m and m.group(1) != keep:
                ages[m.group(1)] = max(ages.get(m.group(1), -float("inf")), f.stat().st_mtime)
            elif f.name.startswith(".build-") and f.is_dir() and now - f.stat().st_mtime > max_age_s:
                shutil.rmtree(f, ignore_errors=True)
        except OSError:
            continue
    gone = sorted(k for k, t in ages.items() if now - t > max_age_s)
    for k in gone:
        for ext in ("json", "so", "failed"):   # the manifest first: a half-removed library is not loaded
            (folder / f"{k}.{ext}").unlink(missing_ok=True)
    return gone


def _mark_used(manifest: Path) -> None:
    """Mark the library of ``manifest`` as used now (its modification time; :func:`prune`)."""
    try:
        os.utime(manifest)
    except OSError:   # a read-only cache: the library is used all the same
        pass


class CKernels:
    """The dwell kernel set (:class:`taos.planar._expcoef.KernelSet`) of one law's C library."""

    name = "c"

    def __init__(self, path: Path, manifest: dict, law: str | None = None):
        import ctypes

        self._lib = ctypes.CDLL(str(path))   # CDLL releases the GIL during a call: dwells run on threads
        self._kinds = {}
        ct = {"double": ctypes.c_double, "long": ctypes.c_long, "void": None}
        # a law's own library, or its entries in the library of every law (law given)
        entries = manifest["entries"] if law is None else manifest["laws"][law]
        for cname, e in entries.items():
            f = getattr(self._lib, e.get("symbol", cname))
            argt = []
            for k in e["args"]:
                if k in ("arr1", "iarr1"):
                    argt += [ctypes.c_void_p, ctypes.c_long]
                elif k in ("arr2", "arr3"):
                    argt += [ctypes.c_void_p] + [ctypes.c_long] * int(k[-1])
                elif k in ct:
                    argt.append(ct[k])
            f.argtypes, f.restype = argt, ct[e["ret"]]
            self._kinds[cname] = (f, e["args"])
        self.provenance = {"kernels": "c", "kernels_how": "the numba kernels translated to C (taos.planar._cdwell), "
                           f"compiled by {manifest['compiler']} {' '.join(manifest['cflags'])}, loaded with ctypes"}

    def _call(self, cname, args):
        f, kinds = self._kinds[cname]
        flat, keep = [], []
        for k, a in zip(kinds, args):
            if k == "fn":
                continue
            if k in ("double", "long"):
                flat.append(a)
                continue
            dt = np.int64 if k == "iarr1" else np.float64
            if not (isinstance(a, np.ndarray) and a.dtype == dt and a.flags.c_contiguous):
                if isinstance(a, np.ndarray) and a.flags.writeable and a.dtype == dt:
                    raise TypeError(f"{cname}: a non-contiguous array argument")   # an output would be lost
                a = np.ascontiguousarray(a, dt)
            keep.append(a)
            flat += [a.ctypes.data] + list(a.shape)
        return f(*flat)

    def expm(self, W):
        W = np.ascontiguousarray(W, np.float64)
        n = W.shape[0]
        R, X, T, tmp = (np.empty((n, n)) for _ in range(4))
        self._call("taos_expm", (W, X, R, T, tmp))
        return R

    @staticmethod
    def law(model):
        return None

    def rate_response_z(self, fid, fp, v, dt, z0):
        tq, zs = np.empty(v.shape[0]), np.empty(v.shape[0])
        self._call("taos_rate_fill", (fid, fp, v, float(dt), float(z0), tq, zs))
        return zs

    def friction_rate(self, fid, fp, w, ta, z, cwbf, cabf):
        return self._call("taos_friction_rate", (fid, fp, w, ta, z, float(cwbf), float(cabf)))

    def dwell_batch(self, *args):
        self._call("taos_dwell_batch", args)


def load(law: str, retry: bool = False) -> CKernels:
    """Law ``law``'s C kernel set: the cached library, built first when there is none or it is
    damaged (module docstring); raises :class:`CUnavailable`. A failed build is remembered for
    its key (``KEY.failed`` beside the libraries, with the reason) and not tried again by each
    command; ``retry`` (the warm-up) tries again."""
    with _LOCK:
        if law in _LOADED:
            return _LOADED[law]
        cc = compiler()
        if not cc:
            raise CUnavailable("no C compiler ($CC, cc or gcc)")
        folder = cache_dir()
        key = cache_key(law, cc)
        so, man, failed = folder / f"{key}.so", folder / f"{key}.json", folder / f"{key}.failed"
        if not man.is_file():   # no library of its own: the warm-up's library of every law, if any
            ks = _from_all(folder, cc, law)
            if ks is not None:
                _LOADED[law] = ks
                return ks
        if failed.is_file() and not retry:   # failed before for this source, compiler and machine
            raise CUnavailable(f"{failed.read_text().strip()} (remembered in {failed}; `python -m "
                               "taos.cli.warmup --only 'C dwells'` or removing it tries again)")
        failed.unlink(missing_ok=True)
        for attempt in range(2):
            try:
                if attempt or not man.is_file():
                    build(law, folder)
                ks = CKernels(so, json.loads(man.read_text()))
                _mark_used(man)
                break
            except CUnavailable as e:
                _write_failure(failed, str(e))
                raise
            except (OSError, ValueError, KeyError, AttributeError) as e:   # a damaged entry: rebuilt once
                if attempt:
                    _write_failure(failed, f"loading {so}: {e}")
                    raise CUnavailable(f"loading {so}: {e}") from None
        _LOADED[law] = ks
        return ks


def _from_all(folder: Path, cc: str, law: str) -> CKernels | None:
    """Law ``law``'s kernel set from the library of every built-in law (:func:`build_all`) in
    ``folder``, or None (none there, or not loadable: the law's own library is built instead)."""
    key = cache_key_all(cc)
    try:
        ks = CKernels(folder / f"{key}.so", json.loads((folder / f"{key}.json").read_text()), law)
    except (OSError, ValueError, KeyError, AttributeError):
        return None
    _mark_used(folder / f"{key}.json")
    return ks


def warm() -> None:
    """Build the library of every built-in law unless the cache has it (the warm-up,
    ``python -m taos.cli.warmup``); raises :class:`CUnavailable` if the build fails."""
    cc = compiler()
    if not cc:
        raise CUnavailable("no C compiler ($CC, cc or gcc)")
    key = cache_key_all(cc)
    folder = cache_dir()
    try:
        json.loads((folder / f"{key}.json").read_text())
        if (folder / f"{key}.so").is_file():
            return
    except (OSError, ValueError):
        pass
    build_all(folder)


def _write_failure(path: Path, reason: str) -> None:
    """Remember why the C path failed for this key (its name changes with the sources, the
    compiler and the machine, so a fix is tried again)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(reason + "\n")
    except OSError:
        pass


def dwell_kernels(model):
    """The kernel set of ``model``'s dwells: C (:func:`load`) unless ``TAOS_KERNELS=numba`` or
    the C path is unavailable (module docstring), then numba's, its provenance saying why."""
    from ..bounds import check_choice

    engine = os.environ.get(ENV, "c").strip().lower() or "c"
    check_choice(engine, ENV, ENGINES)
    if engine == "c":
        try:
            return load(model.friction.name)
        except (CUnavailable, OSError) as e:
            reason = str(e)
    from ._expplan import NUMBA

    if engine == "numba":
        return NUMBA
    return _Fallback(NUMBA, reason)


class _Fallback:
    """numba's kernel set, with the reason the C path did not run in its provenance."""

    def __init__(self, ks, reason: str):
        self._ks = ks
        self.name = ks.name
        self.provenance = {"kernels": "numba", "c_unavailable": reason}

    def __getattr__(self, a):
        return getattr(self._ks, a)
