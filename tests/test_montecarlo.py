"""Monte Carlo campaigns: honest statistics, global sensitivity through the engine, the store,
failed runs, inputs checked and hashed, connections. The Dask cluster tests are in
tests/test_montecarlo_cluster.py."""

from __future__ import annotations

import json
import math
import os
import shutil
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from taos.cli import main
from taos.errors import InputError
from taos.montecarlo import Design, Ishigami, load_campaign, open_store, run_campaign, run_design, wilson_interval
from taos.montecarlo import sensitivity as sens
from taos.montecarlo.campaign import run_factors
from taos.montecarlo.stats import holm, quantile_interval

DATA = Path(__file__).resolve().parent / "data"
ROOT = DATA.parent.parent
SHORT = DATA / "mc_short.toml"
FAILING = DATA / "mc_failing.toml"


def stats(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())["statistics"]


def copy_inputs(dst: Path) -> Path:
    """The short campaign with the model, flight and FEM files it reads, copied under ``dst``
    (the relative paths kept); returns the copied campaign file."""
    for d in ("models", "fem_data"):
        shutil.copytree(ROOT / d, dst / d)
    (dst / "tests" / "data").mkdir(parents=True)
    return Path(shutil.copy(SHORT, dst / "tests" / "data" / SHORT.name))


def test_wilson_interval_textbook_values():
    """Wilson (1927) score interval, 95 %: 5/10 -> (0.2366, 0.7634); 0/10 -> (0, 0.2775);
    81/263 -> (0.2553, 0.3662) (Newcombe, Stat. Med. 17 (1998) 857, table I)."""
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(81, 263) == pytest.approx((0.2553, 0.3662), abs=1e-4)


def test_order_statistic_intervals_match_the_tables():
    """Distribution-free 95 % interval of the median: ranks 40 and 61 for n = 100, 1 and 6 for
    n = 6 (Conover, Practical Nonparametric Statistics, table A3 / sec. 3.2); none for n = 5,
    and none for the 95th percentile of 20 runs."""
    assert quantile_interval(100, 0.5) == (40, 61)
    assert quantile_interval(6, 0.5) == (1, 6)
    assert quantile_interval(5, 0.5) is None
    assert quantile_interval(20, 0.95) is None


def test_holm_adjustment_by_hand():
    """p = (0.01, 0.04, 0.03, 0.005): sorted 0.005*4 = 0.02, 0.01*3 = 0.03, 0.03*2 = 0.06,
    0.04*1 -> max(0.06, 0.04) = 0.06."""
    assert holm([0.01, 0.04, 0.03, 0.005]) == pytest.approx([0.03, 0.06, 0.06, 0.02])


def test_logistic_regression_recovers_the_generating_law():
    """20,000 outcomes drawn from P = 1/(1 + exp(-(0.5 + 1.5 z1 - 1.0 z2))) with z3 inert: the
    fitted coefficients are within 4 standard errors of the truth; z3 is not significant."""
    rng = np.random.default_rng(1)
    x = rng.normal(size=(20_000, 3)) * [2.0, 0.5, 1.0] + [10.0, 1.0, 3.0]
    z = (x - x.mean(axis=0)) / x.std(axis=0)
    yes = rng.random(20_000) < 1 / (1 + np.exp(-(0.5 + 1.5 * z[:, 0] - 1.0 * z[:, 1])))
    r = sens.logistic_regression(["a", "b", "c"], x, yes)
    c = {row["parameter"]: row for row in r["coefficients"]}
    assert r["converged"]
    for name, truth in (("a", 1.5), ("b", -1.0), ("c", 0.0)):
        assert abs(c[name]["coefficient_per_std"] - truth) < 4 * c[name]["std_error"]
    assert c["a"]["significant"] and c["b"]["significant"] and not c["c"]["significant"]
    assert sens.logistic_regression(["a"], x[:, :1], np.ones(20_000, bool)) is None



def test_separated_outcome_is_reported_not_an_infinite_odds_ratio():
    """Complete separation (Albert and Anderson 1984): every run with factor a above its median
    limit-cycles, none below; no maximum-likelihood coefficient exists. The result says so,
    keeps the sign of a's effect, and is valid JSON (no inf/NaN); before, the odds ratio
    overflowed to inf and the campaign's summary could not be written (exit 1 on 200 soft runs)."""
    rng = np.random.default_rng(3)
    x = rng.normal(size=(400, 2))
    yes = x[:, 0] > np.median(x[:, 0])
    r = sens.logistic_regression(["a", "b"], x, yes)
    assert r["separation"] and "separated" in r["note"]
    c = {row["parameter"]: row for row in r["coefficients"]}
    assert c["a"]["direction"] == 1 and c["a"]["odds_ratio_per_std"] is None and not c["a"]["significant"]
    json.dumps(r, allow_nan=False)

