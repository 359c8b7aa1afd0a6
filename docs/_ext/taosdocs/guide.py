"""The user guide's commands: one list, run by the docs build (which shows each command, what it
printed and the pictures it made) and by ``tests/test_docs.py`` (which checks each one exits 0
and writes its outputs).

Each :class:`Step` is a ``taos`` or ``masv`` command line exactly as a user types it from the
repository root. :func:`run_step` runs it in-process (one interpreter, so the compiled kernels
load once) in a work folder whose ``models`` is the shipped ``models/`` folder, so the same
relative paths work; outputs go under ``out/`` there. Runs are kept short (few frequencies,
short time-domain runs, one fit start) so the whole guide runs in a minute or two.
"""

from __future__ import annotations

import base64
import contextlib
import io
import re
import shlex
import shutil
import struct
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]


@dataclass(frozen=True)
class Step:
    """One command of the guide: ``outputs`` the files it must write (relative to the work
    folder), ``figures`` the pictures among them shown in the docs, ``report_html`` an HTML
    report whose inline PNG pictures are extracted and shown, ``show_stdout`` how many lines of
    its standard output the docs show (0: none)."""

    id: str
    command: str
    outputs: tuple[str, ...] = ()
    figures: tuple[str, ...] = ()
    report_html: str | None = None
    show_stdout: int = 0
    downloads: tuple[str, ...] = ()


@dataclass
class StepResult:
    step: Step
    exit_code: int
    stdout: str
    stderr: str
    workdir: Path
    figures: list[Path] = field(default_factory=list)

    @property
    def missing(self) -> list[str]:
        return [o for o in self.step.outputs if not (self.workdir / o).exists()]


DATA_A = "models/data/greenrun_ambient_synthetic.csv"
DATA_B = "models/data/greenrun_hotfire_synthetic.csv"
LCO_SHORT = "--amplitudes-deg 0.03,0.1,0.3 --freq-hz 0.05,0.08,0.12,0.18,0.27,0.4"

