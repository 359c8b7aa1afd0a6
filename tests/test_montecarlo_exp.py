"""The Monte Carlo lanes on the exponential integrator (``integrator = "etdrk4"``,
:mod:`taos.planar._explanes`): independent of the lanes' company bit for bit, fourth order
against the RK4 lockstep kernel at a fine step, the campaign file's integrator and step checked.
The campaign-scale accuracy (64 runs x 200 s, every stored output) is in benchmarks/RESULTS.md,
section mcexp (``benchmarks/mc_exp_convergence.py``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from taos.cli import main
from taos.montecarlo import load_campaign

DATA = Path(__file__).resolve().parent / "data"
SHORT = DATA / "mc_short.toml"


@pytest.fixture(scope="module")
def dispersed_runs():
    """Four dispersed soft-case runs of the post-separation campaign: (ascent, model, seed)."""
    from taos.montecarlo.campaign import apply_factors
    from taos.montecarlo.executor import flight_runs, montecarlo_design
    c = load_campaign("post_separation")
    kind, _ = flight_runs(c, "soft", None)
    d = montecarlo_design(c, 4)
    runs = [apply_factors(kind.ascent, kind.model, c.cases["soft"], dict(zip(d.names, map(float, d.factors[i]))))[:2]
            + (int(d.seeds[i]),) for i in range(4)]
    return c, runs


def test_the_campaign_flies_etdrk4_at_5_ms():
    c = load_campaign("post_separation")
    assert (c.integrator, c.dt_s) == ("etdrk4", 5e-3)


def test_exp_lanes_are_bit_identical_alone_and_in_any_company(dispersed_runs):
    """A run's numbers do not depend on the other runs of its ETDRK4 kernel call (the store's
    bit-identity across batch sizes, workers and resumes rests on this)."""
    from taos.flight.ascent_sim import simulate_ascents
    c, runs = dispersed_runs
    kw = dict(axis=c.axis, start_s=c.start_s, end_s=c.start_s + 12.0, dt_s=5e-3, record_interval_s=0.02,
              integrator="etdrk4")
    together = simulate_ascents(runs, **kw)
    assert together[0].provenance["solver"] == {"method": "etdrk4-lanes", "dt_s": 5e-3, "record_every": 4}
    for order in ([0], [3, 1], [2, 0, 3, 1]):
        for i, h in zip(order, simulate_ascents([runs[i] for i in order], **kw)):
            for k, v in h.signals.items():
                assert np.array_equal(v, together[i].signals[k]), (order, i, k)


def test_exp_lanes_converge_to_rk4_at_a_fine_step(dispersed_runs):
    """30 s through the booster separation (its kick) and six changes of plant: the FCS command
    and the engine angle at 5 ms and 2.5 ms against RK4 at 0.25 ms (RK4 at 1 ms is within 5e-7
    of the peak there), relative to each run's peak. Measured (4 runs): 5 ms command 7e-5 to
    2.4e-4 (largest just after the kick), engine 7e-6 to 5.4e-5; 2.5 ms command 4e-6 to 1.6e-5,
    engine 2e-6 to 1e-5; the worst run's error 5-15x smaller at half the step (fourth order:
    16x; the engine's stick-slip reversals, where the friction law is only continuous, lower it)."""
    from taos.flight.ascent_sim import simulate_ascents
    c, runs = dispersed_runs
    kw = dict(axis=c.axis, start_s=c.start_s, end_s=c.start_s + 30.0, record_interval_s=0.02)
    ref = simulate_ascents(runs, dt_s=2.5e-4, **kw)
    err = {}
    for h in (5e-3, 2.5e-3):
        got = simulate_ascents(runs, dt_s=h, integrator="etdrk4", **kw)
        for sig in ("command_rad", "engine_rad"):
            e = []
            for g, r in zip(got, ref):
                np.testing.assert_array_equal(g.t_s, r.t_s)
                a, b = g.signal(sig, c.axis), r.signal(sig, c.axis)
                e.append(np.max(np.abs(a - b)) / np.max(np.abs(b)))
            err[h, sig] = max(e)
    bound = {(5e-3, "command_rad"): 1e-3, (5e-3, "engine_rad"): 2e-4, (2.5e-3, "command_rad"): 5e-5,
             (2.5e-3, "engine_rad"): 4e-5}
    for k, b in bound.items():
        assert err[k] < b, (k, err[k])
    for sig in ("command_rad", "engine_rad"):
        assert err[5e-3, sig] > 4.0 * err[2.5e-3, sig], (sig, err)


@pytest.mark.parametrize("lines, field", [
    ('integrator = "euler"', "integrator"),
    ('dt = "5 ms"', "dt"),                           # RK4 beyond the oil column's stability bound
    ('dt = "3 ms"\nintegrator = "etdrk4"', "dt"),    # an ETDRK4 step that does not divide the 20 ms records
])
def test_the_campaign_integrator_and_step_are_checked(tmp_path, capsys, lines, field):
    text = SHORT.read_text().replace('ascent = "../../models/flight/ascent.toml"',
                                     f'ascent = "{(DATA / "../../models/flight/ascent.toml").resolve()}"')
    text = text.replace('dt = "1 ms"\n', lines + "\n")
    p = tmp_path / "bad.toml"
    p.write_text(text)
    out = tmp_path / "out"
    assert main(["montecarlo", str(p), "--runs", "3", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f": {field}:" in err[0], err
    assert not out.exists()


@pytest.fixture(scope="module")
def exp_short(tmp_path_factory):
    """The short test campaign flown by ETDRK4 at 5 ms (its copy beside the original's inputs)."""
    text = SHORT.read_text().replace('ascent = "../../models/flight/ascent.toml"',
                                     f'ascent = "{(DATA / "../../models/flight/ascent.toml").resolve()}"')
    p = tmp_path_factory.mktemp("mcexp") / "exp_short.toml"
    p.write_text(text.replace('dt = "1 ms"\n', 'dt = "5 ms"\nintegrator = "etdrk4"\n'))
    return p


def test_exp_store_cluster_equals_in_process_and_resume_equals_uninterrupted(exp_short, tmp_path, monkeypatch):
    """The store's bit-identity with the ETDRK4 lanes: a LocalCluster of 2 workers (the default
    batch) against the in-process engine with 3 runs a batch, and a campaign stopped after two
    batches then resumed against the uninterrupted one."""
    from taos.montecarlo import run_campaign, store
    from tests.test_montecarlo_cluster import same_store
    c = load_campaign(exp_short)
    runs = 10
    ref = tmp_path / "ref"
    run_campaign(c, ref, runs=runs, workers=0, batch=3)
    summary = (ref / "summary.json").read_text()
    assert '"etdrk4-lanes"' in summary
    assert main(["montecarlo", str(exp_short), "--runs", str(runs), "--out", str(tmp_path / "local"),
                 "--no-progress"]) == 0
    same_store(tmp_path / "local", ref)
    write, calls = store.write_batch, []

    def stop_after_two(*a, **k):
        if len(calls) == 2:
            raise KeyboardInterrupt
        calls.append(1)
        return write(*a, **k)
    monkeypatch.setattr(store, "write_batch", stop_after_two)
    with pytest.raises(KeyboardInterrupt):
        run_campaign(c, tmp_path / "resumed", runs=runs, workers=0, batch=3)
    monkeypatch.setattr(store, "write_batch", write)
    run_campaign(c, tmp_path / "resumed", runs=runs, workers=0, batch=3, resume=True)
    same_store(tmp_path / "resumed", ref)