def test_runs_are_pure_functions_of_seed_and_index():
    c = load_campaign(SHORT)
    a = [run_factors(c, i) for i in range(5)]
    assert a == [run_factors(c, i) for i in range(5)]
    assert len({s for s, _ in a}) == 5
    assert run_factors(c, -1)[1] == {d.name: 1.0 for d in c.dispersions}


def test_sobol_indices_of_ishigami_through_the_engine(tmp_path):
    """Saltelli design of the Ishigami function (a = 7, b = 0.1) run through the campaign engine
    and store (in this process): S1 and ST within their bootstrap intervals (widened 1.5x) and
    0.04 of the closed-form indices (S1 = 0.314, 0.442, 0; ST = 0.558, 0.442, 0.244)."""
    kind = Ishigami()
    prob = kind.problem()
    x = sens.design("sobol", prob, 4096, seed=3)
    ds = run_design(kind, Design(("x1", "x2", "x3"), x, np.zeros(len(x), np.int64)), tmp_path / "ish.zarr", workers=0)
    assert ds.sizes["run"] == 4096 * 5 and bool((ds["status"].values == 1).all())
    rows = {r["parameter"]: r for r in sens.indices("sobol", prob, ds["factor"].values, ds["y"].values, seed=3)}
    exact = kind.analytic_indices()
    for i, name in enumerate(("x1", "x2", "x3")):
        for k in ("S1", "ST"):
            err = abs(rows[name][k] - exact[k][i])
            assert err < 0.04 and err < 1.5 * rows[name][f"{k}_conf"] + 0.005, (name, k, rows[name], exact[k][i])


def test_morris_screen_ranks_a_linear_function_exactly():
    """Elementary effects of y = 3 x1 - 1 x2 + 0 x3 are the coefficients themselves, so
    mu* is proportional to |c| (same ranges) and sigma is 0."""
    prob = {"num_vars": 3, "names": ["x1", "x2", "x3"], "bounds": [[0.0, 2.0]] * 3, "dists": ["unif"] * 3}
    x = sens.design("morris", prob, 20, seed=2)
    rows = {r["parameter"]: r for r in sens.indices("morris", prob, x, x @ [3.0, -1.0, 0.0], seed=2)}
    assert rows["x1"]["mu_star"] / rows["x2"]["mu_star"] == pytest.approx(3.0)
    assert rows["x3"]["mu_star"] == pytest.approx(0.0, abs=1e-12)
    assert all(r["sigma"] == pytest.approx(0.0, abs=1e-9) for r in rows.values())


@pytest.fixture(scope="module")
def failing(tmp_path_factory):
    out = tmp_path_factory.mktemp("mcf") / "failing"
    res = run_campaign(load_campaign(FAILING), out, runs=12, workers=0, batch=5)
    return out, res


def test_failed_and_diverged_runs_are_counted_and_stored_in_their_rows(failing):
    """Of 12 runs with absurd attitude gains, 2 fail (non-finite state) and 5 reach the hard
    stops: every run is counted, the fraction is given over the completed runs and as a range
    over all runs, and the store keeps each run in its row (NaN traces for the failed ones)."""
    out, res = failing
    s = stats(out)
    assert (s["runs"], s["runs_ok"], s["runs_failed"], s["runs_diverged"]) == (12, 5, 2, 5)
    f = s["lco_fraction"]
    assert f["lco_runs"] == 5 and f["value"] == 1.0
    assert f["all_runs_low"] == pytest.approx(5 / 12) and f["all_runs_high"] == pytest.approx(1.0)
    assert sorted(x["status"] for x in s["failures"]) == ["diverged"] * 5 + ["failed"] * 2
    ds = open_store(out / "campaign.zarr", dask=False)
    st = ds["status"].values
    assert list(ds["run"].values) == list(range(12))
    # each run in its own row: the same campaign flown one run a batch (each run alone in the
    # kernel, not beside four others) stores the same status, error and amplitude in every row
    # (which of these chaotic, absurd-gain runs fails and which reaches the stops is the
    # kernel's rounding; the counts above are the physics)
    alone = out.parent / "alone"
    run_campaign(load_campaign(FAILING), alone, runs=12, workers=0, batch=1)
    ds1 = open_store(alone / "campaign.zarr", dask=False)
    assert list(ds1["status"].values) == list(st)
    assert list(ds1["error"].values) == list(ds["error"].values)
    np.testing.assert_array_equal(ds1["amplitude_deg"].values, ds["amplitude_deg"].values)
    tr = ds["trace"].values
    assert np.isnan(tr[st == 2]).all() and np.isfinite(tr[st == 1]).all()
    assert all("unstable" in e for e in ds["error"].values[st == 2])
    assert all("hard stops" in e for e in ds["error"].values[st == 3])
    assert set(ds["inputs_sha256"].values) == {json.loads((out / "campaign.json").read_text())["inputs_sha256"]}
    assert not ds["lco"].values[st != 1].any()
    assert np.isnan(ds["amplitude_deg"].values[st == 2]).all()
    seeds = [run_factors(load_campaign(FAILING), i)[0] for i in range(12)]
    assert list(ds["seed"].values) == seeds


