"""Model variants: one way to change a model, through the model-file loader.

A variant is the model file with some of its keys given other values, exactly as if the file
held them: the same parsing, units, bounds, cross-field checks and parameter-set rules
(:func:`taos.model.load_model` with ``overrides``; :meth:`taos.model.TvcModel.with_values`). Every override, sweep, dispersion, fit and
reduction makes its models this way::

    m2 = model.with_values({"structure.load_stiffness": "160000 lbf/in",     # a value with its unit
                            "friction.coulomb_torque": 1.4e4})               # or SI (here N m)

Keys are ``"section.key"`` of the model file (``docs/reference/model_keys`` lists them), plus
``friction.model`` (the law, as ``--friction`` swaps it, keeping the levels). One meaning per
key: the model file's. In particular ``friction.coulomb_torque`` is the bearing's friction
LEVEL T_c: the law's other load-proportional (torque-like) parameters follow it in proportion,
those the file holds itself (``static_torque``, inline bristle values) and those of a shared
parameter set with a ``reference_torque``, as friction proportional to the bearing normal load
does and as a model file with that ``coulomb_torque`` would load (a file whose friction
parameters come from a shared set cannot hold "T_c alone": the set's keys may not be repeated
in it). A torque-like key given in the same variant (``friction.bristle_stiffness``) is set
as given, after the level.

The result records that it was modified and how: :attr:`~taos.model.TvcModel.overrides` (the
accumulated ``(key, value)`` pairs, values as a model file would hold them),
:attr:`~taos.model.TvcModel.base_sha256` (the files' combined hash) and its own
:attr:`~taos.model.TvcModel.sha256` (the files' hash and the overrides), all of which
:func:`taos.results.model_provenance` puts in every output. A model carries the bytes of every TOML file it was read from (model file, parameter sets) and
the hashes of the others (stiffness file); its variants are parsed from those, never from the
disk (:func:`taos.errors.stored_inputs`): the same on a Dask worker that cannot open a project
file, and unaffected by files deleted or rewritten since.
"""

from __future__ import annotations

import hashlib
import json
import math
import numbers
from typing import Any, Mapping

from .errors import InputError
from .model_keys import key_kind, torque_like_kinds

#: where a variant's errors say they come from when the value was given in code
VARIANT_SOURCE = "model variant"
#: at most this many keys in one variant (bounded work)
MAX_OVERRIDES = 200

def file_value(dotted: str, value: Any) -> Any:
    """``value`` as a model file holds it at key ``dotted``: a string with its unit for a
    physical quantity (a plain number is taken in the SI unit of the key's kind, a pint
    Quantity keeps its unit), else the TOML value itself (text, whole number, switch, list).
    Raises :class:`InputError` naming the key for a value of the wrong type or not finite."""
    from .units import DIMENSIONS

    kind = key_kind(dotted)
    if kind is None:
        if isinstance(value, (str, bool, int, list, tuple)) and not isinstance(value, float):
            return list(value) if isinstance(value, tuple) else value
        raise InputError(VARIANT_SOURCE, dotted, "text, a whole number, true/false or a list as in a model file",
                         got=repr(value)[:60])
    if hasattr(value, "magnitude") and hasattr(value, "units"):   # a pint Quantity keeps its unit
        mag = value.magnitude
        if not isinstance(mag, numbers.Real) or isinstance(mag, bool) or not math.isfinite(mag):
            raise InputError(VARIANT_SOURCE, dotted, "a finite scalar quantity", got=repr(value)[:60])
        return f"{float(mag)!r} {value.units}"
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(VARIANT_SOURCE, dotted, f"a {kind.replace('_', ' ')}: a number in SI or a string with "
                         f"its unit, like {DIMENSIONS[kind][2]}", got=repr(value)[:60])
    v = float(value)
    if not math.isfinite(v):
        raise InputError(VARIANT_SOURCE, dotted, f"a finite {kind.replace('_', ' ')}", got=repr(value))
    return v if kind == "dimensionless" else f"{v!r} {DIMENSIONS[kind][1]}"


