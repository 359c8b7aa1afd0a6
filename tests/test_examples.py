"""The examples gallery (issue 29 point 4): every ``examples/plot_*.py`` runs as a user would run
it (a fresh interpreter, from another folder, headless plots) and prints what it is about; the
documentation build runs the same scripts through sphinx-gallery (docs/conf.py).

Each script checks its own physics where it has a reference (the fit recovers the record's load
stiffness, python-control and taos.loop_margins agree on the phase margin, a law of one's own
reproduces the built-in law it equals); here the printed lines are checked too.

The examples run once per ``make test``: in its documentation build, whose sphinx-gallery run
records each example (``taosdocs.gallery``: ``docs/_generated/records``, emptied at the start of
each build). Under ``make test`` (``TAOS_TEST_DOCS_STATUS``, as in tests/test_docs.py; make test
runs this file right after that build) :func:`test_example_runs` checks the same three things on
that record when the build succeeded and recorded this very source: the example ran without an
exception, printed every expected line, and left its working folder as it found it. Otherwise
(``make check``, plain pytest, a failed build, no record or one of another source) it runs the
script here in a fresh interpreter, as before. What differs in the gallery's run:

* the examples run one after another in the Sphinx process (not each in a fresh interpreter):
  modules, compiled kernels and caches stay loaded from one to the next. State an example leaves
  is reset between examples: matplotlib (sphinx-gallery's reset: rc parameters, figures closed)
  and the friction registry (a law an example registers is removed after it, by the hook);
  no example reads other global state that another sets. ``__file__`` is undefined there
  (an example that uses it fails the build);
* the working folder is the example's own folder ``examples/`` (sphinx-gallery sets it for each
  code block; it is not configurable), not an empty one: "writes nothing into the working
  folder" is checked as "every file and folder under ``examples/`` is the same (path, size,
  modification time) after the example as before it";
* the output checked is what the gallery captured and shows on the example's page: its
  standard output and standard error together (every expected line is printed with print());
* the exit status: an exception in an example stops the build (``abort_on_example_error``), so
  the build fails (and so does make test) and these tests run every example themselves.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from .conftest import ROOT, docs_build_succeeded

sys.path.insert(0, str(ROOT / "docs" / "_ext"))
from taosdocs import gallery  # noqa: E402

EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))

#: what each example must print (besides running without error)
EXPECT = {
    "plot_greenrun_own_model.py": ["load resonance 6.50 Hz", "fails the mask", "pitch engine: -3 dB at"],
    "plot_fit_own_record.py": ["fitted K_L / true K_L = ", "model adequacy: ADEQUATE"],
    "plot_ambient_vs_hotfire.py": ["load_stiffness", "ratio 1.783", "notch_frequency_pitch_hz"],
    "plot_lco_verdict.py": ["limit cycle expected", "the verdict flips between"],
    "plot_flight_signoff.py": ["flight sign-off against NOTIONAL requirements", "FAIL in 1 of 3 case(s)"],
    "plot_masv_coupling.py": ["strongest engine-to-engine", "below the direct response"],
    "plot_control_interop.py": ["python-control: gain margin", "taos.loop_margins: phase margin"],
    "plot_custom_friction_law.py": ["(viscous-coulomb-example)", "with c = 2e5 N m s/rad"],
    "plot_fmu_in_fmpy.py": ["FMPy validation problems: []", "max engine-angle difference 0 deg"],
    "plot_fit_reduce_lco_chain.py": ["hot fire: fitted K_L", "not explained by the FEM gimbal pair",
                                     "reduction within tolerance: True", "K_L =  60,000 lbf/in", "chain run time"],
    "plot_montecarlo_sobol.py": ["160 model variants (sobol design), 160 computed", "(analytic: 1 and 0)"],
}


def test_the_gallery_has_at_least_eight_examples_each_with_a_title():
    assert len(EXAMPLES) >= 8
    assert {p.name for p in EXAMPLES} >= set(EXPECT)
    for p in EXAMPLES:
        doc = p.read_text().split('"""')[1].strip().splitlines()
        assert len(doc) >= 3 and set(doc[1]) == {"="} and len(doc[1]) >= len(doc[0]), p.name   # an rst title


@pytest.fixture(scope="module")
def gallery_records():
    """Under make test, once its documentation build succeeded: the folder of its records; else None."""
    return gallery.records_dir(ROOT / "docs") if docs_build_succeeded() else None


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(path, tmp_path, gallery_records):
    rec = gallery.read_record(path, gallery_records) if gallery_records is not None else None
    if rec is not None:          # the docs build's run of this very source (module docstring)
        assert rec["error"] is None, rec["error"][-2000:]
        for text in EXPECT.get(path.name, []):
            assert text in rec["output"], (text, rec["output"][-1500:])
        assert rec["folder_after"] == rec["folder_before"]   # examples write nothing into the working folder
        return
    env = {**os.environ, "MPLBACKEND": "Agg"}
    r = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    for text in EXPECT.get(path.name, []):
        assert text in r.stdout, (text, r.stdout[-1500:])
    assert list(tmp_path.iterdir()) == []          # examples write nothing into the working folder


def test_a_gallery_record_counts_only_for_the_source_it_ran(tmp_path):
    """The docs build's record of an example stands for it only while the source is the one it
    ran (an edited example is run here again); its output is read back from the page's blocks."""
    page = ("Text.\n\n.. rst-class:: sphx-glr-script-out\n\n .. code-block:: none\n\n    first line\n\n"
            "      indented\n\n\n\n.. GENERATED FROM PYTHON SOURCE LINES 3-4\n\nMore text.\n\n"
            ".. rst-class:: sphx-glr-script-out\n\n .. code-block:: none\n\n    second block\n\n\n\n"
            ".. rst-class:: sphx-glr-timing\n")
    assert gallery.captured_output(page) == "first line\n\n  indented\nsecond block"
    example = tmp_path / "plot_x.py"
    example.write_text("print('x')\n")
    rec = {"example": example.name, "source_sha256": gallery.source_hash(example), "error": None, "output": "x",
           "folder_before": [], "folder_after": []}
    from taosdocs.guide import _record_path
    (tmp_path / "records").mkdir()
    _record_path(tmp_path / "records", "gallery", example.name).write_text(json.dumps(rec))
    assert gallery.read_record(example, tmp_path / "records") == rec
    example.write_text("print('y')\n")
    assert gallery.read_record(example, tmp_path / "records") is None
    assert gallery.read_record(tmp_path / "plot_other.py", tmp_path / "records") is None
