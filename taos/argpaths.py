"""The paths a command line names, for the checks made before any work
(:func:`taos.results.check_arguments`): every input however it was named (a path, a shipped
file's bare name, a file an input TOML names), and whether two output names are one place."""

from __future__ import annotations

import os
import stat


def input_paths(args, output_options=()) -> list[str]:
    """Every argument value (positional or option, lists included) other than an output option
    that names an existing path, or a shipped file by its bare name (``ascent`` is
    ``models/flight/ascent.toml``, :func:`taos.shipped.resolve`, of any kind), and the files
    those TOML inputs name in turn (a flight file's TVC model, a model's parameter sets, a few
    levels deep): the run's inputs however they were named."""
    from taos.shipped import KIND_FOLDERS, resolve
    out = []
    for k, v in vars(args).items():
        if k in output_options or k == "func":
            continue
        for x in (v if isinstance(v, (list, tuple)) else [v]):
            if not (isinstance(x, str) and x and len(x) < 4096 and "\0" not in x):
                continue
            if os.path.exists(x):
                out.append(x)
                continue
            try:
                out.extend(str(p) for p in {resolve(x, kind) for kind in KIND_FOLDERS} if p.is_file())
            except (OSError, ValueError):
                pass
    return out + _referenced_files(out)


def _referenced_files(paths, depth: int = 3, limit: int = 200) -> list[str]:
    """The existing files that the TOML files among ``paths`` name in their string values
    (beside the file, or in the shipped folder), ``depth`` levels deep, at most ``limit``: an
    output must not replace them either. Unreadable files are skipped (their loader reports them)."""
    import tomllib

    from taos.shipped import reference_places
    seen, found, todo = set(), [], [(p, 0) for p in paths]
    while todo and len(seen) < limit:
        p, d = todo.pop()
        try:
            rp = os.path.realpath(p)
            st = os.stat(rp)
            # a regular file only: a FIFO given as an input would block this open (its reader refuses it)
            if rp in seen or not rp.endswith(".toml") or not stat.S_ISREG(st.st_mode) or st.st_size > (1 << 20):
                continue
            seen.add(rp)
            with open(rp, "rb") as fh:
                doc = tomllib.load(fh)
        except (OSError, ValueError, RecursionError):   # nested beyond reason: its loader refuses it
            continue
        stack = [doc]
        while stack:
            x = stack.pop()
            if isinstance(x, dict):
                stack.extend(x.values())
            elif isinstance(x, list):
                stack.extend(x)
            elif isinstance(x, str) and 0 < len(x) < 1024 and "\0" not in x and ("/" in x or "." in x):
                try:
                    for c in reference_places(x, rp):
                        if c is not None and c.is_file():
                            found.append(str(c))
                            if d + 1 < depth:
                                todo.append((str(c), d + 1))
                except (OSError, ValueError):
                    pass
    return found


def same_place(a: str, b: str) -> bool:
    """Whether two output names are one place (the same resolved path, or one file by two names)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    ia, ib = _identity_of(a), _identity_of(b)
    return ia is not None and ia == ib


def _identity_of(path) -> tuple | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return (st.st_dev, st.st_ino)


def check_environment() -> None:
    """The environment variables a command reads, checked before any work (one line, exit 2;
    docs/reference/cli.md): ``NUMBA_NUM_THREADS`` a whole number of at least 1 (numba fails on
    0 or less when a kernel first asks for its threads, and silently takes its default for text
    it cannot read); ``TAOS_KERNELS`` ``c`` or ``numba`` (:mod:`taos.planar._cdwell`). ``MPLBACKEND`` is not refused: a command draws its plots into files with
    matplotlib's Agg backend whatever it says, so it is set to Agg here (a name matplotlib does not
    know would stop the import of matplotlib itself). A file name that is not valid in the
    locale's encoding (``LANG=C``, or bytes that are not UTF-8) is handled as the bytes it is
    (:func:`os.fsencode`)."""
    from taos.errors import InputError

    v = os.environ.get("NUMBA_NUM_THREADS")
    if v is not None and not (v.strip().isdigit() and int(v) >= 1):
        raise InputError("environment", "NUMBA_NUM_THREADS", "a whole number of threads, 1 or more (or unset: "
                         "one per core)", got=repr(v)[:40])
    k = os.environ.get("TAOS_KERNELS", "").strip().lower()
    if k not in ("", "c", "numba"):
        raise InputError("environment", "TAOS_KERNELS", "c (the dwells' C kernels, default) or numba",
                         got=repr(os.environ["TAOS_KERNELS"])[:40])
    if os.environ.get("MPLBACKEND", "agg").lower() != "agg" and "matplotlib" not in __import__("sys").modules:
        os.environ["MPLBACKEND"] = "agg"