def test_resume_refuses_an_edited_input_file(tmp_path):
    """An input named by an input (the ascent's flight file) edited after a campaign: --resume
    refuses it (inputs hash), before anything is written; the manifest lists every file read."""
    camp = copy_inputs(tmp_path / "proj")
    out = tmp_path / "out"
    run_campaign(load_campaign(camp), out, runs=2, workers=0)
    man = json.loads((out / "campaign.json").read_text())
    files = {Path(f["file"]).name for f in man["input_files"]}
    assert {"mc_short.toml", "ascent.toml", "core_stage.toml", "rs25_flight.toml"} <= files
    flight = tmp_path / "proj" / "models" / "flight" / "core_stage.toml"
    flight.write_text(flight.read_text() + "\n# an edit\n")
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    with pytest.raises(InputError, match="inputs_sha256"):
        run_campaign(load_campaign(camp), out, runs=2, workers=0, resume=True)
    assert before == {p.name: p.stat().st_mtime_ns for p in out.iterdir()}


def test_sobol_needs_a_power_of_two(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "6", "--sensitivity", "sobol", "--out", str(out)]) == 2
    assert "power of two" in capsys.readouterr().err and not out.exists()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_dead_scheduler_address_one_line_nothing_written(tmp_path, capsys):
    out = tmp_path / "out"
    t0 = time.perf_counter()
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler", f"tcp://127.0.0.1:{_free_port()}",
                 "--connect-timeout", "3", "--out", str(out)]) == 2
    assert time.perf_counter() - t0 < 20
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler" in err[0] and "memory" not in err[0]
    assert not out.exists()