STEPS: tuple[Step, ...] = (
    # -- Green Run ---------------------------------------------------------------------------
    Step("info", "taos info rs25_hotfire", show_stdout=40),
    Step("greenrun", "taos greenrun rs25_hotfire --out out/greenrun --quiet",
         outputs=("out/greenrun/index.html", "out/greenrun/greenrun.h5"), report_html="out/greenrun/index.html"),
    Step("freqresp", "taos freqresp rs25_hotfire --freq-hz 0.5,1,2,4,7,10,14 --amplitude-deg 0.4 "
         "--plot out/bode_hotfire.png --json out/freqresp_hotfire.json",
         outputs=("out/bode_hotfire.png", "out/freqresp_hotfire.json"), figures=("out/bode_hotfire.png",)),
    Step("freqresp_map", "taos freqresp rs25_hotfire --freq-hz 0.5,1,2,4,7,10 --amplitude-deg 0.05,0.1,0.4 "
         "--steady shoot --plot out/df_map.png --json out/df_map.json",
         outputs=("out/df_map.png", "out/df_map.json"), figures=("out/df_map.png",)),
    Step("simulate", "taos simulate rs25_hotfire --profile step_pitch --out out/step_pitch.h5",
         outputs=("out/step_pitch.h5",)),
    Step("view", "taos view out/step_pitch.h5 --html out/step_pitch.html",
         outputs=("out/step_pitch.html",), downloads=("out/step_pitch.html",)),
    # -- LCO ---------------------------------------------------------------------------------
    Step("lco", f"taos lco rs25_flight --flight core_stage {LCO_SHORT} --duration 60 "
         "--plot out/lco_nichols.png --plot-df out/lco_df.png --plot-time out/lco_time.png --json out/lco.json",
         outputs=("out/lco.json", "out/lco_nichols.png", "out/lco_df.png", "out/lco_time.png"),
         figures=("out/lco_df.png", "out/lco_nichols.png", "out/lco_time.png")),
    Step("lco_stiff", f"taos lco rs25_flight --flight core_stage --load-stiffness '205000 lbf/in' "
         f"{LCO_SHORT} --no-time-domain --plot out/lco_stiff.png --json out/lco_stiff.json",
         outputs=("out/lco_stiff.json", "out/lco_stiff.png"), figures=("out/lco_stiff.png",)),
    Step("lco_coulomb", f"taos lco rs25_flight --flight core_stage --friction coulomb-switching "
         f"{LCO_SHORT} --no-time-domain --json out/lco_coulomb.json", outputs=("out/lco_coulomb.json",)),
    Step("signoff", f"taos lco rs25_flight --flight core_stage {LCO_SHORT} --no-time-domain "
         "--requirements models/specs/flight_signoff_notional.toml --sweep load_stiffness=90000lbf/in,205000lbf/in "
         "--signoff out/signoff", outputs=("out/signoff/signoff.json", "out/signoff/signoff.html"), show_stdout=12,
         downloads=("out/signoff/signoff.html",)),
    # -- identification ----------------------------------------------------------------------
    Step("estimate", f"taos estimate {DATA_B} --json out/estimate_hotfire.json",
         outputs=("out/estimate_hotfire.json",)),
    Step("fit", f"taos fit {DATA_B} --model rs25_hotfire --free load_stiffness,coulomb_torque --starts 1 "
         "--plot out/fit_hotfire.png --out-model out/fit_hotfire.toml --json out/fit_hotfire.json",
         outputs=("out/fit_hotfire.png", "out/fit_hotfire.toml", "out/fit_hotfire.json"),
         figures=("out/fit_hotfire.png",)),
    Step("compare", f"taos compare rs25_ambient rs25_hotfire --data {DATA_A} {DATA_B} --out out/compare",
         outputs=("out/compare/table.txt", "out/compare/comparison.json", "out/compare/bode_overlay.png",
                  "out/compare/piston_side_by_side.png"),
         figures=("out/compare/bode_overlay.png", "out/compare/piston_side_by_side.png"), show_stdout=40),
    # -- Monte Carlo -------------------------------------------------------------------------
    Step("montecarlo", "taos montecarlo post_separation --runs 4 --workers 1 --out out/mc --no-progress",
         outputs=("out/mc/summary.json", "out/mc/campaign.zarr", "out/mc/montecarlo.png"),
         figures=("out/mc/montecarlo.png",), show_stdout=5),
    # -- Sweeps ------------------------------------------------------------------------------
    Step("sweep", "taos sweep rs25_ambient --set 'structure.load_stiffness=80000 lbf/in,115000 lbf/in,150000 lbf/in' "
         "--set 'actuator.loop_gain=20 1/s,40 1/s,400 1/s' --metric load_resonance_hz,engine_peaking_db,"
         "phase_margin_deg --out out/sweep --json out/sweep.json --plot out/sweep.png",
         outputs=("out/sweep.json", "out/sweep.png", "out/sweep/sweep.zarr", "out/sweep/sweep.json"),
         figures=("out/sweep.png",), show_stdout=14),
    Step("sweep_lco", f"taos sweep rs25_flight --flight core_stage {LCO_SHORT} --set 'structure.load_stiffness="
         "115000 lbf/in,160000 lbf/in,205000 lbf/in' --metric lco,lco_engine_amplitude_deg,lco_margin_db "
         "--plot out/sweep_lco.png", outputs=("out/sweep_lco.png",), figures=("out/sweep_lco.png",), show_stdout=6),
    # -- MASV --------------------------------------------------------------------------------
    Step("masv_modes", "masv modes core_stage", show_stdout=30),
    Step("masv_freqresp", "masv freqresp core_stage --freq-hz 0.5,1,2,3,5,7,10,14 --plot out/masv_grid.png "
         "--json out/masv_freqresp.json", outputs=("out/masv_grid.png", "out/masv_freqresp.json"),
         figures=("out/masv_grid.png",)),
    Step("masv_coupling", "masv coupling core_stage --plot out/masv_coupling.png --json out/masv_coupling.json",
         outputs=("out/masv_coupling.png", "out/masv_coupling.json"), figures=("out/masv_coupling.png",)),
)

STEP_BY_ID = {s.id: s for s in STEPS}


def prepare_workdir(workdir: Path) -> Path:
    """A work folder whose ``models`` is the shipped models folder; ``out/`` starts empty."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    link = workdir / "models"
    if not link.exists():
        from taos.shipped import models_dir
        link.symlink_to(models_dir(), target_is_directory=True)
    return workdir


def _main(prog: str):
    if prog == "taos":
        from taos.cli import main
    elif prog == "masv":
        from masv.cli import main
    else:
        raise ValueError(f"guide commands are taos or masv commands, got {prog!r}")
    return main


_PNG = re.compile(r'data:image/png;base64,([A-Za-z0-9+/=]+)')


def extract_report_pictures(html_file: Path, dest: Path, prefix: str, min_px: int = 100) -> list[Path]:
    """The inline base64 PNG pictures of an HTML report (plots, not icons: both sides at least
    ``min_px`` pixels), saved as ``prefix_N.png`` in ``dest``."""
    out = []
    for m in _PNG.finditer(Path(html_file).read_text(encoding="utf-8")):
        png = base64.b64decode(m.group(1))
        w, h = struct.unpack(">II", png[16:24])
        if min(w, h) < min_px:
            continue
        p = dest / f"{prefix}_{len(out) + 1}.png"
        p.write_bytes(png)
        out.append(p)
    return out


def run_step(step: Step, workdir: Path) -> StepResult:
    """Run one guide command in ``workdir`` (see :func:`prepare_workdir`), in-process."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    workdir = prepare_workdir(workdir)
    (workdir / "out").mkdir(exist_ok=True)
    for o in step.outputs:           # a fresh run: the command may refuse to overwrite
        p = workdir / o
        if p.is_dir():
            shutil.rmtree(p)
        elif p.exists():
            p.unlink()
        if Path(o).parent != Path("out") and p.parent.is_dir() and p.parent != workdir / "out":
            shutil.rmtree(p.parent)
    argv = shlex.split(step.command)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(workdir), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = int(_main(argv[0])(argv[1:]) or 0)
        except SystemExit as e:  # argparse errors
            code = int(e.code or 0)
    plt.close("all")
    res = StepResult(step, code, out.getvalue(), err.getvalue(), workdir)
    res.figures = [workdir / f for f in step.figures if (workdir / f).exists()]
    if step.report_html and (workdir / step.report_html).exists():
        dest = workdir / "out" / f"{step.id}_pictures"
        if dest.exists():
            shutil.rmtree(dest)
        dest.mkdir(parents=True)
        res.figures += extract_report_pictures(workdir / step.report_html, dest, step.id)
    return res


