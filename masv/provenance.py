"""Provenance of MASV results: the configuration, its modal file and every engine's model."""

from __future__ import annotations

from pathlib import Path

from taos.results import base_provenance, file_sha256, model_provenance, package_version


def config_provenance(cfg) -> dict:
    """Configuration file and hash, modal file and hash (none for a rigid or in-code structure),
    number of modes, how an FE file was imported, each engine's model provenance
    (:func:`taos.results.model_provenance`), package version and git revision."""
    src = cfg.structure.source
    modes_sha = file_sha256(src) if src and Path(src).is_file() else ""
    return {"config_file": cfg.source, "config_sha256": cfg.sha256, "modes_file": src, "modes_sha256": modes_sha,
            "n_modes": cfg.structure.n_modes, "structure_import": dict(cfg.structure_import),
            "engines": {e.name: model_provenance(e.model) for e in cfg.engines},
            "taos_version": package_version(), **base_provenance()}