@pytest.mark.parametrize("reply, expected", [(b"", "3 s"), (b"\xff" * 64, "not as a Dask scheduler")])
def test_a_server_that_is_not_dask_refused_in_time_nothing_written(tmp_path, capsys, reply, expected):
    """A server that accepts and never answers, or answers with bytes that are not the Dask
    protocol: refused within the timeout (3 s, plus start-up) with the right reason (never "out
    of memory"), nothing written."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    held = []
    stop = threading.Event()

    def accept():
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                c = srv.accept()[0]
                held.append(c)
                if reply:
                    c.sendall(reply)
            except OSError:
                pass
    th = threading.Thread(target=accept, daemon=True)
    th.start()
    out = tmp_path / "out"
    try:
        t0 = time.perf_counter()
        rc = main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler", f"tcp://127.0.0.1:{srv.getsockname()[1]}",
                   "--connect-timeout", "3", "--out", str(out)])
        el = time.perf_counter() - t0
    finally:
        stop.set()
        th.join()
        for c in held:
            c.close()
        srv.close()
    assert rc == 2 and el < 15, el
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--scheduler" in err[0] and expected in err[0] and "memory" not in err[0].lower(), err
    assert not out.exists()


def test_scheduler_port_out_of_range_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "2", "--scheduler", "tcp://127.0.0.1:99999", "--out", str(out)]) == 2
    assert "port 1 to 65535" in capsys.readouterr().err and not out.exists()


BAD = [
    ("dispersions.coulomb_torqe", 'coulomb_torqe = { distribution = "normal", mean = 1.0, std = 0.1 }'),
    ("dispersions.wind.std", 'wind = { distribution = "normal", mean = 1.0, std = -0.1 }'),
    ("dispersions.wind.high", 'wind = { distribution = "uniform", low = 1.5, high = 0.5 }'),
    ("dispersions.wind.distribution", 'wind = { distribution = "cauchy", low = 0.5, high = 1.5 }'),
]


@pytest.mark.parametrize("field, line", BAD)
def test_bad_campaign_files_one_line_exit_2_no_campaign(tmp_path, capsys, field, line):
    text = SHORT.read_text().replace('ascent = "../../models/flight/ascent.toml"',
                                     f'ascent = "{(DATA / "../../models/flight/ascent.toml").resolve()}"')
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith(line.split(" =")[0] + " ="))
    p = tmp_path / "bad.toml"
    p.write_text(text + "\n" + line + "\n")
    out = tmp_path / "out"
    assert main(["montecarlo", str(p), "--runs", "3", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not out.exists()


def test_zero_runs_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["montecarlo", str(SHORT), "--runs", "0", "--out", str(out)]) == 2
    assert "--runs" in capsys.readouterr().err and not out.exists()


def test_percentile_intervals_in_the_summary(failing):
    s = stats(failing[0])
    amp = s["amplitude_deg_lco_runs"]
    assert amp["n"] == 5 and amp["p50_ci"] is None  # 5 runs: no 95 % interval of the median exists
    assert not math.isnan(amp["p50"])


def test_flight_sensitivity_designs_run_through_the_campaign_engine(tmp_path):
    """Morris (2 trajectories: 2 (k + 1) runs) and Sobol' (N = 2: N (k + 2) runs) designs of the
    short flight campaign, in this process: every run stored, indices for every factor, every
    run with the campaign's turbulence seed; the Sobol' design rows follow the dispersions'
    ranges."""
    c = load_campaign(SHORT)
    k = len(c.dispersions)
    for method, n, rows, key in (("morris", 2, 2 * (k + 1), "mu_star"), ("sobol", 2, 2 * (k + 2), "ST")):
        out = tmp_path / method
        run_campaign(c, out, runs=n, workers=0, design=method)
        summary = json.loads((out / "summary.json").read_text())
        s = summary["sensitivity"]
        assert s["method"] == method and s["runs"] == rows
        ds = open_store(out / "campaign.zarr", dask=False)
        assert ds.sizes["run"] == rows and set(ds["seed"].values) == {c.seed}
        if s["indices"] is not None:
            assert {r["parameter"] for r in s["indices"]} == {d.name for d in c.dispersions}
            assert all(math.isfinite(r[key]) for r in s["indices"])
        else:
            assert "failed or diverged" in s["error"]
        for j, d in enumerate(c.dispersions):
            col = ds["factor"].values[:, j]
            lo = d.low if math.isfinite(d.low) else 0.0
            assert col.min() >= lo - 1e-12 and (not math.isfinite(d.high) or col.max() <= d.high + 1e-12)


# -- the lockstep flight kernel -------------------------------------------------------------
def per_segment_reference(asc, model, axis: str, start_s: float, end_s: float, dt_s: float, seed: int,
                          record_interval_s: float = 0.02) -> np.ndarray:
    """The commanded angle [rad] at the records flown the previous way (an independent path):
    one dense :func:`taos.planar.simulate.integrate_plant` call per segment, the plant rebuilt
    from scratch (:func:`ascent_plant`, no shared parts) each time, xi re-based and the
    separation kick applied between the calls."""
    from taos.flight.ascent_sim import _external_inputs, _grid, ascent_plant, flight_at
    from taos.planar.simulate import integrate_plant
    _, rec, t, bounds = _grid(asc, start_s, end_s, dt_s, record_interval_s)
    r = _external_inputs(asc, axis, t, seed, dt_s)
    sep = asc.boosters.separation_time_s
    x = z = b_prev = None
    cmd = []
    for k0, k1 in zip(bounds[:-1], bounds[1:]):
        fl, a_b = flight_at(asc, t[k0] + 0.5 * (t[k1] - t[k0]), axis)
        p = ascent_plant(fl, model, axis, a_b, asc.boosters.actuator_time_constant_s)
        si, b = p.ss.state_index, fl.vehicle.twd_coefficient(axis)
        if x is None:
            x, z = np.zeros(p.ss.A.shape[0]), 0.0
        else:
            x[si("xi_rad")] += (b_prev - b) * x[si("theta_rad")]
            x[si("xi_rate_rad_s")] += (b_prev - b) * x[si("omega_rad_s")]
        if abs(t[k0] - sep) < 0.5 * dt_s * rec + 1e-12:
            x[si("xi_rate_rad_s")] += asc.boosters.separation_rate_kick_rad_s
        y, aux = integrate_plant(p, model, r[k0:k1 + 1], dt_s, rec, x0=x, z0=z)
        o = p.ss.output_index
        cmd.append((y[:, o("delta_cmd_rad")] + r[k0:k1 + 1:rec, 0])[: None if k1 == bounds[-1] else -1])
        x, z, b_prev = y[-1, o(f"state:{p.ss.states[0]}"):][: len(x)].copy(), float(aux[-1, 1]), b
    return np.concatenate(cmd)


#: the RK4 lockstep kernel's step on this campaign (the campaign itself flies ETDRK4 at 5 ms)
RK4_DT_S = 1e-3


@pytest.fixture(scope="module")
def dispersed_runs():
    """Five dispersed soft-case runs of the post-separation campaign: (ascent, model, seed)."""
    from taos.montecarlo.campaign import apply_factors
    from taos.montecarlo.executor import flight_runs, montecarlo_design
    c = load_campaign("post_separation")
    kind, _ = flight_runs(c, "soft", None)
    d = montecarlo_design(c, 5)
    runs = []
    for i in range(5):
        a2, m2, _ = apply_factors(kind.ascent, kind.model, c.cases["soft"], dict(zip(d.names, map(float, d.factors[i]))))
        runs.append((a2, m2, int(d.seeds[i])))
    return c, runs


def test_lockstep_runs_are_bit_identical_alone_and_in_any_company(dispersed_runs):
    """A run's numbers do not depend on the other runs of its kernel call, their number or its
    place among them (the store's bit-identity across batch sizes rests on this)."""
    from taos.flight.ascent_sim import simulate_ascents
    c, runs = dispersed_runs
    kw = dict(axis=c.axis, start_s=c.start_s, end_s=c.start_s + 12.0, dt_s=RK4_DT_S, record_interval_s=0.02)
    together = simulate_ascents(runs, **kw)
    for order in ([0], [3], [4, 2], [1, 0, 4, 3, 2]):
        for i, h in zip(order, simulate_ascents([runs[i] for i in order], **kw)):
            for k, v in h.signals.items():
                assert np.array_equal(v, together[i].signals[k]), (order, i, k)


def test_lockstep_kernel_matches_the_per_segment_dense_path(dispersed_runs):
    """The lockstep sparse kernel against the previous path (dense RK4 per segment, the plant
    rebuilt each time) over 30 s through the booster separation (the kick) and six changes of
    plant (xi re-based): the same flight to rounding (sums in another order)."""
    from taos.flight.ascent_sim import simulate_ascents
    c, runs = dispersed_runs
    end = c.start_s + 30.0
    flown = simulate_ascents(runs[:3], axis=c.axis, start_s=c.start_s, end_s=end, dt_s=RK4_DT_S,
                             record_interval_s=0.02)
    for (asc, model, seed), h in zip(runs[:3], flown):
        ref = per_segment_reference(asc, model, c.axis, c.start_s, end, RK4_DT_S, seed)
        got = h.signal("command_rad", c.axis)
        assert np.max(np.abs(ref)) > 1e-4  # the kick moved it
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))


