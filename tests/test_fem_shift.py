"""The FEM-explained share of the ambient -> hot-fire load-stiffness shift comes with its range over
plausible gimbal geometry (issue 24.8): the committed sweep (fem_data/fem_shift_range.toml, written
by scripts/fem_shift_sensitivity.py) covers at least the corners of the documented ranges, its
min/max are those of its points, the nominal lies inside, and two of its points are recomputed
here with the FEM pipeline."""

from __future__ import annotations

import itertools

import pytest

from taos.fem.build import engine_actuator_line, run_level
from taos.fem.gimbal import GimbalGeometry, MeshSpec, retainer_stress
from taos.fem.load_path import implied_load_stiffness
from taos.fem.shift import (LIP_RANGE_M, PAPER_RATIO, SEAT_SPHERE_RADIUS_RANGE_M, explained_share,
                            fem_shift_share, swept_geometry)


def test_share_definition():
    assert explained_share(1.0) == 0.0 and explained_share(PAPER_RATIO) == pytest.approx(1.0)
    assert explained_share(1.35) == pytest.approx(0.35 / (205 / 115 - 1))


def test_swept_geometry_is_the_shipped_one_at_the_nominal_point():
    g = GimbalGeometry()
    s = swept_geometry(g.lip_top - g.lip_bottom, g.seat_sphere_radius)
    for f in ("bore_radius", "seat_radius", "lip_inner_radius", "shoulder_radius", "lip_top"):
        assert getattr(s, f) == pytest.approx(getattr(g, f), abs=1e-12)


def test_committed_range_covers_the_corners_and_contains_the_nominal():
    r = fem_shift_share()
    pts = {(round(p.lip_m, 6), round(p.seat_sphere_radius_m, 6)): p for p in r.points}
    for t, rs in itertools.product(LIP_RANGE_M, SEAT_SPHERE_RADIUS_RANGE_M):
        assert (round(t, 6), round(rs, 6)) in pts and pts[round(t, 6), round(rs, 6)].share is not None
    shares = [p.share for p in r.points if p.share is not None] + [r.nominal]
    assert r.minimum == min(shares) and r.maximum == max(shares)
    assert r.minimum <= r.nominal <= r.maximum and r.minimum < r.maximum
    # every plausible geometry holds the hanging engine below yield (~880 MPa), recomputed
    for p in r.points:
        g = swept_geometry(p.lip_m, p.seat_sphere_radius_m)
        assert p.lip_stress_Pa == pytest.approx(retainer_stress(g)["lip"], rel=1e-9) and p.lip_stress_Pa < 880e6
        assert p.share == pytest.approx(explained_share(p.ratio), rel=1e-12)
    # the convergence check: the nominal share on the sweep's mesh within 0.1 of the finest level
    assert r.fine_nominal is not None and abs(r.fine_nominal - r.nominal) < 0.1
    assert "range" in r.text() and f"{100 * r.minimum:.0f}-{100 * r.maximum:.0f} %" in r.text()


@pytest.mark.slow
def test_two_points_of_the_sweep_recomputed_with_the_fem():
    r = fem_shift_share()
    spec, line = MeshSpec(r.mesh_h_m, r.mesh_n_theta), engine_actuator_line()
    lo = min((p for p in r.points if p.share is not None), key=lambda p: p.share)
    for lip, rs, want in ((0.004, 0.110, r.nominal), (lo.lip_m, lo.seat_sphere_radius_m, lo.share)):
        lv = run_level(swept_geometry(lip, rs), spec, line)
        sh = implied_load_stiffness(lv.compliance["hanging"], lv.compliance["thrust"])
        assert explained_share(sh.ratio) == pytest.approx(want, rel=1e-6)
