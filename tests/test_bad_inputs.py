"""Bad and hostile input at every entry point (issue: "No silent wrong answers and no lost files").

Each case runs the CLI in-process (``taos.cli.main`` / ``masv.cli.main``) and checks the
contract of DESIGN.md: exit status 2, exactly one line on standard error, no traceback, and no
output file. The cases cover model, profile, flight, MASV and data files, FEM stiffness
matrices, command-line options and output places; ``test_case_count`` keeps the count honest.
"""

from __future__ import annotations

import pickle
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from .conftest import inline_actuator_set

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
AMBIENT = MODELS / "rs25_ambient.toml"
PROFILE = MODELS / "profiles" / "step_pitch.toml"
DATA = MODELS / "data" / "greenrun_ambient_synthetic.csv"


# -- helpers that write bad files ---------------------------------------------------------------

def model_text() -> str:
    """The ambient model with its stiffness file made absolute (so copies work anywhere) and its
    shared actuator set inlined."""
    t = inline_actuator_set(AMBIENT.read_text(), AMBIENT)  # actuator keys editable in the copy
    return t.replace('stiffness_file = "../fem_data/', f'stiffness_file = "{ROOT}/fem_data/')


def model_with(tmp: Path, *subs: tuple[str, str], append: str = "", name: str = "m.toml") -> Path:
    """A copy of the ambient model with regex substitutions (pattern, replacement) per line."""
    t = model_text()
    for pat, rep in subs:
        t2 = re.sub(pat, rep, t, count=1, flags=re.M)
        assert t2 != t, pat
        t = t2
    p = tmp / name
    p.write_text(t + append)
    return p


def write(tmp: Path, name: str, text: str | bytes) -> Path:
    p = tmp / name
    p.write_bytes(text if isinstance(text, bytes) else text.encode())
    return p


def profile(tmp: Path, text: str) -> Path:
    return write(tmp, "p.toml", text)


DWELL = 'type = "sine_dwell"\namplitude = "0.4 deg"\nfrequency = "1 Hz"\ncycles = 2\n'


def data_csv(tmp: Path, edit: Callable[[list[str]], list[str]] | None = None, name="d.csv") -> Path:
    lines = DATA.read_text().splitlines()[:4000]
    if edit:
        lines = edit(lines)
    return write(tmp, name, "\n".join(lines) + "\n")


def _first_data_row(lines):
    return next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#")) + 1


def set_cell(row: int, col: int, value: str):
    def edit(lines):
        k = _first_data_row(lines) + row
        cells = lines[k].split(",")
        cells[col] = value
        lines[k] = ",".join(cells)
        return lines
    return edit


def last_time(value: str):
    def edit(lines):
        cells = lines[-1].split(",")
        cells[0] = value
        lines[-1] = ",".join(cells)
        return lines
    return edit


def sidecar_csv(tmp: Path, sidecar: str) -> Path:
    """Plain column names and a sidecar TOML."""
    write(tmp, "s.csv", "t,c,x\n" + "\n".join(f"{i * 0.01},{np.sin(i / 5):.5f},{np.sin(i / 5) * 0.01:.6f}"
                                              for i in range(200)) + "\n")
    write(tmp, "s.toml", 'sidecar_for = "s.csv"\n' + sidecar)   # the mark: this TOML is s.csv's sidecar
    return tmp / "s.csv"


GOOD_SIDECAR = ('[columns]\nt = {signal = "time", unit = "s"}\nc = {signal = "pitch_command", unit = "deg"}\n'
                'x = {signal = "pitch_piston", unit = "in"}\n')


def masv_with(tmp: Path, old: str, new: str) -> Path:
    t = (MODELS / "masv" / "core_stage.toml").read_text()
    t = t.replace('"../../fem_data/', f'"{ROOT}/fem_data/').replace('"../rs25_hotfire.toml"',
                                                                  f'"{MODELS}/rs25_hotfire.toml"')
    assert old in t, old
    return write(tmp, "masv.toml", t.replace(old, new, 1))