def test_the_inputs_hash_does_not_depend_on_what_the_process_loaded_before(tmp_path):
    """A fresh process's first model load also reads taos's own units cache
    (``~/.cache/taos/units-*.json``); that cache is not an input, so a store written by a ``taos``
    process resumes from a process that had already loaded a model (the recorded inputs of the
    first and the second load in one fresh process are the same files)."""
    import subprocess
    import sys

    code = ("import json, sys; from taos.montecarlo.inputs import recording, digest; "
            "from taos.model import load_model\n"
            "out = []\n"
            "for _ in range(2):\n"
            "    with recording() as f:\n"
            "        load_model(sys.argv[1])\n"
            "    out.append(digest(f, 's')[1])\n"
            "print(json.dumps(out))")
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    r = subprocess.run([sys.executable, "-c", code, str(ROOT / "models" / "rs25_ambient.toml")],
                       capture_output=True, text=True, env=env, timeout=120, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    first, second = json.loads(r.stdout)
    assert (tmp_path / "cache" / "taos").is_dir()     # the first load did write and read the cache
    assert first == second and first, (first, second)
    assert all("cache" not in Path(t["file"]).parts for t in first)


def test_a_fresh_flight_load_records_the_flight_file_only(tmp_path):
    """The flight loader builds pint's registry on first use (not when its module is imported);
    :func:`~taos.montecarlo.inputs.recording` builds it before the block, so a fresh process's
    first flight load records the flight file, not pint's cache or what pint's imports read."""
    import subprocess
    import sys

    code = ("import json; from taos.montecarlo.inputs import recording, digest; "
            "from taos.flight.vehicle import load_flight\n"
            "with recording() as f:\n"
            "    load_flight('core_stage')\n"
            "print(json.dumps([t['file'] for t in digest(f, 's')[1]]))")
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == [str((ROOT / "models" / "flight" / "core_stage.toml").resolve())]
