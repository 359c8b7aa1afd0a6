"""The LCO verdict map as a stored, resumable campaign on the Monte Carlo engine.

A map point is a run of the campaign engine (:mod:`taos.montecarlo.engine`): the design's rows
are the swept values [SI] of every grid point, the run kind (:class:`VerdictMapRuns`) carries the
parsed flight loop and TVC model (no worker opens a file) and analyses a batch of points with
:func:`taos.flight.lco_map.map_points` (one describing-function map per TVC variant in the
batch, the confirmation runs on the worker's threads). The rows are ordered so that the points of
one TVC variant are adjacent and, on Dask, a batch is one variant's points: each map is made
once. The store's ``run`` coordinate is the point's flat index in the grid (C order).

Output folder (only these names are written)::

    map.json   manifest: format, inputs and their content hash, settings, design hash, batch size
    map.zarr   the store (:mod:`taos.montecarlo.store` layout): per point the factors (swept
               values), status, error, and :data:`taos.flight.lco_map.POINT_SCALARS` /
               ``POINT_FLAGS``

``resume=True`` runs the points still pending and refuses a folder whose inputs, settings or
grid differ. ``workers=0`` (default) runs in this process, without Dask.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.flight.lco_map import POINT_FLAGS, POINT_SCALARS, SWEEPABLE, LcoMap, MapSettings, grid_rows, \
    loop_margins_of, map_points
from taos.flight.vehicle import FlightModel
from taos.model import TvcModel

FORMAT = "taos-lco-map-2"   # 2: the grid_may_miss_cycle flag, maps extended at their edges
MANIFEST = "map.json"
STORE = "map.zarr"
OUTPUT_NAMES = (MANIFEST, STORE)


@dataclass(frozen=True, eq=False)
class VerdictMapRuns:
    """The engine's run kind of a verdict map (:class:`taos.montecarlo.engine.RunKind`)."""

    flight: FlightModel
    model: TvcModel
    settings: MapSettings
    inputs_sha256: str
    threads: int | None = None
    scalars: tuple[str, ...] = POINT_SCALARS
    flags: tuple[str, ...] = POINT_FLAGS
    run_cost_s: float = 1.0

    @property
    def trace_t_s(self) -> np.ndarray:
        return np.zeros(0)

    def run_batch(self, names, factors: np.ndarray, seeds: np.ndarray) -> dict:
        from taos.montecarlo.store import STATUS
        n = len(seeds)
        joint = True
        try:
            pts = [map_points(self.flight, self.model, names, factors, self.settings, threads=self.threads)]
            status, err = np.full(n, STATUS["ok"], np.int8), [""] * n
        except (SimulationUnstable, InputError, ValueError):   # one point at a time, to keep the others
            joint, pts, status, err = False, [], np.zeros(n, np.int8), []
            for i in range(n):
                try:
                    pts.append(map_points(self.flight, self.model, names, factors[i:i + 1], self.settings,
                                          threads=self.threads))
                    status[i], e = STATUS["ok"], ""
                except SimulationUnstable as ex:
                    pts.append(None)
                    status[i], e = STATUS["diverged"], f"unstable: {ex}"
                except (InputError, ValueError) as ex:
                    pts.append(None)
                    status[i], e = STATUS["failed"], str(ex)
                err.append(e)
        out = {"status": status, "error": err, "trace": np.zeros((n, 0))}
        for k in POINT_SCALARS + POINT_FLAGS:
            fill = False if k in POINT_FLAGS else np.nan
            if joint:
                out[k] = pts[0][k]
            else:
                out[k] = np.array([fill if p is None else p[k][0] for p in pts])
        return out


def variant_order(names, rows: np.ndarray) -> np.ndarray:
    """Row order that keeps the points of one TVC variant (same TVC values) adjacent, stable."""
    tvc = [j for j, n in enumerate(names) if SWEEPABLE[n][0] != "fcs"]
    keys = [tuple(r[tvc]) for r in rows]
    uniq = {k: i for i, k in enumerate(dict.fromkeys(keys))}
    return np.argsort([uniq[k] for k in keys], kind="stable")


