"""The Green Run's independent runs on both cores give the serial run's numbers, bit for bit.

The reference is the serial path itself (``threads=1``: every run one after the other in the
calling thread, the code path of before the parallel work), compared with ``threads=2`` by exact
equality (``np.array_equal``, ``==`` on the summary dict): the two-axis run's arrays, the step
figures, the whole ``summary.json`` dict of both engines. A NaN in one lane raises the
SimulationUnstable the serial run raises (same time, same lane) and writes nothing.
"""

from __future__ import annotations

import math
import threading
import time

import numpy as np
import pytest

from taos.errors import InputError, SimulationUnstable
from taos.model import load_model
from taos.planar._parallel import run_each, run_tasks, thread_count
from taos.planar.simulate import TimeHistory, simulate
from taos.profiles import Step, TwoAxis
from taos.report.analysis import DEFAULT_PROFILE, _profile_of, greenrun


@pytest.fixture(scope="module")
def hot():
    return load_model("rs25_hotfire")


@pytest.fixture(scope="module", params=["simplex", "taos"])
def runs(request, hot):
    """(engine, serial result, parallel result) of the default Green Run."""
    return request.param, greenrun(hot, engine=request.param, threads=1), greenrun(hot, engine=request.param, threads=2)


def _summary(r) -> dict:
    s = r.summary()
    s.pop("created_utc")
    return s


# -- the thread pool ---------------------------------------------------------------------------

def test_tasks_run_at_the_same_time_on_two_threads_and_come_back_in_order():
    """Two tasks that each wait for the other at a barrier finish only if they run at once."""
    barrier = threading.Barrier(2, timeout=30)

    def task(k):
        barrier.wait()
        return k, threading.get_ident()

    out = run_tasks([lambda: task(0), lambda: task(1)], threads=2, start_order=[1, 0])
    assert [k for k, _ in out] == [0, 1]
    assert out[0][1] != out[1][1] != threading.get_ident()
    # one thread: in this thread, one after the other, in task order
    seen = []
    assert run_tasks([lambda k=k: seen.append(k) or k for k in range(4)], threads=1) == [0, 1, 2, 3]
    assert seen == [0, 1, 2, 3]


def test_the_first_failure_in_task_order_is_raised_as_the_serial_run_would():
    """Task 1 fails at once, task 0 later: the serial run meets task 0's failure first, so does
    the parallel one."""
    def late():
        time.sleep(0.2)
        raise SimulationUnstable(2.0, "task 0")

    def early():
        raise SimulationUnstable(1.0, "task 1")

    for n in (1, 2):
        with pytest.raises(SimulationUnstable) as e:
            run_tasks([late, early], threads=n)
        assert e.value.time_s == 2.0 and "task 0" in str(e.value)


def test_run_each_calls_every_item_once_the_costliest_first():
    """A batch's items (the dwells): every item once; two threads start the two costliest
    first (they take the items costliest first, one at a time); one thread goes in item order."""
    cost = [3, 9, 1, 7, 5]
    for n in (1, 2):
        seen, lock = [], threading.Lock()

        def call(b):
            with lock:
                seen.append(b)
            time.sleep(0.01 * cost[b])

        run_each(call, cost, threads=n)
        assert sorted(seen) == list(range(5))
        if n == 1:
            assert seen == [0, 1, 2, 3, 4]
        else:
            assert set(seen[:2]) == {1, 3}


def test_thread_count_default_and_bad_values():
    import numba

    assert thread_count() == numba.get_num_threads()
    assert thread_count(3) == 3
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(InputError, match="threads"):
            thread_count(bad)


# -- the Green Run's runs ----------------------------------------------------------------------

def test_two_axis_run_in_parallel_is_the_serial_run_bit_for_bit(hot):
    prof = _profile_of(DEFAULT_PROFILE)[0]
    a, b = simulate(hot, prof, threads=1), simulate(hot, prof, threads=2)
    assert a.axes == b.axes == ("pitch", "yaw")
    for name in ("t_s",) + TimeHistory.ARRAYS + TimeHistory.OPTIONAL_ARRAYS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert a.provenance == b.provenance


