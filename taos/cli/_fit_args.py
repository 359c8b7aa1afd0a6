"""The arguments ``taos fit`` and ``taos compare`` share between the planar and the 3-D fit (one parser
each): ``--bounds 'NAME=LOW:HIGH'``, ``--start NAME=VALUE``, ``--free``, and the output places."""

from __future__ import annotations

from taos.errors import InputError


def _parse_bounds(items, table=None) -> dict:
    """--bounds 'NAME=LO:HI' (each with a unit) -> {name: (lo_si, hi_si)}; names from ``table``
    (name -> an object with ``kind``; default the planar fit's parameters)."""
    from taos.friction.bounds import loader_bound
    from taos.identify.surrogate import PARAMETERS as PLANAR
    from taos.units import to_si

    PARAMETERS = PLANAR if table is None else table

    out = {}
    for it in items or []:
        if "=" not in it or ":" not in it.split("=", 1)[1]:
            raise InputError("command line", "--bounds", "NAME=LOW:HIGH with units, like "
                             "load_stiffness='50000 lbf/in:400000 lbf/in'", got=repr(it))
        k, v = (x.strip() for x in it.split("=", 1))
        if k not in PARAMETERS:
            raise InputError("command line", "--bounds", "a name from " + ", ".join(PARAMETERS), got=repr(k))
        p = PARAMETERS[k]
        lo_s, hi_s = (x.strip() for x in v.split(":", 1))
        lo, hi = (to_si(x if p.kind != "dimensionless" else float(x), p.kind, source="command line",
                        field=f"--bounds {k}", positive=True) for x in (lo_s, hi_s))
        if not lo < hi:
            raise InputError("command line", f"--bounds {k}", "LOW below HIGH", got=repr(v))
        key = getattr(p, "key", None) or f"{p.section}.{p.toml_key}"
        limit = loader_bound(key)   # a fit never returns a value the model loader refuses (issue 40)
        if limit is not None and not limit[0] <= lo < hi <= limit[1]:
            raise InputError("command line", f"--bounds {k}", f"a range within the model file's bound of {key}, "
                             f"{limit[0]:.4g} to {limit[1]:.4g} SI (docs/reference/bounds.md)",
                             got=f"{lo:.4g} to {hi:.4g} SI")
        out[k] = (lo, hi)
    return out


def _parse_start(items, parameters) -> dict:
    """``--start NAME=VALUE`` items -> {name: SI value}; ``parameters`` the fit's table (name -> an
    entry with ``kind``: :data:`taos.identify.surrogate.PARAMETERS` for the planar fit,
    :data:`taos.identify.params3d.PARAMETERS3D` for the 3-D one)."""
    from taos.units import to_si

    out = {}
    for it in items or []:
        if "=" not in it:
            raise InputError("command line", "--start", "NAME=VALUE with a unit, like load_stiffness='150000 lbf/in'",
                             got=repr(it))
        k, v = (s.strip() for s in it.split("=", 1))
        if k not in parameters:
            raise InputError("command line", "--start", "a name from " + ", ".join(parameters), got=repr(k))
        p = parameters[k]
        out[k] = to_si(v if p.kind != "dimensionless" else float(v), p.kind, source="command line",
                       field=f"--start {k}", positive=True)
    return out


def _free(text, default=None) -> list[str]:
    """``--free NAME,NAME`` -> the names (``default`` when ``text`` is empty); empty names refused."""
    free = [s.strip() for s in (text or default or "").split(",")]
    if not all(free):
        raise InputError("command line", "--free", "parameter names separated by single commas, like "
                         "load_stiffness,coulomb_torque", got=repr(text))
    return free


def _outputs(args, *names) -> None:
    """Refuse output places that cannot be written before any work."""
    from taos.results import check_output_file

    for n in names:
        v = getattr(args, n, None)
        if v not in (None, "-"):
            check_output_file(v, "--" + n.replace("_", "-"), (".png", ".svg") if n == "plot" else ())
