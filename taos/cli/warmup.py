"""Compile and cache every numba kernel once (``python -m taos.cli.warmup``; run by ``make test``).

The integrator kernels take tens of seconds to compile on a cold cache and are cached on disk
after their first use. ``make test`` warms every kernel first, so that no test pays a compile.
``make demo`` does not warm everything: the Green Run compiles just the kernels it uses, and
beside it a second process compiles the planar simulation's step (``--only simulate``: the
figures of merit's runs), which the Green Run would otherwise compile after the 3-D model's
kernels on the same core (numba compiles one kernel at a time in a process). Both processes may
compile a shared kernel (the friction law's C callbacks) at once: each kernel has one
specialisation (``tests/test_kernel_specialisations.py``), so both save the same key, which
numba's cache allows (below); a warm cache makes the second process a load of about a second.

``--part K/N`` compiles the K-th of N disjoint shares of the kernels, so that ``make`` runs the
shares at the same time on several cores (``make`` runs ``--part 1/2`` and ``--part 2/2``).
The steps are grouped so that no two shares write the same cache file with different
signatures: numba's cache (``numba.core.caching.IndexDataCacheFile``) is safe against two
processes saving the SAME key (each writes its index and data through a temporary file and
``os.replace``; both write the same key and equivalent machine code), but two processes saving
DIFFERENT signatures of one kernel at once can leave an index entry naming the other
signature's data file. A step that calls a non-inlined cached kernel of another step compiles
that callee too, so the steps sharing such callees form one group and a group is never split:

* ``planar``: the planar simulation, the dwells (ETDRK4 and RK4), the shooting kernels and the
  verdict map's confirmation share ``planar.dynamics`` (``integrate_samples``, which the
  confirmation runs itself, ``_rk4_step``, ``sine_steps``, ``saturation.apply``) and
  ``planar._expstep`` (``etdrk4_step``, ``_nonlin``, ``sine_steps_exp``);
* ``3d``: the 3-D model's kernels share ``taos3d.dynamics`` (with its pieces ``taos3d._rhs``,
  ``taos3d._commands``, ``taos3d._so3``) and ``taos3d._bearing``;
* ``friction``: every built-in law's C callbacks, the lane forms included (``friction.registry.load_all``),
  and the C dwells (not numba's: the dwell kernels translated to C and compiled into one library
  for every built-in law, :mod:`taos.planar._cdwell`, its own cache, which ``taos freqresp``'s
  dwells load instead of numba's): building it imports every law's C callbacks, the friction
  step's kernels, so both steps stay in one share and the callbacks compile once.
* ``masv``: masv's lane kernel (``masv._kernel.integrate``, one compile for any number of engines
  and laws), whose inlined limits come from ``planar.saturation``.

Between groups the only shared callees are ``planar._avionics_kernels.apply``,
``planar._expstep.expm_small`` (the exponential lanes' coefficients, ``lanes``) and the model's
friction law's C callbacks, which every group calls with the same signature (float64 and
C-contiguous float64 arrays), so a simultaneous save writes the same key with the same code.

``--sources`` prints the source files of taos and masv whose code numba compiles
(:func:`kernel_sources`; plain Python, imports nothing from taos: the Makefile runs it with any ``python3``) — the files whose
change makes ``make`` drop the kernel cache and warm it again.
"""

from __future__ import annotations

import argparse
import ast
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

PACKAGE_DIR = Path(__file__).resolve().parents[1]

#: the names whose call or decoration makes numba compile the function (``kernel`` is
#: :func:`taos.friction._builtin.kernel`, a cached ``cfunc``; it is counted only when imported
#: from a module that imports numba, see :func:`kernel_sources`)
JIT_NAMES = frozenset({"njit", "jit", "cfunc", "vectorize", "guvectorize", "stencil", "generated_jit",
                       "overload", "register_jitable"})


# -- the steps ---------------------------------------------------------------------------------
def _model():
    from taos.model import load_model
    return load_model("rs25_hotfire")


