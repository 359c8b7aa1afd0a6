"""The lane variants of the limit laws and the avionics (vector loops across lockstep runs) give
every lane the bits of the single scalar definitions, on and off, inside and beyond every
threshold (the lockstep kernel's results rest on this)."""

from __future__ import annotations

import numpy as np
from numba import njit

from taos.planar import _avionics_kernels as av
from taos.planar import saturation as sat
from taos.planar._avionics_slots import AV_LSB, AV_NTAB, AV_ROUND, AV_TABLE


@njit(error_model="numpy")
def _scalar_laws(H, UV, Q, P, TH, OM, out):
    """The scalar laws lane by lane, as the previous lockstep kernel called them (inlined into a
    kernel compiled without fast-math): out rows valve excess, flow correction, stop torque."""
    for q in range(UV.shape[0]):
        h = H[:, q].copy()
        out[0, q] = sat.valve_excess(h, UV[q])
        out[1, q] = sat.pressure_flow_correction(h, Q[q], P[q])
        out[2, q] = sat.stop_torque(TH[q], OM[q], h[sat.LIM_THMAX], h[sat.LIM_KS], h[sat.LIM_CS])


@njit(error_model="numpy")
def _lane_laws(H, UV, Q, P, TH, OM, out):
    sat.valve_excess_lanes(H, UV, out[0])
    sat.pressure_flow_correction_lanes(H, Q, P, out[1])
    sat.stop_torque_lanes(H, TH, OM, out[2])


@njit(error_model="numpy")
def _avionics_lanes(C, P, out):
    av.apply_lanes(C, P, np.empty((2, C.shape[0])), out)


def _heads(rng, nl: int) -> np.ndarray:
    """Heads of nl lanes, a third of each limit off, the rest on with dispersed values."""
    H = np.zeros((sat.N_HEAD, nl))
    on = rng.random((3, nl)) > 1 / 3
    H[sat.LIM_VMAX] = np.where(on[0], rng.uniform(0.05, 0.3, nl), 0.0)
    H[sat.LIM_KVR] = 12.0
    H[sat.LIM_PS] = np.where(on[1], rng.uniform(1.5e7, 2.5e7, nl), 0.0)
    H[sat.LIM_EPS] = np.where(on[1], sat.SQRT_LAW_EPS, 0.0)
    H[sat.LIM_PR] = np.where(on[1] & (rng.random(nl) > 0.5), 1.1 * H[sat.LIM_PS], np.inf)
    H[sat.LIM_KRA] = np.where(on[1], rng.uniform(1e-9, 1e-7, nl), 0.0)
    H[sat.LIM_THMAX] = np.where(on[2], rng.uniform(0.1, 0.2, nl), 0.0)
    H[sat.LIM_KS] = 1e8
    H[sat.LIM_CS] = 1e6
    return H


def test_lane_limit_laws_give_the_scalar_laws_bits():
    rng = np.random.default_rng(5)
    nl = 4001  # not a multiple of the vector width: the scalar remainder is checked too
    H = _heads(rng, nl)
    ps = np.where(H[sat.LIM_PS] > 0, H[sat.LIM_PS], 2e7)
    UV = rng.normal(0.0, 0.3, nl)  # around +-v_max
    Q = rng.normal(0.0, 0.2, nl) * (rng.random(nl) > 0.05)  # q = 0 exactly on some lanes
    P = ps * rng.uniform(-2.5, 2.5, nl)  # margins d from -1.5 to 3.5: stall, relief, back-flow
    P[:50] = ps[:50] * (1.0 - sat.SQRT_LAW_EPS)  # on the regularisation's edges
    P[50:100] = ps[50:100] * (1.0 + sat.SQRT_LAW_EPS)
    TH = rng.normal(0.0, 0.2, nl)
    OM = rng.normal(0.0, 1.0, nl)
    a, b = np.empty((3, nl)), np.empty((3, nl))
    _scalar_laws(H, UV, Q, P, TH, OM, a)
    _lane_laws(H, UV, Q, P, TH, OM, b)
    for i in range(3):
        assert np.array_equal(a[i].view(np.int64), b[i].view(np.int64)), i  # bits, signed zeros included
    assert np.count_nonzero(a[0]) > nl // 4 and np.count_nonzero(a[2]) > nl // 10  # limits reached


def _avionics_pack(lsb: float, rounding: bool, mags, gains) -> np.ndarray:
    n = len(mags)
    p = np.zeros(AV_TABLE + 2 * n)
    p[AV_LSB], p[AV_ROUND], p[AV_NTAB] = lsb, float(rounding), float(n)
    p[AV_TABLE:AV_TABLE + n], p[AV_TABLE + n:] = mags, gains
    return p


#: the scalar law compiled here, without fast-math and without numba's on-disk cache: after
#: ``make .venv/.warm`` (which compiles it beside the fast-math planar kernels) the cached
#: ``av.apply`` gave 13 of 3000 commands 1 ulp away from a fresh compile (cause not pinned down;
#: FMA contraction is the likely one), while the lockstep kernel compiles its lanes without
#: fast-math. The Monte Carlo bit-identity (a run alone or in any company) is the lane kernel's
#: own and is tested in tests/test_montecarlo.py.
_scalar_avionics = njit(av.apply.py_func)


def test_lane_avionics_gives_the_scalar_avionics_bits():
    rng = np.random.default_rng(6)
    nl = 3001
    tables = [([], []), ([0.0], [0.891]), ([0.0, 1e-3, 4e-3, 2e-2], [0.95, 0.9, 0.97, 1.0]),
              ([1e-3, 1e-3, 5e-3], [0.9, 0.95, 1.0])]  # a repeated magnitude: the scan's first segment
    for mags, gains in tables:
        packs = np.stack([_avionics_pack(rng.choice([0.0, 1e-4, 3e-4]), rng.random() > 0.5, mags, gains)
                          for _ in range(nl)], axis=1)
        C = rng.normal(0.0, 5e-3, nl)
        C[:20] = 0.0
        C[20:40] = -1e-5  # quantised to -0.0 or +0.0
        want = np.array([_scalar_avionics(C[q], np.ascontiguousarray(packs[:, q])) for q in range(nl)])
        got = np.empty(nl)
        _avionics_lanes(C, np.ascontiguousarray(packs), got)
        assert np.array_equal(want.view(np.int64), got.view(np.int64)), mags
