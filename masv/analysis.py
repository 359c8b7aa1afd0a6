"""MASV analyses: 8x8 frequency responses, notches, coupling, closed-loop eigenvalues, loop
margins with the other loops closed, the TVSE (thrust vector servo elastic) loop break, and the
structural modes in the band of interest or near the actuator bandwidth.

Conventions: command -> piston is x_p,i / (R_i theta_c,j) and command -> engine is
theta_i / theta_c,j (dimensionless; element [f, i, j] is output i for command j). Gains are
reported in dB with a floor of -400 dB (an exactly zero coupling, e.g. on a rigid structure).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from taos.planar.freqresp import FrequencyResponse
from taos.linear import gain_db, notch_hz, phase_deg
from taos.stability import loop_margins as _loop_margins
from taos.planar.simplex import simplex_state_space

from .system import MasvSystem, build_system

GAIN_FLOOR = 1e-20   # |h| floor for dB (-400 dB)


def _db(h) -> np.ndarray:
    return gain_db(h, GAIN_FLOOR)


def band_grid(system: MasvSystem, n: int = 400) -> np.ndarray:
    """Log grid over the configuration's band of interest [Hz]."""
    c = system.config
    return np.logspace(math.log10(c.band_low_hz), math.log10(c.band_high_hz), n)


@dataclass(frozen=True, eq=False)
class MasvFrequencyResponse:
    """All eight command -> piston and command -> engine responses, (F, n_act, n_act) complex."""

    freq_hz: np.ndarray
    actuators: tuple[str, ...]
    piston: np.ndarray
    engine: np.ndarray
    provenance: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The ``masv freqresp`` JSON: gain_db/phase_deg indexed [output][command][freq]."""
        def part(h):
            return {"gain_db": np.moveaxis(_db(h), 0, -1).tolist(),
                    "phase_deg": np.moveaxis(phase_deg(h), 0, -1).tolist()}
        return {"freq_hz": [float(f) for f in self.freq_hz], "actuators": list(self.actuators),
                "piston": part(self.piston), "engine": part(self.engine), "provenance": self.provenance}

    def index(self, name: str) -> int:
        return self.actuators.index(name)

    def diagonal(self, name: str) -> FrequencyResponse:
        """Actuator ``name``'s own command -> piston/engine response as a taos FrequencyResponse."""
        k = self.index(name)
        return FrequencyResponse(self.freq_hz, self.piston[:, k, k], self.engine[:, k, k], None,
                                 engine_model="masv", provenance=dict(self.provenance))


def frequency_response(system: MasvSystem, freq_hz) -> MasvFrequencyResponse:
    """Exact linear 8x8 responses by block elimination (:meth:`MasvSystem.frf`)."""
    f = np.atleast_1d(np.asarray(freq_hz, float))
    xp, th = system.frf(f)
    piston = xp / system.moment_arms_m[None, :, None]
    cfg = system.config
    return MasvFrequencyResponse(f, system.actuator_names, piston, th,
                                 {"config_file": cfg.source, "config_sha256": cfg.sha256,
                                  "n_modes": int(system.omega_rad_s.size), "method": "block elimination"})


# -- notches ----------------------------------------------------------------------------------
def notch_frequencies(system: MasvSystem, n_grid: int = 400) -> dict[str, dict]:
    """Each actuator's notch (minimum of its own |x_p / (R theta_c)| in the band), refined with a
    bounded scalar search, beside the rigid-structure simplex notch sqrt((K_L R^2+K_n)/J)/2pi."""
    c = system.config
    n = len(system.actuator_names)
    notches = notch_hz(lambda f: np.abs(system.frf(f)[0][:, range(n), range(n)]), c.band_low_hz, c.band_high_hz,
                       n_grid, xatol=1e-7)
    out = {}
    for k, name in enumerate(system.actuator_names):
        f_notch = float(notches[k])
        a = system.config.actuators[k]
        model = system.config.engine(a.engine).model
        out[name] = {"notch_hz": f_notch,
                     "depth_db": float(_db(abs(system.frf([f_notch])[0][0, k, k]) / system.moment_arms_m[k])),
                     "simplex_load_resonance_hz": model.load_resonance_hz(a.axis)}
    return out