def _dwell(**kw) -> None:
    """numba's dwell kernels (the reference and the fallback of the C dwells, forced here)."""
    import os

    from taos.planar._cdwell import ENV
    from taos.planar.freqresp import sine_dwell_grid
    before = os.environ.get(ENV)
    os.environ[ENV] = "numba"
    try:
        sine_dwell_grid(_model(), [math.radians(0.4)], [10.0], settle_s=0.0, settle_cycles=1, measure_cycles=1, **kw)
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def _c_dwells() -> None:
    """The C dwell library of the built-in laws (:mod:`taos.planar._cdwell`; none without a C
    compiler): one library for every law (one compile of the code they share), built where the
    cache has none, so a dwell command starts without numba; if it cannot be built, each law's
    own (the failure then remembered per law)."""
    from taos.friction._builtin import modules
    from taos.planar import _cdwell

    if _cdwell.compiler() is None:
        return
    try:
        _cdwell.warm()
        return
    except _cdwell.CUnavailable:
        pass
    for law in modules():
        _cdwell.load(law, retry=True)


def _simulate() -> None:
    from taos.planar.simulate import simulate
    from taos.profiles import SineDwell
    simulate(_model(), SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)


def _simulate_exp() -> None:
    from taos.planar.simulate import simulate
    from taos.profiles import SineDwell
    simulate(_model(), SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01, integrator="exp")


def _ascent_lanes() -> None:
    # the lockstep lane kernel of ascents and Monte Carlo batches (one compile for every law:
    # the friction rates are a first-class function argument)
    from taos.flight.ascent import load_ascent
    from taos.flight.ascent_sim import simulate_ascent
    from taos.model import load_model
    from taos.flight.ascent_sim import simulate_ascents
    asc = load_ascent("ascent")
    model = load_model(asc.tvc_model)
    simulate_ascent(asc, model, axes=("yaw",), start_s=0.0, end_s=0.1, dt_s=1e-3, record_interval_s=0.01)
    # and their exponential kernel (taos.planar._explanes: Monte Carlo campaigns with integrator = "etdrk4")
    simulate_ascents([(asc, model, 0)], axis="yaw", start_s=0.0, end_s=0.1, dt_s=5e-3, record_interval_s=0.02,
                     integrator="etdrk4")


def _shoot() -> None:
    # both integrators' shooting kernel compile together (minutes on a loaded machine if a test
    # paid for it)
    _dwell(method="shoot", max_cycles=1)


def _friction() -> None:
    from taos.friction.registry import load_all
    _model().friction.response([0.0, 0.1], 1e-3)
    load_all()   # every built-in law's kernels (a command loads only its own law's)


def _lco_confirm() -> None:
    from taos.flight.lco_confirm import compile_kernel
    compile_kernel(_model())   # the verdict map's confirmation runs (taos lco --sweep)


def _taos_model() -> None:
    from taos.taos3d import taos_model
    taos_model(_model())


def _simulate_taos() -> None:
    import numpy as np

    from taos.profiles import SineDwell
    from taos.taos3d import dynamics as dy, simulate_taos, taos_model
    from taos.taos3d.simulate import pack, rest_state
    tm = taos_model(_model())
    simulate_taos(tm, SineDwell(math.radians(0.4), 1.0, 1), duration_s=0.01)
    pk = pack(tm)   # integrate, the co-simulation core's entry (simulate_taos calls its loop directly)
    dy.integrate(pk.P, pk.fid, pk.fp, pk.avp, rest_state(pk), np.zeros(dy.N_BEARING), np.zeros((2, 2)), 4e-4, 1,
                 np.empty((2, len(dy.REC))))


def _taos_freqresp() -> None:
    from taos.taos3d import taos_freqresp, taos_model
    taos_freqresp(taos_model(_model()), [10.0], math.radians(0.4))


def _masv_simulate() -> None:
    # masv's lane kernel (masv._kernel.integrate): one compile for any number of engines and laws
    from masv.config import load_config
    from masv.timedomain import simulate
    from taos.profiles import SineDwell
    from taos.shipped import models_dir
    cfg = load_config(models_dir() / "masv" / "core_stage_rigid.toml")
    simulate(cfg, SineDwell(math.radians(0.1), 1.0, 1), duration_s=0.01)


@dataclass(frozen=True)
class Step:
    """One warm-up step: ``run`` compiles its kernels; ``group`` the steps sharing non-inlined
    cached callees (never split between shares); ``cost_s`` its compile time on a quiet
    2-core machine [s] (for balancing the shares)."""

    name: str
    group: str
    run: Callable[[], None]
    cost_s: float


