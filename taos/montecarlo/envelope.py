"""A flight against its Monte Carlo envelope (issue 43): percentile envelopes of the stored
actuator command and engine angle over time, and a flight record overlaid with the fraction of
time outside.

A campaign stores, per run, the FCS command [rad] (the TVC command, PTI included) and the engine
angle theta [rad] of its axis at the trace interval (``trace`` and ``engine_trace`` (run, time) of
:mod:`taos.montecarlo.store`, ``time`` [s] the ascent clock): the :data:`QUANTITIES` ``command``
and ``engine``. :func:`envelope` reads the ok runs of a campaign folder and gives, at each stored
time t_j, the percentiles P_p(t_j) over the runs (``numpy.percentile``, linear interpolation
between order statistics). A store written before the engine angle was stored has no engine
trace: asking it for the engine envelope is bad input, named (run the campaign again).

:func:`compare_to_envelope` puts a record on the envelope's times (linear interpolation of the
record's signal of the envelope's quantity, ``command_rad`` or ``engine_rad``, on the campaign's
axis over the times both cover) and counts the samples outside the outermost band [P_lo, P_hi]:

    fraction_outside = #{j : x(t_j) < P_lo(t_j) or x(t_j) > P_hi(t_j)} / #{j}

on the uniform trace grid, i.e. the fraction of the overlapping time outside (with the fractions
above and below). For a record drawn from the campaign's own population the expected fraction is
(lo + 100 - hi) / 100 (10 % for the 5-95 % band). Plot: :func:`taos.plotting.envelope.plot_envelope`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError

#: stored quantity -> (store variable, the record's signal)
QUANTITIES = {"command": ("trace", "command_rad"), "engine": ("engine_trace", "engine_rad")}
DEFAULT_PERCENTILES = (5.0, 50.0, 95.0)


@dataclass(frozen=True, eq=False)
class Envelope:
    """Percentile bands ``bands_rad`` (n_percentiles, n_times) [rad] of ``quantity`` over the
    ``runs_ok`` completed runs of a campaign, at ``t_s`` [s]; ``axis`` the campaign's axis;
    ``provenance`` the store's attributes and the campaign folder."""

    quantity: str
    axis: str | None
    t_s: np.ndarray
    percentiles: tuple[float, ...]
    bands_rad: np.ndarray
    runs_ok: int
    provenance: dict = field(default_factory=dict)

    def band(self, p: float) -> np.ndarray:
        return self.bands_rad[self.percentiles.index(p)]

    def to_dict(self) -> dict:
        return {"quantity": self.quantity, "axis": self.axis, "t_s": self.t_s.tolist(),
                "percentiles": list(self.percentiles), "runs_ok": self.runs_ok,
                "bands_deg": {f"p{p:g}": np.degrees(b).tolist() for p, b in zip(self.percentiles, self.bands_rad)},
                "provenance": self.provenance}


def _check_percentiles(percentiles) -> tuple[float, ...]:
    try:
        ps = tuple(float(p) for p in percentiles)
    except (TypeError, ValueError):
        ps = ()
    if (len(ps) < 2 or any(isinstance(p, bool) for p in percentiles) or not all(0 < p < 100 for p in ps)
            or list(ps) != sorted(set(ps))):
        raise InputError("envelope", "percentiles", "at least two increasing percentiles between 0 and 100, "
                         "like 5, 50, 95", got=repr(percentiles))
    return ps


def envelope(campaign_dir, quantity: str = "command", percentiles=DEFAULT_PERCENTILES) -> Envelope:
    """The percentile envelope (module docstring) of ``quantity`` over the ok runs of the campaign
    written to ``campaign_dir`` (the ``taos montecarlo --out`` folder, or its ``campaign.zarr``)."""
    from taos.montecarlo.store import STATUS, open_store

    ps = _check_percentiles(percentiles)
    if quantity not in QUANTITIES:
        raise InputError("envelope", "quantity", f"one of {', '.join(QUANTITIES)} (the stored traces: FCS "
                         "command, engine angle)", got=repr(quantity))
    p = Path(campaign_dir)
    zpath = p if p.suffix == ".zarr" else p / "campaign.zarr"
    folder = zpath.parent
    try:
        ds = open_store(zpath, consolidated=False, dask=False)
        st = np.asarray(ds["status"].values, np.int8)
        var = QUANTITIES[quantity][0]
        missing = var not in ds and "trace" in ds
        tr = None if missing else np.asarray(ds[var].values, float)
        t = np.asarray(ds["time"].values, float)
        attrs = dict(ds.attrs)
    except (OSError, KeyError, ValueError, FileNotFoundError) as e:
        raise InputError(str(campaign_dir), "campaign", "a Monte Carlo campaign folder (taos montecarlo --out)",
                         got=type(e).__name__) from None
    if missing:
        raise InputError(str(zpath), var, f"a campaign that stored the {quantity} trace (this store was written "
                         "before it was stored: run the campaign again)", got="a store without it")
    ok = st == STATUS["ok"]
    if ok.sum() < 2 or t.size < 2:
        raise InputError(str(campaign_dir), "campaign", "at least two completed runs with a trace",
                         got=f"{int(ok.sum())} completed runs, {t.size} trace samples")
    bands = np.percentile(tr[ok], ps, axis=0)
    axis = None
    try:
        src = json.loads((folder / "campaign.json").read_text()).get("campaign_file")
        if src:
            from taos.montecarlo import load_campaign
            axis = load_campaign(src).axis
    except (OSError, ValueError, InputError):
        pass
    prov = {k: (v.item() if hasattr(v, "item") else v) for k, v in attrs.items()} | {"campaign_dir": str(folder)}
    return Envelope(quantity, axis, t, ps, bands, int(ok.sum()), prov)