# -- coupling ---------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class CouplingResult:
    """Peak gains over the band [dB]: ``engine_peak_db[i, j]`` = max |theta_i / theta_c,j|,
    ``piston_peak_db[i, j]`` = max |x_p,i / (R_i theta_c,j)|, at ``engine_peak_hz``/
    ``piston_peak_hz``. Off-diagonal pairs on different engines are engine-to-engine coupling,
    on the same engine axis-to-axis coupling.

    Engine-to-engine coupling is reported beside the direct response (:meth:`engine_pairs`,
    :meth:`engine_to_engine`): both are peak gains over the same band, each relative to its own
    command, so ``below_direct_db`` = (direct peak of the commanded actuator) - (peak of another
    engine's actuator for that command) says how much smaller the cross response is than the
    commanded engine's own (positive: smaller)."""

    actuators: tuple[str, ...]
    engines: tuple[str, ...]
    band_hz: tuple[float, float]
    engine_peak_db: np.ndarray
    engine_peak_hz: np.ndarray
    piston_peak_db: np.ndarray
    piston_peak_hz: np.ndarray

    def _strongest(self, same_engine: bool, kind: str = "engine") -> dict | None:
        P = self.engine_peak_db if kind == "engine" else self.piston_peak_db
        H = self.engine_peak_hz if kind == "engine" else self.piston_peak_hz
        best = None
        n = len(self.actuators)
        for i in range(n):
            for j in range(n):
                if i == j or (self.engines[i] == self.engines[j]) != same_engine:
                    continue
                if best is None or P[i, j] > best[2]:
                    best = (i, j, P[i, j])
        if best is None:
            return None
        i, j, v = best
        return {"command": self.actuators[j], "response": self.actuators[i], "gain_db": float(v),
                "freq_hz": float(H[i, j])}

    def _kind(self, kind: str):
        if kind not in ("engine", "piston"):
            raise ValueError(f"kind must be 'engine' or 'piston', got {kind!r}")
        return (self.engine_peak_db, self.engine_peak_hz) if kind == "engine" else (self.piston_peak_db,
                                                                                    self.piston_peak_hz)

    def engine_pairs(self, kind: str = "engine") -> dict:
        """Per engine pair [dB]: ``peak_db[i][j]`` the largest peak gain of any actuator on engine i
        for a command to any actuator on engine j (i != j), on the diagonal the largest direct
        (own-actuator) peak on engine i; ``peak_hz`` where; ``kind`` 'engine' (theta / theta_c)
        or 'piston' (x_p / (R theta_c))."""
        P, H = self._kind(kind)
        names = list(dict.fromkeys(self.engines))
        n = len(names)
        peak, hz = np.full((n, n), -np.inf), np.zeros((n, n))
        for i in range(len(self.actuators)):
            for j in range(len(self.actuators)):
                a, b = names.index(self.engines[i]), names.index(self.engines[j])
                if (a == b) != (i == j):
                    continue  # same engine: only the direct responses; other engines: every pair
                if P[i, j] > peak[a, b]:
                    peak[a, b], hz[a, b] = P[i, j], H[i, j]
        return {"kind": kind, "engines": names, "peak_db": peak.tolist(), "peak_hz": hz.tolist()}

    def engine_to_engine(self, kind: str = "engine") -> dict | None:
        """The strongest engine-to-engine coupling beside the direct response: ``cross_db`` at
        ``cross_hz`` (command -> response actuators), ``direct_db`` the commanded actuator's own
        peak, and ``below_direct_db`` the smallest (direct - cross) over every cross pair [dB]
        (class docstring). None with a single engine."""
        P, H = self._kind(kind)
        best, below = None, math.inf
        n = len(self.actuators)
        for i in range(n):
            for j in range(n):
                if self.engines[i] == self.engines[j]:
                    continue
                below = min(below, float(P[j, j] - P[i, j]))
                if best is None or P[i, j] > P[best[0], best[1]]:
                    best = (i, j)
        if best is None:
            return None
        i, j = best
        return {"kind": kind, "command": self.actuators[j], "response": self.actuators[i],
                "cross_db": float(P[i, j]), "cross_hz": float(H[i, j]), "direct_db": float(P[j, j]),
                "direct_hz": float(H[j, j]), "below_direct_db": below}

    @property
    def strongest_engine_to_engine(self) -> dict | None:
        return self._strongest(False)

    @property
    def strongest_axis_to_axis(self) -> dict | None:
        return self._strongest(True)

    def to_dict(self) -> dict:
        return {"band_hz": list(self.band_hz), "actuators": list(self.actuators),
                "engine_peak_db": self.engine_peak_db.tolist(), "engine_peak_hz": self.engine_peak_hz.tolist(),
                "piston_peak_db": self.piston_peak_db.tolist(), "piston_peak_hz": self.piston_peak_hz.tolist(),
                "strongest_engine_to_engine": self.strongest_engine_to_engine,
                "strongest_axis_to_axis": self.strongest_axis_to_axis,
                "strongest_engine_to_engine_piston": self._strongest(False, "piston"),
                "strongest_axis_to_axis_piston": self._strongest(True, "piston"),
                "engine_to_engine": {k: self.engine_to_engine(k) for k in ("engine", "piston")},
                "engine_pairs": {k: self.engine_pairs(k) for k in ("engine", "piston")}}


