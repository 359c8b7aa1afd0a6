"""The reduced planar model file written by ``taos reduce`` (:mod:`taos.identify.reduce`).

The file is the 3-D model's own model file (edited with tomlkit: every other line and comment
stays) with

* a head naming the 3-D model file and the SHA-256 of every file it was read from, its
  variant keys, the test records behind it and the head its fit wrote, the match figures and
  the package version;
* the ``[friction]`` table written out in full: ``model`` and every parameter of the reduced
  law in SI (Python's shortest exact repr, so it loads back to the same floats), the free keys
  commented with the 3-D value they replace; keys of other laws kept (``--friction`` swaps). A
  shared friction parameter set is no longer named: the reduced friction is this file's own;
* the model's variant values (if the 3-D model was a variant) written in; a shared actuator
  set named by its resolved path (as ``taos fit --out-model`` does), inlined if a variant value
  changes one of its keys;
* ``[gimbal]`` and ``[geometry]`` left out: the reduced friction already holds the gimbal
  halves' compliance (the simplex assumption, no gimbal stiffness element), so a 3-D model
  built on this file would count it twice. ``taos lco``, ``taos info`` and every planar
  command take the file as any model file.

It is written atomically (:func:`taos.results.atomic_write`: never over an input or a file this
program did not write) after checking that it loads back to the reduced model.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import math
from pathlib import Path

from taos.errors import InputError

#: head lines of a model file that a fit wrote (``taos fit --out-model``) contain this
_FIT_MARK = "fit"


def fit_header(path) -> tuple:
    """The leading comment lines of the model file at ``path`` that say it was fitted (a fit
    result's head naming its records), without the ``#``; () when none or unreadable."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return ()
    out = []
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if not s.startswith("#"):
            break
        if _FIT_MARK in s.lower():
            out.append(s.lstrip("#").strip())
    return tuple(out)


def _si_text(value: float, kind: str):
    from taos.units import DIMENSIONS

    return float(value) if kind == "dimensionless" else f"{float(value)!r} {DIMENSIONS[kind][1]}"


def _friction_table(result, stamp: str):
    """The reduced ``[friction]`` table (tomlkit), every parameter of the law explicit."""
    import tomlkit

    law = result.model.friction
    start = dict(zip(result.free, result.start_si))
    tab = tomlkit.table()
    tab.add(tomlkit.comment(f"PLANAR-EQUIVALENT friction reduced by taos reduce ({stamp}) from the 3-D model's bearing "
                            "friction: the simplex model's (no gimbal stiffness element); every parameter in SI"))
    tab.add("model", law.name)
    written = {"model"}
    for f in dataclasses.fields(law):
        key, kind = f.metadata.get("key"), f.metadata.get("kind")
        if key is None:
            continue
        item = tomlkit.item(_si_text(getattr(law, f.name), kind))
        dotted = f"friction.{key}"
        if dotted in start:
            item.comment(f"reduced (planar-equivalent); the 3-D model has {_si_text(start[dotted], kind)}")
            item.trivia.comment_ws = "  "
        tab.add(key, item)
        written.add(key)
    for key, value in result.model.friction_table.items():   # keys of other laws, for --friction swaps
        if key not in written and key != "parameter_set":
            tab.add(key, value)
    return tab


def _head(result, stamp: str) -> str:
    p = result.provenance
    lines = [f"Planar (simplex) model reduced by taos reduce on {stamp} from the 3-D TAOS model",
             f"  {p['source_model_file']} (model_sha256 {p['source_model_sha256']})"]
    for role, d in p.get("source_model_inputs", {}).items():
        lines.append(f"  {role}: {d['file']} (sha256 {d['sha256']})")
    if p.get("source_model_overrides"):
        lines.append("  a variant of that file: " + ", ".join(f"{k} = {v}" for k, v in p["source_model_overrides"].items()))
    recs = [f"{r['file']} (sha256 {r['sha256']})" for r in result.records]
    lines.append("Test records behind the 3-D model: " + ("; ".join(recs) if recs else "none named (taos reduce "
                                                                                         "--records)"))
    lines += [f"The 3-D model's fit: {h}" for h in result.fit_header]
    lines += ["Its friction is PLANAR-EQUIVALENT (paper sec. 4: tuned under the simplex assumptions, planar, no gimbal",
              "stiffness element): fitted to the 3-D model's engine sine dwells; match (planar vs 3-D):"]
    lines += ["  " + s for s in result.summary_lines()]
    lines += ["[gimbal] and [geometry] are left out: this friction already holds the gimbal halves' compliance, a 3-D",
              "model built on it would count it twice. The load path is the file's [structure] load_stiffness, the",
              "fitted total the 3-D line stiffness is derived from (taos.taos3d.calibrate).",
              f"taos {p.get('package_version', '')} {p.get('git_revision', '')}".rstrip()]
    return "".join(f"# {s}\n" for s in lines)


def planar_model_text(result) -> str:
    """The reduced planar model file's text (module docstring)."""
    import tomlkit

    from taos.identify.model_file import inline_actuator_parameter_set
    from taos.model import resolve_parameter_set
    from taos.results import toml_set

    src = result.source.source
    try:
        doc = tomlkit.parse(Path(src).read_text(encoding="utf-8"))
    except OSError as e:
        raise InputError(src, "(file)", "the 3-D model file the reduction started from", got=e.strerror) from None
    stamp = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    for dotted, value in result.model.overrides:   # the 3-D model's variant values (the free ones are below)
        section, _, key = dotted.partition(".")
        if section in ("friction", "gimbal", "geometry"):
            continue
        tab = doc.get(section)
        if tab is None:
            raise InputError(src, f"[{section}]", "the section of a variant value", got="no such section")
        if section == "actuator" and key not in tab and "parameter_set" in tab:
            inline_actuator_parameter_set(doc, Path(src), src)
        toml_set(doc, section, key, value, "variant value of the 3-D model")
    ref = doc.get("actuator", {}).get("parameter_set")
    if ref:   # named relative to the 3-D model file: keep it reachable from wherever this file goes
        toml_set(doc, "actuator", "parameter_set", resolve_parameter_set(str(ref), Path(src), "actuator").as_posix(),
                 f"the shared set of {Path(src).name}")
    for section in ("gimbal", "geometry"):
        if section in doc:
            del doc[section]
    doc["friction"] = _friction_table(result, stamp)
    toml_set(doc, "", "name", f"{result.source.name} (planar reduction)")
    toml_set(doc, "", "description", "Planar-equivalent friction reduced from the 3-D TAOS model by taos reduce "
             f"(low-frequency engine response, {'/'.join(result.axes)}); flight-loop model for taos lco.")
    return _head(result, stamp) + _drop_lead_ins(tomlkit.dumps(doc), src)


def _drop_lead_ins(text: str, src: str) -> str:
    """``text`` without the comment blocks that introduced the left-out ``[gimbal]`` and
    ``[geometry]`` tables in the 3-D model file (tomlkit keeps them with the table before)."""
    import re

    try:
        original = Path(src).read_text(encoding="utf-8")
    except OSError:
        return text
    for section in ("gimbal", "geometry"):
        m = re.search(r"((?:^#[^\n]*\n)+)(?=\[" + section + r"\][ \t]*(?:#[^\n]*)?\n)", original, re.MULTILINE)
        if m and m.group(1) in text:
            text = text.replace(m.group(1), "", 1)
    return text.rstrip("\n") + "\n"


def _check_same(back, model) -> None:
    """The written file loads back to the reduced model (every engine, actuator, structure,
    friction and avionics value within 1e-9 relative), else RuntimeError (a writer bug)."""
    for part in ("engine", "actuator", "structure", "friction"):
        a, b = getattr(model, part), getattr(back, part)
        if type(a) is not type(b):
            raise RuntimeError(f"written {part} reads back as {type(b).__name__}, not {type(a).__name__}")
        for f in dataclasses.fields(a):
            x, y = getattr(a, f.name), getattr(b, f.name)
            if isinstance(x, float) and not math.isclose(x, y, rel_tol=1e-9, abs_tol=1e-300):
                raise RuntimeError(f"written {part}.{f.name} reads back as {y!r}, not {x!r}")
            if not isinstance(x, float) and x != y:
                raise RuntimeError(f"written {part}.{f.name} reads back as {y!r}, not {x!r}")
    if back.avionics != model.avionics:
        raise RuntimeError("written avionics read back differently")


def write_planar_model(result, path) -> None:
    """Write the reduced planar model file atomically, after checking it loads back to
    ``result.model`` (:func:`taos.results.atomic_write`: never an input, never a file this
    program did not write unless ``--force``)."""
    from taos.model import load_model
    from taos.results import atomic_write, check_output_file

    inputs = [p for p, _ in result.source.input_files.values()] + [r["file"] for r in result.records]
    check_output_file(path, "--out", (".toml",), inputs=inputs)
    text = planar_model_text(result)

    def write(tmp: Path):
        tmp.write_text(text, encoding="utf-8")
        _check_same(load_model(tmp), result.model)

    atomic_write(path, write, field="--out")