def flight_with(tmp: Path, old: str, new: str) -> Path:
    t = (MODELS / "flight" / "core_stage.toml").read_text()
    t = t.replace('"../rs25_flight.toml"', f'"{MODELS}/rs25_flight.toml"')
    assert old in t, old
    return write(tmp, "flight.toml", t.replace(old, new, 1))


def fem_model(tmp: Path, npz: Path) -> Path:
    return model_with(tmp, (r'^stiffness_file = .*$', f'stiffness_file = "{npz}"'))


def npz(tmp: Path, **arrays) -> Path:
    p = tmp / "K.npz"
    np.savez(p, **arrays)
    return p


def good_k():
    from taos.fem.io import load_gimbal_stiffness

    g = load_gimbal_stiffness(ROOT / "fem_data" / "gimbal_hanging.npz")
    return g


# -- the cases ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class Case:
    """``build(tmp) -> argv`` (with ``OUT`` standing for the output path); ``prog`` taos or masv."""

    name: str
    build: Callable[[Path], list]
    prog: str = "taos"
    outputs: tuple[str, ...] = ("out.h5", "out.json", "outdir", "out.html", "out.png", "fit.toml")
    expect_in_line: tuple[str, ...] = field(default=())


def sim(model=AMBIENT, prof=PROFILE, *more):
    return ["simulate", str(model), "--profile", str(prof), "--out", "OUT/out.h5", *more]


def info(model):
    return ["info", str(model), "--json", "OUT/out.json"]


def fr(*more, model=AMBIENT):
    return ["freqresp", str(model), *more, "--json", "OUT/out.json"]


def est(path, *more):
    return ["estimate", str(path), *more, "--json", "OUT/out.json"]


