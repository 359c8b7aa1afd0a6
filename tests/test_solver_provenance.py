"""The solvers describe themselves: a frequency response names the integrator that ran, once,
set by the code that ran it (the command line copies it, never composes it)."""

from __future__ import annotations

import json
import math

import pytest

from taos.cli import main

from .conftest import MODELS

AMBIENT = MODELS / "rs25_ambient.toml"


def _walk(d, path=()):
    """(path, key, value) of every entry of a JSON tree."""
    if isinstance(d, dict):
        for k, v in d.items():
            yield path, k, v
            yield from _walk(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from _walk(v, path + (i,))


def _named_integrator(d: dict) -> str:
    """The one integrator the JSON names: exactly one ``integrator`` key, and no other string
    naming an RK4 or ETDRK4 scheme anywhere."""
    found = [(p, v) for p, k, v in _walk(d) if k == "integrator"]
    assert len(found) == 1, found
    (path, name), = found
    assert path == ("provenance", "solver")
    others = [(p, k, v) for p, k, v in _walk(d) if isinstance(v, str) and "rk4" in v.lower()
              and not (k == "integrator" and p == path)]
    assert not others, others
    return name


@pytest.fixture
def ran(monkeypatch):
    """The integrator entry points called, by the name a result should give them."""
    from taos.planar import _expcoef
    from taos.planar import dynamics as planar_dynamics
    from taos.planar.freqresp import INTEGRATOR_NAMES
    from taos.taos3d import dynamics as taos_dynamics
    from taos.taos3d.simulate import INTEGRATOR

    calls = []

    def spy(module, attr, name):
        real = getattr(module, attr)

        def wrapped(*a, **k):
            calls.append(name)
            return real(*a, **k)
        monkeypatch.setattr(module, attr, wrapped)

    spy(_expcoef, "run_dwells", INTEGRATOR_NAMES["exp"])   # C or numba kernels (taos.planar._cdwell)
    spy(planar_dynamics, "sine_dwell_batch", INTEGRATOR_NAMES["rk4"])
    spy(taos_dynamics, "dwell_batch", INTEGRATOR)
    return calls


def _freqresp_json(capsys, *more) -> dict:
    assert main(["freqresp", str(AMBIENT), "--freq-hz", "0.5,2", *more, "--json", "-"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("more", [("--amplitude-deg", "0.4"), ("--amplitude-deg", "0.4,0.8"),
                                  ("--amplitude-deg", "0.4", "--engine", "taos")],
                         ids=["simplex", "simplex-family", "taos"])
def test_freqresp_json_names_the_dwell_integrator_that_ran_once(capsys, ran, more):
    d = _freqresp_json(capsys, *more)
    assert set(ran) == {_named_integrator(d)}
    assert d["provenance"]["solver"]["engine"] == d["engine_model"]
    for key in ("freq_hz", "amplitude_deg", "piston", "engine"):   # the JSON contract is kept
        assert key in d
    assert set(d["engine"]) == {"gain_db", "phase_deg"}


@pytest.mark.parametrize("more", [("--linear",), ("--linear", "--engine", "taos")], ids=["simplex", "taos"])
def test_freqresp_json_linear_names_no_time_integrator(capsys, ran, more):
    d = _freqresp_json(capsys, *more)
    assert not ran
    assert _named_integrator(d).startswith("none")
    assert d["provenance"]["solver"]["method"].startswith("linear (exact")


@pytest.mark.parametrize("integrator", ["exp", "rk4"])
def test_sine_dwell_description_follows_the_integrator_setting(ran, integrator):
    from taos.model import load_model
    from taos.planar.freqresp import INTEGRATOR_NAMES, sine_dwell_freqresp

    fr = sine_dwell_freqresp(load_model(AMBIENT), [2.0], math.radians(0.4), integrator=integrator,
                             settle_cycles=3, dt_max_s=1e-4)
    s = fr.provenance["solver"]
    assert ran == [INTEGRATOR_NAMES[integrator]] == [s["integrator"]]
    assert (s["dt_max_s"], s["settle_cycles"], s["engine"]) == (1e-4, 3, "simplex")
    assert s["method"] == "sine dwell, settled from rest"


def test_describing_function_map_names_the_integrator_that_ran(ran):
    from taos.flight.describing import describing_function_map
    from taos.model import load_model

    df = describing_function_map(load_model(AMBIENT), [math.radians(0.2), math.radians(0.4)], [1.0, 2.0])
    assert set(ran) == {df.provenance["solver"]["integrator"]}
    assert _named_integrator({"provenance": df.provenance}) == df.provenance["solver"]["integrator"]