STEPS: tuple[Step, ...] = (
    # the planar steps' costs: the previous quiet-machine figures times each step's measured
    # after/before ratio (issue 44 point 1, benchmarks/RESULTS.md "planar kernels' cold compile"),
    # and since for simulate, dwell rk4, shoot (the RK4 step's stages through one copy of its
    # rates) and the C dwells (one library for every law): benchmarks/RESULTS.md "stage4"
    Step("simulate", "planar", _simulate, 6.4),
    Step("simulate exponential", "planar", _simulate_exp, 7.0),
    Step("dwell exponential", "planar", _dwell, 6.6),
    Step("dwell rk4", "planar", lambda: _dwell(integrator="rk4"), 3.9),
    Step("shoot", "planar", _shoot, 12.8),
    Step("lco confirmation", "planar", _lco_confirm, 0.1),
    Step("friction laws", "friction", _friction, 4.7),
    Step("C dwells", "friction", _c_dwells, 4.9),
    # (+ 6.5 s: the ETDRK4 lanes, benchmarks/RESULTS.md mcexp; - 8.6 s: the RK4 lanes' four stages
    # through one inlined copy of their rates, compile2)
    Step("ascent lanes", "lanes", _ascent_lanes, 14.2),
    Step("3-D model", "3d", _taos_model, 8.9),
    Step("3-D simulate", "3d", _simulate_taos, 7.8),
    Step("3-D frequency response", "3d", _taos_freqresp, 2.3),
    # (- 6.4 s: the four RK4 stages through one inlined copy of their rates, benchmarks/RESULTS.md compile2)
    Step("masv simulate", "masv", _masv_simulate, 3.5),
)


def shares(n: int, steps: tuple[Step, ...] = STEPS) -> list[list[Step]]:
    """The steps in ``n`` shares of about equal cost: whole groups, the costliest first onto the
    least loaded share (longest-processing-time rule); steps keep their order within a share."""
    groups: dict[str, list[Step]] = {}
    for s in steps:
        groups.setdefault(s.group, []).append(s)
    load = [0.0] * n
    out: list[list[Step]] = [[] for _ in range(n)]
    for g in sorted(groups.values(), key=lambda g: -sum(s.cost_s for s in g)):
        k = load.index(min(load))
        out[k].extend(g)
        load[k] += sum(s.cost_s for s in g)
    return out


# -- the kernel sources ------------------------------------------------------------------------
def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _resolve(mod: str, level: int, here: str, is_pkg: bool) -> str:
    if level == 0:
        return mod
    base = here.split(".") if is_pkg else here.split(".")[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([mod] if mod else []))


@dataclass
class _Module:
    path: Path
    imports_numba: bool = False
    jit_calls: set[str] = field(default_factory=set)      # names called
    decorators: set[str] = field(default_factory=set)     # names used as decorators
    modules: set[str] = field(default_factory=set)        # taos modules imported whole (``import taos.x``)
    names: dict[str, tuple[str, str]] = field(default_factory=dict)   # local name -> (module, name) imported


def _outside_functions(tree: ast.Module):
    """The nodes of ``tree`` not inside a function (a kernel cannot import; an import inside a
    function is the Python around the kernels)."""
    stack = list(tree.body)
    while stack:
        node = stack.pop()
        yield node
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            stack.extend(ast.iter_child_nodes(node))