def test_greenrun_in_parallel_is_the_serial_run_step_figures_and_summary(runs):
    """One test per engine (the module fixture computed once per engine, also under xdist)."""
    engine, serial, par = runs
    fs, fp = serial.figures_of_merit, par.figures_of_merit
    assert set(fs) == {"pitch", "yaw"} and all("step" in fs[ax] for ax in fs)
    assert fs == fp
    for name in TimeHistory.ARRAYS + TimeHistory.OPTIONAL_ARRAYS:
        assert np.array_equal(getattr(serial.time_history, name), getattr(par.time_history, name)), name
    s, p = _summary(serial), _summary(par)
    assert s["engine_model"] == engine
    assert s == p


def test_step_merits_of_one_axis_are_the_rows_of_both(hot):
    """step_merit (one axis) and step_merits (both axes at once) give the same figures."""
    from taos.report.merit import step_merit, step_merits

    both = step_merits(hot, ("pitch", "yaw"), threshold_tol_rad=math.radians(0.02), threads=2)
    one = step_merit(hot, "yaw", threshold_tol_rad=math.radians(0.02), threads=1)
    assert both["yaw"] == one


# -- instability -------------------------------------------------------------------------------

class _NanAfter:
    """A step command that turns NaN at ``t_nan_s`` [s] (a lane that goes non-finite)."""

    def __init__(self, t_nan_s: float, duration_s: float = 0.6):
        self.t_nan_s, self.duration_s = t_nan_s, duration_s

    def __call__(self, t):
        t = np.asarray(t, float)
        return np.where(t < self.t_nan_s, Step(math.radians(0.2), 0.05, 0.5)(t), np.nan)


def test_a_nan_lane_raises_the_serial_runs_instability(hot):
    """Yaw goes NaN first in simulated time (0.2 s), pitch later (0.4 s): the serial run stops
    in pitch, the first axis, and so does the parallel one; yaw alone raises yaw's time."""
    got = {}
    for n in (1, 2):
        with pytest.raises(SimulationUnstable) as e:
            simulate(hot, TwoAxis(_NanAfter(0.4), _NanAfter(0.2)), threads=n)
        got[n] = (e.value.time_s, str(e.value))
    assert got[1] == got[2]
    assert 0.4 <= got[1][0] <= 0.4 + 1e-3
    for n in (1, 2):
        with pytest.raises(SimulationUnstable) as e:
            simulate(hot, TwoAxis(Step(math.radians(0.2), 0.05, 0.5), _NanAfter(0.2)), threads=n)
        assert 0.2 <= e.value.time_s <= 0.2 + 1e-3


def test_a_nan_lane_in_the_greenrun_writes_nothing(hot, tmp_path):
    prof = TwoAxis(Step(math.radians(0.2), 0.05, 0.5), _NanAfter(0.3))
    msgs = set()
    for n in (1, 2):
        out = tmp_path / f"rep{n}"
        with pytest.raises(SimulationUnstable) as e:
            greenrun(hot, prof, out=out, threads=n, spec=None)
        assert 0.3 <= e.value.time_s <= 0.3 + 1e-3
        msgs.add(str(e.value))
        assert not out.exists()
        assert list(tmp_path.iterdir()) == []
    assert len(msgs) == 1


def test_verdict_step_reruns_in_parallel_are_the_serial_ones():
    """The ambient model fails the mask's step (overshoot): its three single removals' step runs
    go to the threads; the verdict is the serial one."""
    from taos.report.analysis import DEFAULT_SPEC
    from taos.report.spec import load_spec
    from taos.report.verdict import spec_verdict

    amb, mask = load_model("rs25_ambient"), load_spec(DEFAULT_SPEC)
    v1, v2 = (spec_verdict(amb, mask, threads=n) for n in (1, 2))
    steps = [c for c in v1.checks if c.basis == "step"]
    assert steps and not all(c.passed for c in steps)
    assert {"friction", "load_stiffness", "avionics"} <= set(next(c for c in steps if not c.passed).removed)
    assert v1.to_dict() == v2.to_dict()