C = Case
CASES = [
    # model files ------------------------------------------------------------------------------
    C("model missing", lambda t: info(t / "nope.toml")),
    C("model not TOML", lambda t: info(write(t, "m.toml", "this is = = not toml"))),
    C("model binary", lambda t: info(write(t, "m.toml", bytes(range(256))))),
    C("model empty", lambda t: info(write(t, "m.toml", ""))),
    C("model section missing", lambda t: info(model_with(t, (r"^\[engine\]", "[engine_old]"))), expect_in_line=("engine",)),
    C("model section typo", lambda t: info(model_with(t, append='\n[structur]\nload_stiffness = "1 N/m"\n')),
      expect_in_line=("did you mean 'structure'",)),
    C("model key typo", lambda t: info(model_with(t, (r"^loop_gain", "loop_gian"))), expect_in_line=("did you mean 'loop_gain'",)),
    C("model section is a list", lambda t: info(write(t, "m.toml", model_text().replace("[structure]", "structure = [1, 2]\n[structure_x]")))),
    C("model wrong unit", lambda t: info(model_with(t, (r'^load_stiffness = "[^"]*"', 'load_stiffness = "115000 lbf"')))),
    C("model negative stiffness", lambda t: info(model_with(t, (r'^load_stiffness = "[^"]*"', 'load_stiffness = "-115000 lbf/in"')))),
    C("model absurd stiffness", lambda t: info(model_with(t, (r'^load_stiffness = "[^"]*"', 'load_stiffness = "1e300 lbf/in"'))),
      expect_in_line=("structure.load_stiffness",)),
    C("model nan stiffness", lambda t: info(model_with(t, (r'^load_stiffness = "[^"]*"', 'load_stiffness = "nan lbf/in"')))),
    C("model name is a table", lambda t: info(model_with(t, (r"^name = .*$", "name = {a = 1}"))), expect_in_line=("name",)),
    C("model valve order 3", lambda t: info(model_with(t, (r"^valve_order = .*$", "valve_order = 3")))),
    C("model bits as text", lambda t: info(model_with(t, (r"^quantization_bits = .*$", 'quantization_bits = "12"')))),
    C("model rounding unknown", lambda t: info(model_with(t, (r"^rounding = .*$", 'rounding = "up"')))),
    C("model friction law unknown", lambda t: info(model_with(t, (r'^model = .*$', 'model = "stribeck"')))),
    C("model friction key typo", lambda t: info(model_with(t, (r"^coulomb_torque", "coulomb_torqe")))),
    C("model mass boolean", lambda t: info(model_with(t, (r"^mass = .*$", "mass = true")))),
    C("model zero piston area", lambda t: info(model_with(t, (r'^piston_area = .*$', 'piston_area = "0 in**2"')))),
    C("model crossover lengths", lambda t: info(model_with(t, (r"^crossover_gain = .*$", "crossover_gain = [1.0]")))),
    C("--friction unknown", lambda t: ["info", str(AMBIENT), "--friction", "bogus", "--json", "OUT/out.json"]),
    # profiles ---------------------------------------------------------------------------------
    C("profile missing", lambda t: sim(AMBIENT, t / "nope.toml")),
    C("profile pitch is text", lambda t: sim(AMBIENT, profile(t, 'pitch = "sine"\n'))),
    C("profile segments are numbers", lambda t: sim(AMBIENT, profile(t, '[pitch]\ntype = "sequence"\nsegments = [1, 2]\n'))),
    C("profile key typo", lambda t: sim(AMBIENT, profile(t, DWELL.replace("cycles", "cycels"))),
      expect_in_line=("did you mean 'cycles'",)),
    C("profile huge cycle count", lambda t: sim(AMBIENT, profile(t, DWELL.replace("cycles = 2", "cycles = 1000000000000")))),
    C("profile 1e-300 Hz", lambda t: sim(AMBIENT, profile(t, DWELL.replace('"1 Hz"', '"1e-300 Hz"')))),
    C("profile amplitude beyond gimbal", lambda t: sim(AMBIENT, profile(t, DWELL.replace('"0.4 deg"', '"20 deg"'))),
      expect_in_line=("10.5 deg",)),
    C("profile 45 deg step", lambda t: sim(AMBIENT, profile(t, 'type = "step"\namplitude = "45 deg"\n')),
      expect_in_line=("10.5 deg",)),
    C("profile unknown type", lambda t: sim(AMBIENT, profile(t, 'type = "square"\n'))),
    C("profile zero cycles", lambda t: sim(AMBIENT, profile(t, DWELL.replace("cycles = 2", "cycles = 0")))),
    C("profile fractional cycles", lambda t: sim(AMBIENT, profile(t, DWELL.replace("cycles = 2", "cycles = 2.5")))),
    C("profile logarithmic as text", lambda t: sim(AMBIENT, profile(
        t, 'type = "sine_sweep"\namplitude = "0.4 deg"\nstart_frequency = "1 Hz"\nend_frequency = "2 Hz"\n'
           'duration = "2 s"\nlogarithmic = "yes"\n'))),
    C("profile sweep of 1e9 s", lambda t: sim(AMBIENT, profile(
        t, 'type = "sine_sweep"\namplitude = "0.4 deg"\nstart_frequency = "1 Hz"\nend_frequency = "2 Hz"\n'
           'duration = "1e9 s"\n'))),
    C("profile empty multisine", lambda t: sim(AMBIENT, profile(
        t, 'type = "multisine"\namplitude = "0.4 deg"\nfrequencies = []\nduration = "2 s"\n'))),
    C("profile name is a table", lambda t: sim(AMBIENT, profile(t, "name = {a = 1}\n" + DWELL))),
    C("profile frequency in metres", lambda t: sim(AMBIENT, profile(t, DWELL.replace('"1 Hz"', '"1 m"')))),
    C("profile zero ramp rate", lambda t: sim(AMBIENT, profile(
        t, 'type = "multi_ramp"\nlevels = ["0.2 deg"]\nrate = "0 deg/s"\n'))),
    C("profile top-level typo", lambda t: sim(AMBIENT, profile(t, '[pich]\n' + DWELL)), expect_in_line=("pitch",)),
    # command-line options ---------------------------------------------------------------------
    C("--dt 1e-9", lambda t: sim(AMBIENT, PROFILE, "--dt", "1e-9"), expect_in_line=("--dt",)),
    C("--dt oversized", lambda t: sim(AMBIENT, PROFILE, "--dt", "0.01"), expect_in_line=("at most", "--dt")),
    C("--dt negative", lambda t: sim(AMBIENT, PROFILE, "--dt", "-1")),
    C("--dt nan", lambda t: sim(AMBIENT, PROFILE, "--dt", "nan")),
    C("--dt text", lambda t: sim(AMBIENT, PROFILE, "--dt", "abc")),
    C("--freq-hz 1e9", lambda t: fr("--freq-hz", "1e9", "--amplitude-deg", "0.4")),
    C("--freq-hz 1e-9", lambda t: fr("--freq-hz", "1e-9", "--amplitude-deg", "0.4")),
    C("--freq-hz 1e-4 sine dwell (job too long)", lambda t: fr("--freq-hz", "1e-4", "--amplitude-deg", "0.4"),
      expect_in_line=("steps",)),
    C("--freq-hz text", lambda t: fr("--freq-hz", "abc")),
    C("--amplitude-deg list with text", lambda t: fr("--freq-hz", "1", "--amplitude-deg", "0.1,abc"),
      expect_in_line=("--amplitude-deg",)),
    C("--amplitude-deg list, one beyond the gimbal", lambda t: fr("--freq-hz", "1", "--amplitude-deg", "0.1,40"),
      expect_in_line=("--amplitude-deg",)),
    C("--steady shoot with the 3-D engine", lambda t: fr("--freq-hz", "1", "--amplitude-deg", "0.1", "--steady",
                                                          "shoot", "--engine", "taos"), expect_in_line=("--steady",)),
    C("--amplitude-deg map too long", lambda t: fr("--freq-hz", "0.01,0.02", "--amplitude-deg",
                                                   ",".join(["0.1"] * 400)), expect_in_line=("--freq-hz",)),
    C("--freq-hz negative", lambda t: fr("--freq-hz", "-1")),
    C("--amplitude-deg 20", lambda t: fr("--freq-hz", "1", "--amplitude-deg", "20"), expect_in_line=("10.5",)),
    C("--amplitude-deg below LSB", lambda t: fr("--freq-hz", "1", "--amplitude-deg", "0.001"), expect_in_line=("LSB",)),
    C("--axis roll", lambda t: fr("--freq-hz", "1", "--axis", "roll")),
    C("--nperseg -5", lambda t: est(DATA, "--method", "h1", "--nperseg", "-5")),
    C("--nperseg 0", lambda t: est(DATA, "--method", "h1", "--nperseg", "0")),
    C("--starts 0", lambda t: ["fit", str(DATA), "--model", str(AMBIENT), "--free", "load_stiffness",
                               "--starts", "0", "--json", "OUT/out.json"]),
    C("--min-coherence 2", lambda t: ["fit", str(DATA), "--model", str(AMBIENT), "--free", "load_stiffness",
                                      "--min-coherence", "2", "--json", "OUT/out.json"]),
    C("--start without =", lambda t: ["fit", str(DATA), "--model", str(AMBIENT), "--free", "load_stiffness",
                                      "--start", "load_stiffness", "--json", "OUT/out.json"]),
    C("view --angle-scale -1", lambda t: ["view", str(t / "run.h5"), "--angle-scale", "-1", "--html", "OUT/out.html"]),
    C("view of a non-run", lambda t: ["view", str(write(t, "run.h5", "not hdf5")), "--html", "OUT/out.html"]),
    C("unknown subcommand", lambda t: ["simulat", str(AMBIENT)]),
    C("compare three labels", lambda t: ["compare", str(AMBIENT), str(AMBIENT), "--labels", "a,b,c", "--out", "OUT/outdir"]),
    C("greenrun engine unknown", lambda t: ["greenrun", str(AMBIENT), "--engine", "bogus", "--out", "OUT/outdir"]),
    C("greenrun one-axis profile", lambda t: ["greenrun", str(AMBIENT), "--profile", str(PROFILE), "--out", "OUT/outdir"]),
    # data files -------------------------------------------------------------------------------
    C("data missing", lambda t: est(t / "nope.csv")),
    C("data wrong suffix", lambda t: est(write(t, "d.dat", "1,2\n"))),
    C("data NaN", lambda t: est(data_csv(t, set_cell(5, 1, "nan")))),
    C("data text cell", lambda t: est(data_csv(t, set_cell(5, 1, "abc")))),
    C("data reversed time", lambda t: est(data_csv(t, set_cell(5, 0, "-1")))),
    C("data mistyped timestamp 1e12", lambda t: est(data_csv(t, last_time("1e12"))),
      expect_in_line=("time",)),
    C("data too few samples", lambda t: est(data_csv(t, lambda ls: ls[:_first_data_row(ls) + 5]))),
    C("data header without unit", lambda t: est(data_csv(t, lambda ls: [
        ln.replace("pitch_command [deg]", "pitch_command") for ln in ls]))),
    C("data unit of mass", lambda t: est(data_csv(t, lambda ls: [
        ln.replace("pitch_command [deg]", "pitch_command [kg]") for ln in ls]))),
    C("data empty", lambda t: est(write(t, "d.csv", ""))),
    C("data binary", lambda t: est(write(t, "d.csv", bytes(range(256)) * 4))),
    C("data metadata typo", lambda t: est(data_csv(t, lambda ls: ['# conditon = "x"'] + ls)),
      expect_in_line=("did you mean 'condition'",)),
    C("sidecar columns = 5", lambda t: est(sidecar_csv(t, "columns = 5\n"))),
    C("sidecar unknown key", lambda t: est(sidecar_csv(t, 'conditon = "ambient"\n' + GOOD_SIDECAR)),
      expect_in_line=("did you mean 'condition'",)),
    C("sidecar unknown signal", lambda t: est(sidecar_csv(t, GOOD_SIDECAR.replace('"pitch_piston"', '"pitch_pistn"')))),
    C("sidecar spec key typo", lambda t: est(sidecar_csv(t, GOOD_SIDECAR.replace('unit = "in"}', 'unit = "in", unti = 1}'))),
      expect_in_line=("did you mean 'unit'",)),
    C("sidecar not TOML", lambda t: est(sidecar_csv(t, "[[[ nonsense"))),
    # FEM stiffness matrices (3-D engine) ----------------------------------------------------------
    C("npz empty", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos", model=fem_model(t, npz(t)))),
    C("npz is text", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos",
                                  model=fem_model(t, write(t, "K.npz", "K_upper = 1\n")))),
    C("npz pickled", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos",
                                  model=fem_model(t, write(t, "K.npz", pickle.dumps({"K_upper": np.eye(6)}))))),
    C("npz object array", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos",
                                       model=fem_model(t, npz(t, K_upper=np.array([{"a": 1}], dtype=object),
                                                              K_lower=np.eye(6))))),
    C("npz asymmetric", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos", model=fem_model(
        t, npz(t, K_upper=np.triu(np.ones((6, 6))) * 1e8 + np.eye(6) * 1e9, K_lower=np.eye(6) * 1e9)))),
    C("npz wrong shape", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos", model=fem_model(
        t, npz(t, K_upper=np.eye(5) * 1e9, K_lower=np.eye(6) * 1e9)))),
    C("npz missing", lambda t: fr("--freq-hz", "1", "--linear", "--engine", "taos", model=fem_model(t, t / "none.npz"))),
    # flight files ---------------------------------------------------------------------------------
    C("flight missing", lambda t: ["lco", str(AMBIENT), "--flight", str(t / "nope.toml"), "--json", "OUT/out.json"]),
    C("flight section typo", lambda t: ["lco", str(AMBIENT), "--flight", str(flight_with(t, "\n[fcs]", "\n[fsc]")),
                                        "--json", "OUT/out.json"], expect_in_line=("did you mean 'fcs'",)),
    C("flight vehicle is a number", lambda t: ["lco", str(AMBIENT), "--flight", str(flight_with(t, "[vehicle]", "vehicle = 5\n[vehicle_x]")),
                                               "--json", "OUT/out.json"]),
    # MASV configurations ------------------------------------------------------------------------
    C("masv engine = [1, 2]", lambda t: ["freqresp", str(masv_with(t, '[[engine]]\nname = "engine_1"', 'engine = [1, 2]\n[[engine_x]]\nname = "engine_1"')),
                                         "--freq-hz", "1", "--json", "OUT/out.json"], prog="masv"),
    C("masv key typo", lambda t: ["modes", str(masv_with(t, "gimbal_node = \"gimbal_1\"", "gimbal_nod = \"gimbal_1\"")),
                                  "--json", "OUT/out.json"], prog="masv", expect_in_line=("did you mean 'gimbal_node'",)),
    C("masv band is text", lambda t: ["modes", str(masv_with(t, '[band]', 'band = "wide"\n[band_x]')),
                                      "--json", "OUT/out.json"], prog="masv"),
    C("masv missing", lambda t: ["modes", str(t / "nope.toml")], prog="masv"),
    C("masv --freq-hz 0", lambda t: ["freqresp", str(MODELS / "masv" / "core_stage.toml"), "--freq-hz", "0",
                                     "--json", "OUT/out.json"], prog="masv"),
    C("masv --factor 0.5", lambda t: ["modes", str(MODELS / "masv" / "core_stage.toml"), "--factor", "0.5",
                                      "--json", "OUT/out.json"], prog="masv"),
    # output places ------------------------------------------------------------------------------
    C("simulate --out is a folder", lambda t: ["simulate", str(AMBIENT), "--profile", str(PROFILE), "--out", str(t)]),
    C("simulate --out under a file", lambda t: ["simulate", str(AMBIENT), "--profile", str(PROFILE),
                                                "--out", str(write(t, "f.txt", "x") / "run.h5")]),
    C("greenrun --out is a file", lambda t: ["greenrun", str(AMBIENT), "--quiet", "--out", str(write(t, "notes.txt", "mine"))]),
    C("greenrun --out foreign index.html", lambda t: ["greenrun", str(AMBIENT), "--quiet", "--out",
                                                      str(write(t, "index.html", "mine").parent)]),
    C("info --json into a folder", lambda t: ["info", str(AMBIENT), "--json", str(t)]),
    C("info --json under a file", lambda t: ["info", str(AMBIENT), "--json", str(write(t, "f.txt", "x") / "a.json")]),
    C("view --html is a folder", lambda t: ["view", str(t / "run.h5"), "--html", str(t)]),
    C("compare --out is a file", lambda t: ["compare", str(AMBIENT), str(AMBIENT), "--out", str(write(t, "f.txt", "x"))]),
    C("freqresp --plot wrong suffix", lambda t: fr("--freq-hz", "1", "--linear", "--plot", "OUT/out.txt")),
    C("freqresp --json into a folder", lambda t: ["freqresp", str(AMBIENT), "--freq-hz", "1", "--linear", "--json", str(t)]),
]


def test_case_count():
    assert len({c.name for c in CASES}) == len(CASES)
    assert len(CASES) >= 60


def _main(prog):
    if prog == "masv":
        from masv.cli import main
    else:
        from taos.cli import main
    return main


def snapshot(folder: Path) -> dict:
    return {p.relative_to(folder): p.read_bytes() if p.is_file() else None for p in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_one_line_exit_2(case: Case, tmp_path, capsys, monkeypatch):
    work = tmp_path / "in"
    work.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    argv = [str(a).replace("OUT", str(out)) for a in case.build(work)]
    before = snapshot(work)
    monkeypatch.chdir(tmp_path)
    rc = _main(case.prog)(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2, (rc, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for s in case.expect_in_line:
        assert s in lines[0], lines[0]
    assert list(out.iterdir()) == [], "an output was written"
    assert snapshot(work) == before, "an input folder was changed"