def _scan(path: Path, root: Path, tops: frozenset[str] = frozenset()) -> tuple[str, _Module]:
    """The module of ``path`` (under package folder ``root``): its numba use and its imports from
    ``root``'s package and the packages named in ``tops``."""
    name = _module_name(path, root)
    is_pkg = path.name == "__init__.py"
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    m = _Module(path)
    tops = tops | {root.name}
    module_level = {id(n) for n in _outside_functions(tree)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "numba":
                    m.imports_numba = True
                elif a.name.split(".")[0] in tops and id(node) in module_level:
                    m.modules.add(a.name)
        elif isinstance(node, ast.ImportFrom):
            mod = _resolve(node.module or "", node.level, name, is_pkg)
            if mod.split(".")[0] == "numba":
                m.imports_numba = True
            elif mod.split(".")[0] in tops and id(node) in module_level:
                for a in node.names:
                    m.names[a.asname or a.name] = (mod, a.name)
        elif isinstance(node, ast.Call):
            f = node.func
            m.jit_calls.add(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for d in node.decorator_list:
                f = d.func if isinstance(d, ast.Call) else d
                m.decorators.add(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))
    return name, m


#: the packages scanned for kernels: taos, and masv beside it (its lane kernel calls taos's)
PACKAGES = (PACKAGE_DIR, PACKAGE_DIR.parent / "masv")


def kernel_sources(roots: tuple[Path, ...] = PACKAGES) -> list[Path]:
    """The source files under ``roots`` (the taos and masv packages; one missing is skipped) whose
    code numba compiles, sorted.

    numba's on-disk cache checks only the file of the kernel it compiled; a kernel that inlines
    or calls code from another file, or reads its constants, keeps its old machine code when
    only that other file changes. So the set is: every module that imports numba (anywhere,
    even inside a function), every module that declares kernels with a decorator imported from
    such a module (the friction laws' ``@kernel``), and for each module declaring kernels, every
    taos or masv module it imports from (a module or a name of it: a callee, a constant, a
    packed-slot index), each name followed to the module that defines it. Static (``ast``): imports nothing.
    """
    roots = [Path(r) for r in roots if Path(r).is_dir()]
    tops = frozenset(r.name for r in roots)
    mods = dict(_scan(p, root, tops) for root in roots for p in sorted(root.rglob("*.py")) if "__pycache__" not in p.parts)
    numba_mods = {n for n, m in mods.items() if m.imports_numba}

    def declares(n: str) -> bool:
        m = mods[n]
        if m.imports_numba and (m.jit_calls | m.decorators) & JIT_NAMES:
            return True
        return any(local in m.decorators and src in numba_mods for local, (src, _) in m.names.items())

    def module_of(mod: str) -> str | None:
        while mod and mod not in mods:
            mod = mod.rpartition(".")[0]
        return mod or None

    def definer(mod: str, name: str, seen: frozenset[tuple[str, str]] = frozenset()) -> set[str]:
        """The module ``name`` comes from, through re-exports (``mod.name`` may be a module)."""
        if f"{mod}.{name}" in mods:
            return {f"{mod}.{name}"}
        m = module_of(mod)
        if m is None or (m, name) in seen:
            return set()
        src = mods[m].names.get(name)
        if src is None:
            return {m}
        return {m} | definer(*src, seen=seen | {(m, name)})

    kernel_mods = {n for n in mods if declares(n)}
    out = set(numba_mods) | kernel_mods
    for n in kernel_mods:
        m = mods[n]
        out |= {mod for mod in m.modules if mod in mods}
        for src in m.names.values():
            out |= definer(*src)
    return sorted(mods[n].path for n in out)


# -- command line ------------------------------------------------------------------------------
def _part(text: str) -> tuple[int, int]:
    try:
        k, n = (int(v) for v in text.split("/"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected K/N (e.g. 1/2), got {text!r}") from None
    if not 1 <= k <= n <= len(STEPS):
        raise argparse.ArgumentTypeError(f"expected 1 <= K <= N <= {len(STEPS)}, got {text!r}")
    return k, n


def _names(text: str) -> frozenset[str]:
    names = frozenset(v.strip() for v in text.split(","))
    known = {s.name for s in STEPS}
    if not names <= known:
        raise argparse.ArgumentTypeError(f"unknown step(s) {sorted(names - known)}; expected some of {sorted(known)}")
    return names


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m taos.cli.warmup", description=__doc__.splitlines()[0])
    ap.add_argument("--part", type=_part, default=(1, 1), metavar="K/N",
                    help="compile the K-th of N disjoint shares of the kernels (default 1/1: all)")
    ap.add_argument("--only", type=_names, default=None, metavar="STEP[,STEP]",
                    help="compile only these steps (`make demo` compiles the planar simulation's kernels "
                         "this way beside the Green Run's own 3-D compiles); one of: "
                         + ", ".join(s.name for s in STEPS))
    ap.add_argument("--sources", action="store_true",
                    help="print the source files whose code numba compiles, relative to the working folder")
    args = ap.parse_args(argv)
    if args.sources:
        cwd = Path.cwd()
        for p in kernel_sources():
            print(p.relative_to(cwd) if p.is_relative_to(cwd) else p)
        return
    if args.only is not None and args.part != (1, 1):
        ap.error("--only and --part exclude each other")
    k, n = args.part
    t0 = time.perf_counter()
    todo = shares(n)[k - 1] if args.only is None else [s for s in STEPS if s.name in args.only]
    for step in todo:
        t1 = time.perf_counter()
        step.run()
        print(f"taos warm-up {k}/{n}: {step.name} {time.perf_counter() - t1:.1f} s", flush=True)
    print(f"taos: numba kernels ({k}/{n}) compiled and cached in {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