def merge_overrides(old: tuple[tuple[str, Any], ...], values: Mapping[str, Any]) -> tuple[tuple[str, Any], ...]:
    """The accumulated overrides: ``old`` with ``values`` (checked, as file values) laid over
    it; a key given again takes its new value in its first place."""
    if not isinstance(values, Mapping):
        raise InputError(VARIANT_SOURCE, "values", "a mapping of model keys ('section.key') to values",
                         got=type(values).__name__)
    if len(values) + len(old) > MAX_OVERRIDES:
        raise InputError(VARIANT_SOURCE, "values", f"at most {MAX_OVERRIDES} model keys in a variant",
                         got=str(len(values) + len(old)))
    out = dict(old)
    for k, v in values.items():
        if not isinstance(k, str) or "." not in k:
            raise InputError(VARIANT_SOURCE, str(k)[:60], "a model key 'section.key', like structure.load_stiffness",
                             got=repr(k)[:60])
        out[k] = file_value(k, v)
        if k == "friction.model":   # named here, not as the command line's --friction
            from .friction import registry

            registry.params_of(v, VARIANT_SOURCE, k)
    return tuple(out.items())


def variant_sha256(base_sha256: str, overrides: tuple[tuple[str, Any], ...]) -> str:
    """A modified model's hash: SHA-256 of its files' combined hash and its overrides (canonical
    JSON); the files' hash itself when there are none."""
    if not overrides:
        return base_sha256
    text = base_sha256 + "\n" + json.dumps([[k, v] for k, v in overrides], sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


def check_variant_source(model: Any, values: Mapping[str, Any]) -> None:
    """Refuse a variant of a model built in code (no file to vary), or a law swap of a model whose
    law was replaced in code (:meth:`~taos.model.TvcModel.replace`): :class:`InputError`."""
    if model.source in ("", "<code>") or not model.input_files:
        raise InputError(VARIANT_SOURCE, ", ".join(map(str, values))[:80] or "values",
                         "a model loaded from a model file (a variant is that file with other values)",
                         got=f"a model built in code ({model.source})")
    code = {k[5:] for k, _ in model.overrides if k.startswith("code.")}
    if "friction" in code and "friction.model" in values:   # a law swap would drop the law set in code
        raise InputError(VARIANT_SOURCE, "friction.model", "a model whose friction law was not replaced in code "
                         "(swap the law with with_values instead of replace)", got="a law set in code")


def code_changes(model: Any) -> dict:
    """field -> value of the changes made in code (:meth:`~taos.model.TvcModel.replace`), which a
    variant keeps (:func:`keep_code_changes`)."""
    return {k[5:]: v for k, v in model.overrides if k.startswith("code.")}


#: (model file, files' combined hash, overrides) -> the file's variant without the code's changes,
#: as :func:`base_variant` loaded it (a few models a process: most recent last)
_BASES: dict = {}
MAX_BASES = 8


def base_variant(model: Any, old: tuple, load) -> Any:
    """``load(old)``: the model's file variant with its earlier file overrides ``old`` and without
    the changes made in code, the reference :func:`keep_code_changes` compares a new variant to.
    It is the same for every variant of ``model`` (a pure function of the files' contents, which
    ``model.base_sha256`` hashes, and of ``old``), so it is loaded once a process and kept: a
    Monte Carlo batch makes a variant per run of the same model."""
    key = (model.source, model.base_sha256, repr(old))
    got = _BASES.pop(key, None)
    if got is None:
        got = load(old)
        while len(_BASES) >= MAX_BASES:
            _BASES.pop(next(iter(_BASES)))
    _BASES[key] = got
    return got


def keep_code_changes(code: Mapping[str, Any], before: Any, after: Any) -> dict:
    """The sections changed in code, with the variant's own effect laid over them: each field the
    new keys changed (``after`` against ``before``, the file's variant with and without them, both
    through the loader) set on the object made in code; the code's other fields stay. A field the
    object made in code does not have (a friction law of another class) is refused."""
    import dataclasses

    out = {}
    for sec, obj in code.items():
        new, old = getattr(after, sec, None), getattr(before, sec, None)
        if not dataclasses.is_dataclass(new) or not dataclasses.is_dataclass(obj):
            out[sec] = obj
            continue
        changed = {f.name: getattr(new, f.name) for f in dataclasses.fields(new)
                   if not _same(getattr(new, f.name), getattr(old, f.name))}
        names = {f.name for f in dataclasses.fields(obj)}
        missing = sorted(set(changed) - names)
        if missing:
            raise InputError(VARIANT_SOURCE, f"{sec}.{missing[0]}", f"a key of the {sec} made in code",
                             got=f"a field its {type(obj).__name__} does not have")
        out[sec] = dataclasses.replace(obj, **changed) if changed else obj
    return out


def _same(a: Any, b: Any) -> bool:
    """``a == b`` as a plain truth value (False where it has none: CasADi symbols, arrays)."""
    try:
        return bool(a == b)
    except Exception:   # noqa: BLE001 - any value without a plain truth value differs
        return False


def check_unchanged(model: Any, out: Any) -> None:
    """Refuse a variant whose files changed since ``model`` was loaded (:class:`InputError`)."""
    if out.base_sha256 != model.base_sha256:
        raise InputError(model.source, "", "the model file and the files it names unchanged since the model was "
                         f"loaded (SHA-256 {model.base_sha256[:12]}...)", got=f"{out.base_sha256[:12]}...")


def with_overrides(doc: dict, overrides: Mapping[str, Any]) -> tuple[dict, dict]:
    """The model file's tables with ``overrides`` (``"section.key" -> TOML value``) written in,
    and, per section, the overrides of keys the file does not hold itself (for ``[actuator]`` and
    ``[friction]``: written after the parameter set is merged, so a swept set key is a variant of
    the hardware and a swept model-file key is scaled with as the file's own would be)."""
    doc, late = dict(doc), {}
    for dotted, value in overrides.items():
        section, _, key = dotted.partition(".")
        table = dict(doc[section]) if isinstance(doc.get(section), Mapping) else {}
        if section in ("actuator", "friction") and key not in table:
            late.setdefault(section, {})[key] = value
        else:
            table[key] = value
        doc[section] = table
    return doc, late


def level_follows(doc: dict, overrides: Mapping[str, Any], src: str) -> dict:
    """The model file's tables with the friction level rule of an overridden
    ``friction.coulomb_torque`` applied (:mod:`taos.variants`): every other torque-like key the
    file's ``[friction]`` holds itself and the overrides leave alone (``static_torque``, inline
    bristle values) scaled by the new level over the file's; a shared parameter set follows
    through its ``reference_torque``."""
    if "friction.coulomb_torque" not in overrides or not isinstance(doc.get("friction"), Mapping):
        return doc
    ftab = dict(doc["friction"])
    if "coulomb_torque" not in ftab:
        return doc
    from .units import DIMENSIONS, to_si

    old = to_si(ftab["coulomb_torque"], "torque", source=src, field="friction.coulomb_torque", nonnegative=True)
    new = to_si(overrides["friction.coulomb_torque"], "torque", source=src, field="friction.coulomb_torque",
                nonnegative=True)
    if not old > 0:
        return doc
    kinds = torque_like_kinds()
    for key, kind in kinds.items():
        if key in ftab and f"friction.{key}" not in overrides:
            v = to_si(ftab[key], kind, source=src, field=f"friction.{key}", nonnegative=True)
            ftab[key] = f"{v * (new / old)!r} {DIMENSIONS[kind][1]}"
    return {**doc, "friction": ftab}