def coupling(system: MasvSystem, n_freq: int = 400) -> CouplingResult:
    """Peak coupling gains over the band of interest (see :class:`CouplingResult`)."""
    fr = frequency_response(system, band_grid(system, n_freq))
    ge, gp = _db(fr.engine), _db(fr.piston)
    ie, ip = np.argmax(ge, axis=0), np.argmax(gp, axis=0)
    cfg = system.config
    return CouplingResult(fr.actuators, tuple(a.engine for a in cfg.actuators), (cfg.band_low_hz, cfg.band_high_hz),
                          ge.max(axis=0), fr.freq_hz[ie], gp.max(axis=0), fr.freq_hz[ip])


# -- closed-loop eigenvalues ------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class ClosedLoopEigen:
    """Eigenvalues [1/s] of the whole model with all eight position loops closed."""

    eigenvalues: np.ndarray

    @property
    def stable(self) -> bool:
        return bool(np.all(self.eigenvalues.real < 0))

    @property
    def max_real_per_s(self) -> float:
        return float(self.eigenvalues.real.max())

    def least_damped(self, n: int = 10) -> list[dict]:
        """The n oscillatory eigenvalues of lowest damping ratio (freq_hz, damping_ratio)."""
        p = self.eigenvalues[self.eigenvalues.imag > 0]
        z = -p.real / np.abs(p)
        o = np.argsort(z)[:n]
        return [{"freq_hz": float(abs(p[i]) / (2 * math.pi)), "damping_ratio": float(z[i])} for i in o]

    def to_dict(self) -> dict:
        return {"stable": self.stable, "max_real_per_s": self.max_real_per_s, "least_damped": self.least_damped()}


def closed_loop_eigenvalues(system: MasvSystem) -> ClosedLoopEigen:
    return ClosedLoopEigen(system.state_space().poles())


# -- loop margins -----------------------------------------------------------------------------
@dataclass(frozen=True)
class LoopMargin:
    """Margins of one actuator's position loop broken at its piston-position feedback with the
    other seven closed. L = T / (1 - T) with T = x_p / x_c (the valve sees K_v (x_c - x_p), so
    x_c and x_p enter the loop at the same summing point). ``gain_margin_db`` is the smallest
    -20 log|L| where L crosses the negative real axis (inf if it never does)."""

    actuator: str
    gain_margin_db: float
    phase_crossover_hz: float | None
    phase_margin_deg: float
    gain_crossover_hz: float | None

    def to_dict(self) -> dict:
        return {"actuator": self.actuator,
                "gain_margin_db": None if math.isinf(self.gain_margin_db) else self.gain_margin_db,
                "phase_crossover_hz": self.phase_crossover_hz,
                "phase_margin_deg": None if math.isinf(self.phase_margin_deg) else self.phase_margin_deg,
                "gain_crossover_hz": self.gain_crossover_hz}


def _crossing(x, y0, y1):
    """Fraction t in [0, 1] where the linear interpolation y0 + t (y1 - y0) is zero."""
    return y0 / (y0 - y1) if y0 != y1 else 0.0


def margins_from_loop(name: str, f: np.ndarray, L: np.ndarray) -> LoopMargin:
    """Gain and phase margins of loop transfer L sampled on ascending f: the smallest over every
    crossing that :func:`taos.stability.loop_margins` finds (interpolated between samples)."""
    if not np.any(L):  # no loop (e.g. the TVSE loop on a rigid structure)
        return LoopMargin(name, math.inf, None, math.inf, None)
    lm = _loop_margins(f, L)
    gm = lm.min_gain_margin_db
    k = int(np.argmin(lm.gain_margin_db)) if lm.gain_margin_db.size else None
    pm, fpm = lm.min_phase_margin
    return LoopMargin(name, float(gm), None if k is None else float(lm.phase_crossover_hz[k]), float(pm), fpm)


