"""Layouts of the output files, read from files the guide commands made (so they stay true)."""

from __future__ import annotations

import json
from pathlib import Path


def _short(v) -> str:
    s = v if isinstance(v, str) else str(v)
    s = s.replace("\n", " ")
    return s if len(s) <= 60 else s[:57] + "..."


def h5_layout(path: Path, max_items: int = 60) -> str:
    """Text tree of an HDF5 file: groups, datasets (shape, dtype) and attributes."""
    import h5py

    lines: list[str] = []

    def attrs(obj, indent):
        for k in sorted(obj.attrs):
            v = obj.attrs[k]
            if isinstance(v, bytes):
                v = v.decode("utf-8", "replace")
            shown = _short(v) if (_shown(v) or not isinstance(v, str)) else "str (" + (
                "JSON" if v[:1] in "{[" else "text") + ")"
            lines.append(f"{indent}  @{k} = {shown}")

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


def _shown(v) -> bool:
    """Booleans and short words are shown as examples; paths and hashes (machine-specific) not."""
    return isinstance(v, bool) or (isinstance(v, str) and len(v) < 40 and "/" not in v)


def json_layout(path: Path) -> str:
    """Text tree of a JSON file: keys with the type (and length) of each value."""
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    lines: list[str] = []

    def walk(v, key, indent):
        if isinstance(v, dict):
            lines.append(f"{indent}{key}{{}}")
            for k, x in v.items():
                walk(x, f"{k}: ", indent + "  ")
        elif isinstance(v, list):
            depth, x = 0, v
            while isinstance(x, list) and x:
                depth, x = depth + 1, x[0]
            if isinstance(x, dict):
                lines.append(f"{indent}{key}[{len(v)} x {{}}], each:")
                walk(x, "", indent + "  ")
            else:
                lines.append(f"{indent}{key}list{'[]' * depth} of {type(x).__name__ if v else 'nothing'} "
                             f"(length {len(v)})")
        else:
            lines.append(f"{indent}{key}{type(v).__name__ if v is not None else 'null'}"
                         f"{'  = ' + _short(v) if _shown(v) else ''}")

    walk(doc, "", "")
    return "\n".join(lines)