def _check_out(out: Path, manifest: dict, resume: bool) -> dict | None:
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", "a folder for the map campaign (or a new path)", got=f"{out} (a file)")
    mpath = out / MANIFEST
    if not mpath.exists():
        clash = [n for n in OUTPUT_NAMES if (out / n).exists()]
        if clash:
            raise InputError("command line", "--out", "a folder whose map file names are free (files taos did not "
                             "write are never replaced)", got=f"{out / clash[0]} exists")
        if resume:
            raise InputError("command line", "--resume", "a folder with a map campaign to resume", got=str(out))
        return None
    try:
        old = json.loads(mpath.read_text())
    except (OSError, ValueError):
        raise InputError(str(mpath), "(file)", "a map manifest written by taos lco --out", got="an unreadable file") \
            from None
    if not resume:
        raise InputError("command line", "--out", "a folder without a map campaign in it (or --resume to continue it)",
                         got=str(out))
    for k in ("format", "inputs_sha256", "design_sha256"):
        if old.get(k) != manifest[k]:
            what = {"inputs_sha256": "inputs and settings (a file or an option changed)",
                    "design_sha256": "grid"}.get(k, k)
            raise InputError(str(mpath), k, f"the same {what} to resume this map", got=f"{manifest[k]!r} (stored: "
                             f"{old.get(k)!r})")
    return old


def run_map_campaign(flight: FlightModel, model: TvcModel, axes, settings: MapSettings, out_dir, *,
                     inputs_sha256: str, input_files: list, workers: int = 0, scheduler: str | None = None,
                     resume: bool = False, progress: bool = False) -> tuple[LcoMap, list[dict]]:
    """Run the map of ``axes`` as a campaign into ``out_dir`` (module docstring); returns the map
    and the points that failed ({"at": {name: value}, "status", "error"})."""
    from taos.montecarlo import engine, store
    from taos.montecarlo.engine import Design, Part
    from taos.results import atomic_write, package_version

    names = tuple(a.name for a in axes)
    rows = grid_rows(axes)
    perm = variant_order(names, rows)
    design = Design(names, rows[perm], np.zeros(len(rows), np.int64))
    kind = VerdictMapRuns(flight, model, settings, inputs_sha256)
    out = Path(out_dir)
    manifest = {"format": FORMAT, "inputs_sha256": inputs_sha256, "input_files": input_files,
                "settings": dataclasses.asdict(settings), "parameters": list(names),
                "values": [list(a.values) for a in axes], "design_sha256": design.sha256(),
                "package_version": package_version()}
    old = _check_out(out, manifest, resume)
    spath = out / STORE
    with engine.connected(workers, scheduler) as client:
        n_workers = len(client.scheduler_info().get("workers", {})) if client is not None else 0
        n_var = len({tuple(r[[j for j, n in enumerate(names) if SWEEPABLE[n][0] != "fcs"]]) for r in rows})
        if old is not None and store.status(spath) is not None:
            batch = int(old["batch"])
        else:
            if client is None:
                batch = design.n                         # one batch: every point on this process's threads
            elif n_var > 1:
                batch = design.n // n_var                # one TVC variant (one describing-function map) a batch
            else:
                batch = max(1, math.ceil(design.n / max(n_workers, 1)))
            manifest["batch"] = batch
            out.mkdir(parents=True, exist_ok=True)
            atomic_write(out / MANIFEST, lambda q: q.write_text(json.dumps(manifest, indent=1) + "\n"))
            if spath.exists():
                import shutil
                shutil.rmtree(spath)
            store.create(spath, labels=perm, names=names, factors=design.factors, seeds=design.seeds,
                         scalars=kind.scalars, flags=kind.flags, trace_t_s=kind.trace_t_s, batch=batch,
                         attrs={"format": FORMAT, "inputs_sha256": inputs_sha256,
                                "friction_model": model.friction.name})
        engine.execute(spath, kind, [Part(None, design)], batch, client, progress=progress)
    return read_map(spath, axes, model.friction.name, loop_margins_of(flight, axes), settings)


def read_map(spath: Path, axes, friction_model: str, lgm: dict, settings: MapSettings) -> tuple[LcoMap, list[dict]]:
    """The map stored at ``spath`` (rows put back in grid order) and its failed points."""
    from taos.montecarlo import store
    ds = store.open_store(spath, dask=False)
    idx = np.asarray(ds["run"].values, np.int64)
    n = idx.size
    pts = {}
    for k in POINT_SCALARS + POINT_FLAGS:
        v = np.asarray(ds[k].values)
        g = np.empty(n, v.dtype)
        g[idx] = v
        pts[k] = g
    st = np.asarray(ds["status"].values)
    err = np.asarray(ds["error"].values)
    rows = np.asarray(ds["factor"].values)
    names = [a.name for a in axes]
    failed = [{"at": dict(zip(names, map(float, rows[i]))), "status": [k for k, c in store.STATUS.items()
                                                                     if c == st[i]][0], "error": str(err[i])}
              for i in range(n) if st[i] != store.STATUS["ok"]]
    return LcoMap.from_points(tuple(axes), pts, friction_model, lgm, settings), failed