def run_python(code: str, workdir: Path) -> str:
    """Run a Python example of the guide in ``workdir``; returns what it printed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    (Path(workdir) / "out").mkdir(parents=True, exist_ok=True)
    out = io.StringIO()
    with contextlib.chdir(workdir), contextlib.redirect_stdout(out):
        exec(compile(code, "<guide example>", "exec"), {"__name__": "__guide__"})
    plt.close("all")
    return out.getvalue()


PY_EXAMPLE = re.compile(r"```\{taos-python\}[^\n]*\n((?::[a-z]+:[^\n]*\n)*)(.*?)```", re.S)


def python_examples(docs_dir: Path) -> list[tuple[str, str]]:
    """(page, code) of every ``{taos-python}`` example in the guide pages."""
    out = []
    for md in sorted(Path(docs_dir).rglob("*.md")):
        if "_generated" in md.parts or "_build" in md.parts:
            continue
        for m in PY_EXAMPLE.finditer(md.read_text(encoding="utf-8")):
            out.append((md.relative_to(docs_dir).as_posix(), m.group(2)))
    return out


# -- what the docs build ran, for the tests of the same `make test` (tests/test_docs.py) -------
def _record_path(records: Path, kind: str, key: str) -> Path:
    return Path(records) / f"{kind}_{re.sub(r'[^A-Za-z0-9_.-]', '_', key)}.json"


def write_step_record(res: StepResult, records: Path) -> None:
    """Save what :func:`run_step` returned (exit code, printed text, pictures relative to the
    work folder) as ``records/step_ID.json``."""
    import json
    Path(records).mkdir(parents=True, exist_ok=True)
    rec = {"id": res.step.id, "command": res.step.command, "exit_code": res.exit_code, "stdout": res.stdout,
           "stderr": res.stderr[-4000:], "figures": [f.relative_to(res.workdir).as_posix() for f in res.figures]}
    _record_path(records, "step", res.step.id).write_text(json.dumps(rec), encoding="utf-8")


def read_step_record(step: Step, records: Path, workdir: Path) -> StepResult | None:
    """The :class:`StepResult` the docs build saved for ``step`` (its outputs and pictures read
    from ``workdir`` now), or None when it has no record of this very command."""
    import json
    p = _record_path(records, "step", step.id)
    if not p.is_file():
        return None
    rec = json.loads(p.read_text(encoding="utf-8"))
    if rec["command"] != step.command:
        return None
    return StepResult(step, rec["exit_code"], rec["stdout"], rec["stderr"], Path(workdir),
                      [Path(workdir) / f for f in rec["figures"]])


def write_python_record(page: str, code: str, error: str | None, records: Path) -> None:
    """Save that the Python example ``code`` of ``page`` ran (``error`` None) or how it failed."""
    import hashlib
    import json
    Path(records).mkdir(parents=True, exist_ok=True)
    key = hashlib.sha256(code.strip().encode()).hexdigest()[:16]
    rec = {"page": page, "code": code, "error": error}
    _record_path(records, "python", key).write_text(json.dumps(rec), encoding="utf-8")


def python_record_error(code: str, records: Path) -> str | None:
    """How the docs build's run of the Python example ``code`` ended: None (no exception), the
    exception's text, or ``"not run by the docs build"``."""
    import hashlib
    import json
    p = _record_path(records, "python", hashlib.sha256(code.strip().encode()).hexdigest()[:16])
    if not p.is_file():
        return "not run by the docs build"
    rec = json.loads(p.read_text(encoding="utf-8"))
    return rec["error"] if rec["code"].strip() == code.strip() else "not run by the docs build"