@dataclass(frozen=True, eq=False)
class EnvelopeComparison:
    """A record on an envelope: ``t_s`` [s] the envelope times the record covers, ``value_rad`` the
    record there, ``lo_rad`` / ``hi_rad`` the outermost band, the fractions of those samples
    (of the time) outside, above and below, and the band's percentiles."""

    t_s: np.ndarray
    value_rad: np.ndarray
    lo_rad: np.ndarray
    hi_rad: np.ndarray
    fraction_outside: float
    fraction_above: float
    fraction_below: float
    band_percentiles: tuple[float, float]
    source: str = ""
    quantity: str = "command"

    def to_dict(self) -> dict:
        return {"quantity": self.quantity, "record": self.source, "samples": int(self.t_s.size), "t_start_s": float(self.t_s[0]),
                "t_end_s": float(self.t_s[-1]), "band_percentiles": list(self.band_percentiles),
                "fraction_outside": self.fraction_outside, "fraction_above": self.fraction_above,
                "fraction_below": self.fraction_below,
                "expected_fraction_outside_if_from_the_campaign":
                    (self.band_percentiles[0] + 100 - self.band_percentiles[1]) / 100}


def compare_to_envelope(record, env: Envelope, axis: str | None = None) -> EnvelopeComparison:
    """The fraction of time ``record`` (a :class:`taos.flight.pti_record.FlightRecord`, or a pair
    (t [s], value [rad]) of ``env``'s quantity) spends outside ``env``'s outermost band (module
    docstring), on the campaign's ``axis`` (default the envelope's)."""
    sig = QUANTITIES[env.quantity][1]
    if isinstance(record, tuple):
        t, x = (np.asarray(a, float) for a in record)
        src = "<arrays>"
    else:
        ax = axis or env.axis or (record.axes[0] if len(record.axes) == 1 else None)
        if ax not in record.axes:
            raise InputError(getattr(record, "source", "record"), "axis", f"one of the record's axes "
                             f"{', '.join(record.axes)} (the campaign's)", got=repr(ax))
        t, x, src = np.asarray(record.t_s, float), record.signal(sig, ax), record.source
        if x is None:
            raise InputError(src, f"{ax}_{sig}", f"the record's {env.quantity} signal for its {env.quantity} envelope",
                             got="a record without it")
    if t.ndim != 1 or t.shape != x.shape or t.size < 2 or not np.all(np.isfinite(x)):
        raise InputError(src, sig, f"a finite {env.quantity} sampled at increasing times", got=f"{t.shape} samples")
    sel = (env.t_s >= t[0]) & (env.t_s <= t[-1])
    if sel.sum() < 1:
        raise InputError(src, "t_s", f"a record overlapping the envelope's {env.t_s[0]:g}-{env.t_s[-1]:g} s",
                         got=f"{t[0]:g}-{t[-1]:g} s")
    te = env.t_s[sel]
    v = np.interp(te, t, x)
    lo, hi = env.bands_rad[0][sel], env.bands_rad[-1][sel]
    above, below = v > hi, v < lo
    n = te.size
    return EnvelopeComparison(te, v, lo, hi, float((above | below).sum() / n), float(above.sum() / n),
                              float(below.sum() / n), (env.percentiles[0], env.percentiles[-1]), src, env.quantity)


def record_against_campaign(record, campaign_dir, percentiles=DEFAULT_PERCENTILES, axis: str | None = None
                            ) -> dict[str, tuple[Envelope, EnvelopeComparison | None, str | None]]:
    """Every stored quantity of a campaign against ``record``: quantity -> (envelope, comparison,
    why there is no comparison). The command is required (bad input when it cannot be compared);
    the engine angle is compared when both the store and the record carry it, else its comparison
    is None with the reason (and its envelope None too for a store written before it)."""
    env = envelope(campaign_dir, "command", percentiles)
    out = {"command": (env, compare_to_envelope(record, env, axis), None)}
    try:
        eng = envelope(campaign_dir, "engine", percentiles)
    except InputError as e:
        return out | {"engine": (None, None, str(e))}
    try:
        out["engine"] = (eng, compare_to_envelope(record, eng, axis), None)
    except InputError as e:
        out["engine"] = (eng, None, str(e))
    return out