def actuator_loop_margins(system: MasvSystem, f_lo_hz: float = 0.01, f_hi_hz: float = 1000.0,
                 n: int = 3000) -> tuple[LoopMargin, ...]:
    """Margins of every actuator's position loop with the other loops closed (:class:`LoopMargin`)."""
    f = np.logspace(math.log10(f_lo_hz), math.log10(f_hi_hz), n)
    xp, _ = system.frf(f)
    out = []
    for k, name in enumerate(system.actuator_names):
        T = xp[:, k, k] / system.moment_arms_m[k]
        out.append(margins_from_loop(name, f, T / (1.0 - T)))
    return tuple(out)


# -- TVSE loop break -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class TvseLoop:
    """The Thrust Vector Servo Elastic loop of one actuator (paper sec. 3.3; Greensite, *Analysis
    and Design of Space Vehicle Flight Control Systems*, 1970, on the TWD/DWT coupling): the
    loop broken between the flexible-body dynamics and the engine's inertial coupling into the
    structure (:meth:`masv.system.MasvSystem.tvse_loop`), ``loop`` L(j w) (F,) complex on
    ``freq_hz`` [Hz], its largest gain ``peak_db`` at ``peak_hz``, and its margins
    (:func:`margins_from_loop`: critical point -1). Drawn by :func:`masv.plotting.plot_tvse_loops`."""

    actuator: str
    freq_hz: np.ndarray
    loop: np.ndarray
    margin: LoopMargin
    peak_db: float
    peak_hz: float

    def to_dict(self) -> dict:
        return {"actuator": self.actuator, "peak_db": self.peak_db, "peak_hz": self.peak_hz,
                "margin": self.margin.to_dict()}


def tvse_loops(system: MasvSystem, freq_hz=None) -> tuple[TvseLoop, ...]:
    """TVSE loop of every actuator, each broken alone with everything else closed (:class:`TvseLoop`;
    default grid 0.1-100 Hz, 3000 points). On a rigid structure there is no loop (L = 0, infinite
    margins)."""
    f = np.logspace(-1, 2, 3000) if freq_hz is None else np.atleast_1d(np.asarray(freq_hz, float))
    out = []
    loops = system.tvse_loop(f)
    for k, name in enumerate(system.actuator_names):
        L = loops[:, k]
        i = int(np.argmax(np.abs(L)))
        out.append(TvseLoop(name, f, L, margins_from_loop(name, f, L), float(_db(L[i])), float(f[i])))
    return tuple(out)


# -- modes near the actuator bandwidth --------------------------------------------------------
def actuator_bandwidth_hz(model, axis: str = "pitch") -> float:
    """-3 dB frequency [Hz] of the rigid-structure simplex command -> engine response."""
    ss = simplex_state_space(model, axis)
    f = np.logspace(-1, 2.5, 2000)
    g = _db(ss.freqresp(f, "command_rad", "theta_rad"))
    i = int(np.argmax(g < -3.0))
    if g[i] >= -3.0:
        return float(f[-1])
    t = _crossing(None, g[i - 1] + 3.0, g[i] + 3.0)
    return float(10 ** (math.log10(f[i - 1]) + t * (math.log10(f[i]) - math.log10(f[i - 1]))))


@dataclass(frozen=True, eq=False)
class ModeParticipation:
    """The structure's modes within ``band_hz`` [Hz] (the configuration's band of interest, or
    [bandwidth / factor, bandwidth * factor] around the actuator bandwidth). For each mode i and
    actuator k: ``phi_e[i, k]`` the mode's elongation shape along the line of action
    [m/sqrt(kg)] and ``compliance_ratio[i, k]`` = K_L,k phi_e^2 / w_i^2, the static compliance
    the mode adds in series with the load path relative to 1/K_L (0.1 = 10 % softer load
    path). ``factor`` is None for the configuration's band."""

    bandwidth_hz: float
    factor: float | None
    actuators: tuple[str, ...]
    mode_index: np.ndarray
    freq_hz: np.ndarray
    damping_ratio: np.ndarray
    phi_e: np.ndarray
    compliance_ratio: np.ndarray
    n_modes_total: int
    band_hz: tuple[float, float] = (0.0, math.inf)

    @property
    def band_source(self) -> str:
        return "config [band]" if self.factor is None else f"actuator bandwidth x/÷ {self.factor:g}"

    def to_dict(self) -> dict:
        return {"bandwidth_hz": self.bandwidth_hz, "band_hz": list(self.band_hz), "band_source": self.band_source,
                "n_modes_total": self.n_modes_total, "actuators": list(self.actuators),
                "modes": [{"mode": int(self.mode_index[i]) + 1, "freq_hz": float(self.freq_hz[i]),
                           "damping_ratio": float(self.damping_ratio[i]),
                           "phi_e_m_per_sqrt_kg": self.phi_e[i].tolist(),
                           "compliance_ratio": self.compliance_ratio[i].tolist(),
                           "max_compliance_ratio": float(self.compliance_ratio[i].max())}
                          for i in range(self.freq_hz.size)]}


