"""Writing model files from code (tomlkit documents): what a fit or a reduction writes back.

:func:`inline_actuator_parameter_set` replaces ``[actuator] parameter_set`` by the set's keys, so a
file describing a fitted (or otherwise edited) actuator holds that actuator itself.
"""

from __future__ import annotations

from pathlib import Path

from taos.model import PARAMETER_SET_KEY, _parameter_set


def inline_actuator_parameter_set(doc, model_path: Path, src: str) -> bool:
    """Replace ``[actuator] parameter_set`` in a tomlkit document of a model file by the set's
    keys, so the file describes its own actuator (a fitted or edited actuator is a different
    piece of hardware, hence no longer the shared set). Returns False if there was no set."""
    import tomlkit

    tab = doc.get("actuator")
    if tab is None or PARAMETER_SET_KEY not in tab:
        return False
    ref = tab[PARAMETER_SET_KEY]
    ppath, shared = _parameter_set(str(ref), Path(model_path), src, "actuator")
    del tab[PARAMETER_SET_KEY]
    tab.add(tomlkit.comment(f"inlined from the shared actuator set {ppath.as_posix()}: this file's own actuator"))
    for k, v in shared.items():
        tab[k] = v
    return True
