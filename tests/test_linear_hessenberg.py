"""The many-frequency path of :meth:`taos.linear.StateSpace.freqresp` (Hessenberg form, one
vectorised elimination for all frequencies) against the per-frequency LAPACK solve it replaces,
and the section-search notch finder against a notch known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.linear import HESSENBERG_MIN_WORK, StateSpace, hessenberg, hessenberg_solve, notch_hz
from taos.model import load_model
from taos.planar.simplex import simplex_state_space
from taos.report.servo import laboratory


def test_hessenberg_is_an_orthogonal_similarity_to_upper_hessenberg_form():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(9, 9)) * np.logspace(-3, 3, 9)[:, None]
    H, Q = hessenberg(A)
    assert np.allclose(Q.T @ Q, np.eye(9), rtol=0, atol=1e-14)
    assert not np.any(np.tril(H, -2))
    assert np.allclose(Q @ H @ Q.T, A, rtol=0, atol=1e-13 * np.abs(A).max())


@pytest.mark.parametrize("lab", [False, True])
def test_many_frequencies_equal_the_per_frequency_solve_to_round_off(lab):
    """Every output of the simplex block (and of its stiff laboratory twin, K_L = 1e12 N/m) from
    1 mHz to 10 kHz: the batch (Hessenberg path) equals single-frequency calls (LAPACK path) to
    round-off relative to each response's largest value over the band."""
    m = load_model("rs25_ambient")
    ss = simplex_state_space(laboratory(m) if lab else m)
    f = np.logspace(-3, 4, 600)
    n = len(ss.states)
    assert f.size * n * n >= HESSENBERG_MIN_WORK > n * n   # the two paths are the ones compared
    many = ss.freqresp(f)
    one = np.concatenate([ss.freqresp(f[k:k + 1]) for k in range(f.size)])
    scale = np.abs(one).max(axis=0)
    assert np.max(np.abs(many - one) / scale) < (1e-9 if lab else 1e-13)


def test_a_frequency_response_does_not_depend_on_the_other_frequencies_of_the_call():
    ss = simplex_state_space(load_model("rs25_ambient"))
    f = np.logspace(-2, 3, 2000)
    many = ss.freqresp(f, "command_rad", ["x_p_m", "theta_rad"])
    for sub in (slice(1, None), slice(None, None, 3), slice(None, None, -1)):
        assert f[sub].size * 64 >= HESSENBERG_MIN_WORK
        assert np.array_equal(ss.freqresp(f[sub], "command_rad", ["x_p_m", "theta_rad"]), many[sub])


def test_an_exactly_singular_shift_raises_on_both_paths():
    ss = StateSpace(np.zeros((8, 8)), np.ones((8, 1)), np.ones((1, 8)), np.zeros((1, 1)),
                    tuple(f"x{i}" for i in range(8)), ("u",), ("y",))
    for f in ([0.0], np.linspace(0.0, 1.0, 400)):
        with pytest.raises(np.linalg.LinAlgError):
            ss.freqresp(f)
    with pytest.raises(np.linalg.LinAlgError):
        hessenberg_solve(np.zeros((3, 3)), np.zeros(2, complex), np.ones((3, 1)))


def test_section_search_finds_a_closed_form_notch_for_several_responses_at_once():
    """|H| = |1 - (f / f0)^2| has its minimum at f0: one response, and three at once."""
    f0 = np.array([1.3, 4.7, 17.0])
    one = notch_hz(lambda f: np.abs(1 - (f / f0[1]) ** 2), 0.5, 30.0)
    assert isinstance(one, float) and abs(math.log10(one / f0[1])) <= 1e-9
    three = notch_hz(lambda f: np.abs(1 - (f[:, None] / f0[None, :]) ** 2), 0.5, 30.0)
    assert three.shape == (3,) and np.all(np.abs(np.log10(three / f0)) <= 1e-9)