def median_actuator_bandwidth_hz(system: MasvSystem) -> float:
    """Median over the actuators of :func:`actuator_bandwidth_hz` [Hz] (each model/axis once)."""
    cfg = system.config
    seen: dict = {}
    for a in cfg.actuators:
        m = cfg.engine(a.engine).model
        key = (id(m), a.axis)
        if key not in seen:
            seen[key] = actuator_bandwidth_hz(m, a.axis)
    return float(np.median([seen[(id(cfg.engine(a.engine).model), a.axis)] for a in cfg.actuators]))


def modes_in_band(system: MasvSystem, band_hz: tuple[float, float] | None = None,
                  factor: float | None = None, bandwidth_hz: float | None = None) -> ModeParticipation:
    """The structure's modes in ``band_hz`` [Hz] (default: the configuration's ``[band]``) and
    their participation at the actuator attach points (:class:`ModeParticipation`); ``factor``
    only labels a band built around the actuator bandwidth (the median of the actuators'
    simplex -3 dB frequencies, reported in either case; computed unless ``bandwidth_hz`` is
    given)."""
    cfg = system.config
    bw = median_actuator_bandwidth_hz(system) if bandwidth_hz is None else float(bandwidth_hz)
    lo, hi = (cfg.band_low_hz, cfg.band_high_hz) if band_hz is None else (float(band_hz[0]), float(band_hz[1]))
    fz = system.omega_rad_s / (2 * math.pi)
    sel = np.nonzero((fz >= lo) & (fz <= hi))[0]
    na = system.n_actuators
    KL = np.array([cfg.engine(a.engine).model.structure.load_stiffness_N_per_m for a in cfg.actuators])
    pe = system.phi_c[:na, sel].T
    ratio = KL[None] * pe ** 2 / system.omega_rad_s[sel, None] ** 2
    return ModeParticipation(bw, factor, system.actuator_names, sel, fz[sel], system.zeta[sel], pe, ratio,
                             int(fz.size), (lo, hi))


def modes_near_bandwidth(system: MasvSystem, factor: float = 2.0) -> ModeParticipation:
    """Structural modes within [bandwidth / factor, bandwidth * factor] of the actuator
    bandwidth (:func:`modes_in_band`)."""
    bw = median_actuator_bandwidth_hz(system)
    return modes_in_band(system, (bw / factor, bw * factor), factor, bw)


def structure_effect(system: MasvSystem) -> dict:
    """Loop margins with the structure and on a rigid structure, and their differences: does the
    structure (its local modes near the actuator bandwidth) degrade any actuator loop?"""
    from .structure import rigid_structure
    st = system.config.structure
    rigid = build_system(system.config, rigid_structure(st.node_names, st.node_xyz_m))
    with_s, without = actuator_loop_margins(system), actuator_loop_margins(rigid)
    rows = []
    for a, b in zip(with_s, without):
        rows.append({"actuator": a.actuator, "with_structure": a.to_dict(), "rigid": b.to_dict(),
                     "delta_phase_margin_deg": a.phase_margin_deg - b.phase_margin_deg,
                     "delta_gain_margin_db": (a.gain_margin_db - b.gain_margin_db)
                     if math.isfinite(a.gain_margin_db) and math.isfinite(b.gain_margin_db) else None})
    return {"loops": rows,
            "worst_phase_margin_deg": min(m.phase_margin_deg for m in with_s),
            "worst_gain_margin_db": min(m.gain_margin_db for m in with_s),
            "largest_phase_margin_loss_deg": max(-r["delta_phase_margin_deg"] for r in rows)}
