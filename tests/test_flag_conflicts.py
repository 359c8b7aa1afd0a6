"""Flag combinations and output names refused before any work (issue 40): one line naming the
option, exit 2, nothing written; an output is checked against every input however it was named
(a path, a shipped file's bare name, a file an input names) and against the other outputs."""

from __future__ import annotations

import pytest

from .conftest import ROOT, run_cli

CASES = {
    "plot and json one file": (["lco", "--flight", "core_stage", "rs25_flight", "--no-time-domain", "--plot", "{t}/x.png",
                                "--json", "{t}/x.png"], "--json"),
    "json and df-out one file": (["lco", "--flight", "core_stage", "rs25_flight", "--no-time-domain", "--json",
                                  "{t}/x.h5", "--df-out", "{t}/x.h5"], "--df-out"),
    "out-model and json one file": (["fit", "models/rs25_hotfire.toml", "--data",
                                     "models/data/greenrun_hotfire_synthetic.csv", "--out-model", "{t}/x.toml",
                                     "--json", "{t}/x.toml"], "--"),
    "linear with friction": (["freqresp", "rs25_hotfire", "--freq-hz", "1", "--linear", "--friction", "dahl"],
                             "--friction"),
    "empty amplitudes": (["lco", "--flight", "core_stage", "rs25_flight", "--amplitudes-deg", ""], "--amplitudes-deg"),
    "empty frequencies": (["lco", "--flight", "core_stage", "rs25_flight", "--freq-hz", " , "], "--freq-hz"),
    "td-start without sweep": (["lco", "--flight", "core_stage", "rs25_flight", "--td-start", "rest"], "--td-start"),
    "one key swept twice": (["lco", "--flight", "core_stage", "rs25_flight", "--sweep", "integral_gain=0.6",
                             "--sweep", "integral_gain=0.7"], "--sweep"),
    "json onto a shipped input named bare": (["ascent", "ascent", "--start", "120", "--end", "121", "--out", "{t}/a",
                                              "--json", "models/flight/ascent.toml", "--force"], "--json"),
    "json onto a file an input names": (["lco", "--flight", "core_stage", "rs25_flight", "--json",
                                         "models/friction/rs25_gimbal.toml", "--force"], "--json"),
    "resume without a store": (["montecarlo", "models/montecarlo/scaling_short.toml", "--out", "{t}/mc", "--runs", "2", "--resume"],
                               "--resume"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_refused_before_any_work(name, tmp_path):
    argv, opt = CASES[name]
    shipped = {p: p.read_bytes() for p in (ROOT / "models" / "flight").glob("*.toml")}
    shipped[ROOT / "models/friction/rs25_gimbal.toml"] = (ROOT / "models/friction/rs25_gimbal.toml").read_bytes()
    p = run_cli(*[a.format(t=tmp_path) for a in argv], timeout=60)
    assert p.returncode == 2, (p.returncode, p.stderr)
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and opt in lines[0], p.stderr
    assert list(tmp_path.iterdir()) == []                       # nothing written
    assert all(q.read_bytes() == b for q, b in shipped.items())   # no input replaced


def test_a_flight_file_whose_tvc_model_is_itself_is_refused(tmp_path):
    from taos.errors import InputError
    from taos.flight.vehicle import load_flight
    text = (ROOT / "models/flight/core_stage.toml").read_text()
    f = tmp_path / "self.toml"
    f.write_text("\n".join('tvc_model = "self.toml"' if ln.startswith("tvc_model") else ln
                           for ln in text.splitlines()) + "\n")
    with pytest.raises(InputError, match="tvc_model"):
        load_flight(f)
