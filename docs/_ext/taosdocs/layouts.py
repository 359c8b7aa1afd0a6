"""Layouts of the output files, read from files the guide commands made (so they stay true)."""

from __future__ import annotations

import json
from pathlib import Path


def _short(v) -> str:
    s = repr(v) if not isinstance(v, str) else v
    s = s.replace("\n", " ")
    return s if len(s) <= 60 else s[:57] + "..."


def h5_layout(path: Path, max_items: int = 60) -> str:
    """Text tree of an HDF5 file: groups, datasets (shape, dtype) and attributes."""
    import h5py

    lines: list[str] = []

    def attrs(obj, indent):
        for k in sorted(obj.attrs):
            lines.append(f"{indent}  @{k} = {_short(obj.attrs[k])}")

    def walk(g, indent):
        attrs(g, indent)
        names = sorted(g)
        for k, name in enumerate(names):
            if k >= max_items:
                lines.append(f"{indent}  ... ({len(names) - max_items} more)")
                break
            obj = g[name]
            if hasattr(obj, "shape"):
                lines.append(f"{indent}  {name}  {obj.dtype} {tuple(obj.shape)}")
                attrs(obj, indent + "  ")
            else:
                lines.append(f"{indent}  {name}/")
                walk(obj, indent + "  ")

    with h5py.File(path, "r") as h5:
        lines.append("/")
        walk(h5, "")
    return "\n".join(lines)


def json_layout(path: Path) -> str:
    """Text tree of a JSON file: keys with the type (and length) of each value."""
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    lines: list[str] = []

    def walk(v, key, indent):
        if isinstance(v, dict):
            lines.append(f"{indent}{key}{{}}" if key else "{}")
            for k, x in v.items():
                walk(x, f"{k}: ", indent + "  ")
        elif isinstance(v, list):
            depth, x = 0, v
            while isinstance(x, list) and x:
                depth, x = depth + 1, x[0]
            if isinstance(x, dict):
                lines.append(f"{indent}{key}[{len(v)} x]")
                walk(x, "", indent + "  ")
            else:
                lines.append(f"{indent}{key}list{'[]' * depth} of {type(x).__name__ if v else 'nothing'} "
                             f"(length {len(v)})")
        else:
            lines.append(f"{indent}{key}{type(v).__name__ if v is not None else 'null'}"
                         f"{'  = ' + _short(v) if isinstance(v, (str, bool)) else ''}")

    walk(doc, "", "")
    return "\n".join(lines)
