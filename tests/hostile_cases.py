"""The table of hostile inputs of issue 25 ("Nothing a user owns is ever replaced, and every
absurd input is refused"), grouped by the contract each group checks (docs/reference/bounds.md,
"The hostile-input suite"). ``tests/test_hostile.py`` runs them.

A case is ``build(work) -> argv``: it writes whatever hostile file it needs into the folder
``work`` (the user's folder) and returns the command line. The runner checks the exit status,
that standard error is one line naming ``expect`` (the field or option), and that no file of
the user's changed (content hash before and after), except those a case names in ``changes``.
"""

from __future__ import annotations

import copy
import functools
import math
import os
import socket
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from taos.bounds import FLIGHT_BOUNDS, MODEL_BOUNDS
from taos.errors import MAX_DATA_BYTES, MAX_TOML_BYTES

from .test_bad_inputs import DATA, model_text, set_cell
from .test_bad_inputs import _first_data_row as _first_row

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"
AMBIENT = MODELS / "rs25_ambient.toml"
PROFILE = MODELS / "profiles" / "step_pitch.toml"
FLIGHT = MODELS / "flight" / "core_stage.toml"
MASV = MODELS / "masv" / "core_stage.toml"
ASCENT = MODELS / "flight" / "ascent.toml"


@dataclass(frozen=True)
class Case:
    """One hostile input: ``group`` the contract, ``build(work) -> argv``, the expected exit
    status ``rc``, strings ``expect`` the one line must hold, files ``changes`` allowed to change."""

    group: str
    name: str
    build: Callable[[Path], list]
    rc: int = 2
    expect: tuple[str, ...] = ()
    prog: str = "taos"
    changes: tuple[str, ...] = field(default=())


# -- file makers --------------------------------------------------------------------------------

def write(work: Path, name: str, content: str | bytes) -> Path:
    p = work / name
    p.write_bytes(content if isinstance(content, bytes) else content.encode())
    return p


@functools.cache
def parsed_toml(text: str):
    """``text`` parsed by tomlkit once (pure-Python parsing is most of a case's cost); callers
    edit a deep copy."""
    import tomlkit

    return tomlkit.parse(text)


def edited_toml(text: str, edit: Callable | None) -> str:
    """``text`` (TOML) edited through tomlkit: a fresh copy of the parsed document per call."""
    import tomlkit

    doc = copy.deepcopy(parsed_toml(text))
    if edit is not None:
        edit(doc)
    return tomlkit.dumps(doc)


_model_text = functools.cache(model_text)   # the shipped files it reads are checked unchanged by every case


def model_copy(work: Path, name: str = "m.toml", edit: Callable | None = None) -> Path:
    """The ambient model (actuator set inlined, stiffness file absolute), edited through tomlkit."""
    return write(work, name, edited_toml(_model_text(), edit))


def flight_copy(work: Path, edit: Callable) -> Path:
    """The shipped flight file (its TVC model path made absolute), edited through tomlkit."""
    text = FLIGHT.read_text().replace('"../rs25_flight.toml"', f'"{MODELS}/rs25_flight.toml"')
    return write(work, "f.toml", edited_toml(text, edit))


def setting(section: str, key: str, value) -> Callable:
    def edit(doc):
        doc[section][key] = value
    return edit


def fifo(work: Path, name: str) -> Path:
    p = work / name
    os.mkfifo(p)
    return p


def sock(work: Path, name: str) -> Path:
    p = work / name
    s = socket.socket(socket.AF_UNIX)
    s.bind(str(p))
    s.close()
    return p


def sparse(work: Path, name: str, size: int) -> Path:
    p = work / name
    with open(p, "wb") as f:
        f.truncate(size)
    return p


def folder(work: Path, name: str) -> Path:
    p = work / name
    p.mkdir()
    return p


def csv_with(work: Path, edit: Callable[[list[str]], list[str]], name: str = "d.csv") -> Path:
    lines = DATA.read_text().splitlines()[:3000]
    return write(work, name, "\n".join(edit(lines)) + "\n")


# -- 1. outputs never replace what the user owns --------------------------------------------------

def _out_commands():
    """(label, argv with OUT, option name, suffix of the output)."""
    return [
        ("info --json", lambda w: ["info", AMBIENT, "--json", "OUT"], "--json", ".json"),
        ("freqresp --json", lambda w: ["freqresp", AMBIENT, "--freq-hz", "1", "--linear", "--json", "OUT"], "--json", ".json"),
        ("freqresp --plot", lambda w: ["freqresp", AMBIENT, "--freq-hz", "1", "--linear", "--plot", "OUT"], "--plot", ".png"),
        ("simulate --out", lambda w: ["simulate", AMBIENT, "--profile", PROFILE, "--out", "OUT"], "--out", ".h5"),
        ("estimate --json", lambda w: ["estimate", DATA, "--json", "OUT"], "--json", ".json"),
        ("lco --json", lambda w: ["lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--no-time-domain",
                                  "--json", "OUT"], "--json", ".json"),
        ("lco --df-out", lambda w: ["lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--no-time-domain",
                                    "--df-out", "OUT"], "--df-out", ".h5"),
        ("view --html", lambda w: ["view", w / "none.h5", "--html", "OUT"], "--html", ".html"),
        ("fit --out-model", lambda w: ["fit", DATA, "--model", AMBIENT, "--free", "load_stiffness",
                                       "--out-model", "OUT"], "--out-model", ".toml"),
        ("export --out", lambda w: ["export", AMBIENT, "--out", "OUT", "--format", "mat"], "--out", ".mat"),
        ("masv modes --json", lambda w: ["modes", MASV, "--json", "OUT"], "--json", ".json"),
    ]


def _targets():
    """(label, make(work, suffix) -> output path, expected words)."""
    def user(w, sfx):
        return write(w, "user" + sfx, "the user's own file\n")

    def link_to_user(w, sfx):
        t = write(w, "target" + sfx, "the user's file behind a link\n")
        (w / ("link" + sfx)).symlink_to(t)
        return w / ("link" + sfx)

    def hardlink(w, sfx):
        t = write(w, "hard" + sfx, "a file with two names\n")
        os.link(t, w / ("hard2" + sfx))
        return w / ("hard2" + sfx)

    def long_name(w, sfx):
        return w / ("n" * 300 + sfx)

    def under_file(w, sfx):
        return write(w, "plain.txt", "x") / ("out" + sfx)

    return [
        ("an existing user file", user, ("did not write",)),
        ("a link to a user file", link_to_user, ("did not write",)),
        ("a second name of a user file", hardlink, ("did not write",)),
        ("a FIFO", lambda w, sfx: fifo(w, "fifo" + sfx), ("FIFO",)),
        ("a socket", lambda w, sfx: sock(w, "sock" + sfx), ("socket",)),
        ("an existing folder", lambda w, sfx: folder(w, "dir" + sfx), ("folder",)),
        ("a 300-character name", long_name, ("bytes",)),
        ("a path under a regular file", under_file, ("regular file",)),
    ]


def _output_cases():
    cases = []
    for cmd, argv, opt, sfx in _out_commands():
        prog = "masv" if cmd.startswith("masv") else "taos"
        for tname, make, words in _targets():
            def build(w, argv=argv, make=make, sfx=sfx):
                out = make(w, sfx)
                return [out if a == "OUT" else a for a in argv(w)]
            cases.append(Case("outputs", f"{cmd} into {tname}", build, expect=(opt, *words), prog=prog))
    # an output that is an input of the run (the data-loss cases)
    inputs = [
        ("info --json the model", lambda w: ["info", (m := model_copy(w)), "--json", m]),
        ("simulate --out the profile", lambda w: ["simulate", AMBIENT, "--profile",
                                                  (p := write(w, "p.toml", PROFILE.read_text())), "--out", p]),
        ("freqresp --json the model", lambda w: ["freqresp", (m := model_copy(w)), "--freq-hz", "1", "--json", m]),
        ("estimate --json the data", lambda w: ["estimate", (d := write(w, "d.csv", DATA.read_bytes())), "--json", d]),
        ("lco --json the flight file", lambda w: ["lco", MODELS / "rs25_flight.toml", "--flight",
                                                  (f := write(w, "f.toml", FLIGHT.read_text()
                                                              .replace('"../rs25_flight.toml"',
                                                                       f'"{MODELS}/rs25_flight.toml"'))),
                                                  "--json", f]),
        ("info --json a link to the model", lambda w: ["info", (m := model_copy(w)), "--json",
                                                       _symlink(w / "l.json", m)]),
        ("info --json a hard link to the model", lambda w: ["info", (m := model_copy(w)), "--json",
                                                            _hardlink(w / "h.json", m)]),
        ("info --json the model with --force", lambda w: ["info", (m := model_copy(w)), "--json", m, "--force"]),
        ("simulate --out the model", lambda w: ["simulate", (m := model_copy(w)), "--profile", PROFILE, "--out", m]),
        ("export --out the model", lambda w: ["export", (m := model_copy(w)), "--out", m]),
        ("masv --json the configuration", lambda w: ["modes", (c := write(w, "c.toml", MASV.read_text().replace(
            '"../../fem_data/', f'"{ROOT}/fem_data/').replace('"../rs25_hotfire.toml"', f'"{MODELS}/rs25_hotfire.toml"'))),
            "--json", c]),
    ]
    for name, build in inputs:
        cases.append(Case("outputs", name, build, expect=("input",), prog="masv" if "masv" in name else "taos"))
    # what is allowed: /dev/null discards, --force replaces a user file, a rerun replaces its own
    cases += [
        Case("outputs", "info --json /dev/null discards", lambda w: ["info", AMBIENT, "--json", os.devnull], rc=0),
        Case("outputs", "freqresp --json /dev/null discards",
             lambda w: ["freqresp", AMBIENT, "--freq-hz", "1", "--linear", "--json", os.devnull], rc=0),
        Case("outputs", "freqresp --plot /dev/null: no format to make, refused",   # the suffix chooses PNG or SVG
             lambda w: ["freqresp", AMBIENT, "--freq-hz", "1", "--linear", "--plot", os.devnull], expect=(".png",)),
        Case("outputs", "simulate --out /dev/null discards",
             lambda w: ["simulate", AMBIENT, "--profile", PROFILE, "--out", os.devnull], rc=0),
        Case("outputs", "a rerun replaces its own output",
             lambda w: [write(w, ".taos-output.json", '{"written_by": "taos", "files": ["mine.json"]}') and
                        write(w, "mine.json", "old") and "info", AMBIENT, "--json", w / "mine.json"], rc=0,
             changes=("mine.json", ".taos-output.json")),
        Case("outputs", "info --json over a user file with --force",
             lambda w: ["info", AMBIENT, "--json", write(w, "user.json", "mine"), "--force"], rc=0,
             changes=("user.json", ".taos-output.json")),
        Case("outputs", "a user file shaped like a temporary survives a run",
             lambda w: [write(w, f".out.json.1.{'ab' * 16}.taos.tmp", "mine") and "info", AMBIENT, "--json",
                        w / "out.json"], rc=0, changes=("out.json", ".taos-output.json")),
        Case("outputs", "a foreign .taos-output.json is not taken for the mark",
             lambda w: [write(w, ".taos-output.json", "user notes") and "info", AMBIENT, "--json",
                        w / "out.json"], expect=(".taos-output.json",)),
        Case("outputs", "compare --out holding a user file of an output's name",
             lambda w: [write(folder(w, "cmp"), "table.txt", "mine") and "compare", AMBIENT, AMBIENT, "--out",
                        w / "cmp"], expect=("--out", "did not write")),
        Case("outputs", "greenrun --out holding a user index.html",
             lambda w: [write(folder(w, "rep"), "index.html", "mine") and "greenrun", AMBIENT, "--out", w / "rep"],
             expect=("did not write",)),
        Case("outputs", "empty --json", lambda w: ["info", AMBIENT, "--json", ""], expect=("--json",)),
        Case("outputs", "blank --out", lambda w: ["simulate", AMBIENT, "--profile", PROFILE, "--out", "  "],
             expect=("--out",)),
    ]
    return cases


def _symlink(link: Path, target: Path) -> Path:
    link.symlink_to(target)
    return link


def _hardlink(link: Path, target: Path) -> Path:
    os.link(target, link)
    return link


# -- 2. physical bounds of every model value, and the cross-field checks --------------------------

_KEY_UNIT = {"rad": "deg", "1": None}


def _text(si: float, unit: str) -> str | float:
    """A model-file value of ``si`` (SI) in ``unit`` (angles in deg; a plain number for '1')."""
    if unit == "1":
        return si
    if unit == "rad/rad":
        return f"{si:.6g} deg/deg"
    if unit == "rad":
        return f"{math.degrees(si):.6g} deg"
    return f"{si:.6g} {unit}"


def _bound_cases():
    cases = []
    for fld, (lo, hi, unit, _why) in MODEL_BOUNDS.items():
        sec, key = fld.split(".")
        below = lo / 100 if lo > 0 else -1.0 if unit != "rad" else -0.01
        for label, v in (("below", below), ("above", hi * 100 if hi > 0 else 1.0)):
            cases.append(Case("bounds", f"{fld} {label} its bound", lambda w, s=sec, k=key, v=v, u=unit: [
                "info", model_copy(w, edit=setting(s, k, _text(v, u)))], expect=(fld,)))

    for fld, (lo, hi, unit, _why) in FLIGHT_BOUNDS.items():
        sec, key = fld.split(".")
        below = lo / 100 if lo > 0 else -1.0
        for label, v in (("below", below), ("above", hi * 100)):
            cases.append(Case("bounds", f"flight {fld} {label} its bound", lambda w, s=sec, k=key, v=v, u=unit: [
                "lco", MODELS / "rs25_flight.toml", "--flight", flight_copy(w, setting(s, k, _text(v, u))),
                "--no-time-domain"], expect=(fld,)))
    cases.append(Case("bounds", "flight with 1000 engines", lambda w: [
        "lco", MODELS / "rs25_flight.toml", "--flight", flight_copy(w, setting("vehicle", "engine_count", 1000)),
        "--no-time-domain"], expect=("vehicle.engine_count",)))

    def no_geometry(doc):
        del doc["geometry"]
        del doc["gimbal"]
        doc["actuator"]["moment_arm"] = "1.2 m"
        doc["engine"]["gimbal_range"] = "25 deg"

    cases += [
        Case("bounds", "static torque below the Coulomb torque", lambda w: [
            "info", model_copy(w, edit=setting("friction", "static_torque", "1000 in*lbf"))],
            expect=("friction.static_torque", "Coulomb")),
        Case("bounds", "hard stops outside the actuator stroke", lambda w: ["info", model_copy(w, edit=no_geometry)],
             expect=("engine.gimbal_range", "stroke")),
        Case("bounds", "moment arm against the geometry", lambda w: [
            "info", model_copy(w, edit=setting("actuator", "moment_arm", "1.0 m"))], expect=("actuator.moment_arm", "geometry")),
        Case("bounds", "the issue's 1e-300 lbf/in", lambda w: [
            "info", model_copy(w, edit=setting("structure", "load_stiffness", "1e-300 lbf/in"))],
            expect=("structure.load_stiffness",)),
        Case("bounds", "the issue's 400 deg gimbal range", lambda w: [
            "info", model_copy(w, edit=setting("engine", "gimbal_range", "400 deg"))], expect=("engine.gimbal_range",)),
        Case("bounds", "the issue's 1000 m moment arm", lambda w: [
            "info", model_copy(w, edit=setting("actuator", "moment_arm", "1000 m"))], expect=("actuator.moment_arm",)),
        Case("bounds", "relief pressure below the supply", lambda w: [
            "info", model_copy(w, edit=setting("actuator", "relief_pressure", "100 psi"))],
            expect=("actuator.relief_pressure",)),
        Case("bounds", "a profile step beyond the gimbal range", lambda w: [
            "simulate", AMBIENT, "--profile", write(w, "p.toml", 'type = "step"\namplitude = "40 deg"\n'),
            "--out", w / "o.h5"], expect=("amplitude",)),
        Case("bounds", "a profile frequency of 1 MHz", lambda w: [
            "simulate", AMBIENT, "--profile", write(w, "p.toml", 'type = "sine_dwell"\namplitude = "0.4 deg"\n'
                                                   'frequency = "1 MHz"\ncycles = 2\n'), "--out", w / "o.h5"],
            expect=("frequency",)),
        Case("bounds", "a profile of a billion cycles", lambda w: [
            "simulate", AMBIENT, "--profile", write(w, "p.toml", 'type = "sine_dwell"\namplitude = "0.4 deg"\n'
                                                   'frequency = "1 Hz"\ncycles = 1000000000\n'), "--out", w / "o.h5"],
            expect=("cycles",)),
    ]
    return cases


# -- 3. unit text is parsed, never evaluated --------------------------------------------------------

HOSTILE_UNITS = [
    "9**9**9 lbf/in", "9**9**9**9 N/m", "1 lbf/in**9**9", "(9**9)**9 N/m", "1e999 lbf/in", "-1e999 lbf/in",
    "nan lbf/in", "inf N/m", "1 lbf/in" + " " * 100, "1" * 100 + " N/m", "0x1F N/m", "1_000 N/m",
    "__import__('os') N/m", "1 N/m; rm -rf /", "1 N/m # c", "", "   ", "lbf/in", "1 2 N/m", "1 N//m",
    "1 N/m/", "1 */m", "1 N^^2/m", "1 N**999/m", "1 N**-99999/m", "1 (N/m)", "1 ((((((N))))))/m",
    "1 N\u00b7m", "1 N\x00/m", "1\N{FULLWIDTH DIGIT ONE} N/m", "1 " + "m*" * 40 + "m", "1 s",
    "1 deg", "1e-400 N/m", "1e5000 N/m", "+ N/m",
]


def _unit_cases():
    cases = []
    for fld in ("structure.load_stiffness", "engine.mass"):
        sec, key = fld.split(".")
        for i, text in enumerate(HOSTILE_UNITS):
            cases.append(Case("units", f"{fld} = {text[:24]!r} #{i}", lambda w, s=sec, k=key, t=text: [
                "info", model_copy(w, edit=setting(s, k, t))], expect=(fld,)))
    for opt, argv in (("--load-stiffness", lambda v: ["lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT,
                                                      "--no-time-domain", "--load-stiffness", v]),):
        for i, text in enumerate(HOSTILE_UNITS[:12]):
            cases.append(Case("units", f"{opt} {text[:24]!r} #{i}", lambda w, a=argv, t=text: a(t), expect=(opt,)))
    return cases


# -- 4. inputs: regular files only, bounded in size and depth -------------------------------------

def _hostile_files():
    """(label, make(work, name) -> path, expected words)."""
    deep_arrays = "x = " + "[" * 3000 + "]" * 3000 + "\n"
    deep_tables = "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n"
    deep_headers = "[" + ".".join(["a"] * 40) + "]\nb = 1\n"
    return [
        ("a missing file", lambda w, n: w / n, ()),
        ("a folder", lambda w, n: folder(w, n), ("folder",)),
        ("a FIFO", lambda w, n: fifo(w, n), ("FIFO",)),
        ("a socket", lambda w, n: sock(w, n), ("socket",)),
        ("/dev/zero", lambda w, n: Path("/dev/zero"), ("regular file",)),
        ("/dev/null", lambda w, n: Path(os.devnull), ("regular file",)),
        ("a file beyond the size cap", lambda w, n: sparse(w, n, (MAX_DATA_BYTES if n.endswith(".csv")
                                                                 else MAX_TOML_BYTES) + 1), ("bytes",)),
        ("binary junk", lambda w, n: write(w, n, bytes(range(256)) * 4), ()),
        ("arrays nested 3000 deep", lambda w, n: write(w, n, deep_arrays), ()),
        ("inline tables nested 3000 deep", lambda w, n: write(w, n, deep_tables), ()),
        ("table headers nested 40 deep", lambda w, n: write(w, n, deep_headers), ()),
        ("an empty file", lambda w, n: write(w, n, ""), ()),
        ("NUL bytes", lambda w, n: write(w, n, b"name = \"a\x00b\"\n"), ()),
    ]


def _file_cases():
    loaders = [
        ("model", lambda p, w: ["info", p]),
        ("profile", lambda p, w: ["simulate", AMBIENT, "--profile", p, "--out", w / "o.h5"]),
        ("flight", lambda p, w: ["lco", MODELS / "rs25_flight.toml", "--flight", p, "--no-time-domain"]),
        ("ascent", lambda p, w: ["ascent", p, "--out", w / "asc"]),
        ("masv", lambda p, w: ["modes", p]),
        ("friction parameter set", lambda p, w: ["info", model_copy(w, edit=setting("friction", "parameter_set",
                                                                                     str(p)))]),
        ("data record", lambda p, w: ["estimate", p]),
    ]
    cases = []
    for kind, argv in loaders:
        sfx = ".csv" if kind == "data record" else ".toml"
        for label, make, words in _hostile_files():
            if kind == "data record" and "nested" in label:
                continue
            cases.append(Case("files", f"{kind} is {label}", lambda w, a=argv, m=make, s=sfx: a(m(w, "in" + s), w),
                              expect=words, prog="masv" if kind == "masv" else "taos"))
    secret = "SECRET-LINE-42 of a user's private notes"
    cases += [
        Case("files", "stiffness_file naming a foreign text file echoes none of it", lambda w: [
            "freqresp", model_copy(w, edit=setting("gimbal", "stiffness_file", str(write(w, "notes.csv", secret + "\n")))),
            "--freq-hz", "1", "--engine", "taos"], expect=("notes.csv",)),
        Case("files", "stiffness_file naming a FIFO", lambda w: [
            "info", model_copy(w, edit=setting("gimbal", "stiffness_file", str(fifo(w, "k.npz"))))],
            expect=("gimbal.stiffness_file", "FIFO")),
        Case("files", "stiffness_file naming /dev/zero", lambda w: [
            "info", model_copy(w, edit=setting("gimbal", "stiffness_file", "/dev/zero"))],
            expect=("gimbal.stiffness_file",)),
        Case("files", "sidecar TOML is a FIFO", lambda w: [
            "estimate", write(w, "s.csv", "t,c,x\n" + "".join(f"{i / 100},0,0\n" for i in range(64))),
        ] if fifo(w, "s.toml") else [], expect=("s.toml", "FIFO")),
    ]
    return cases


# -- 5. data records: sample rate, columns, time, magnitudes --------------------------------------

def _header(fn):
    def edit(lines):
        k = _first_row(lines) - 1
        lines[k] = ",".join(fn(lines[k].split(",")))
        return lines
    return edit


def _times(scale: float):
    def edit(lines):
        k0 = _first_row(lines)
        for k in range(k0, len(lines)):
            cells = lines[k].split(",")
            cells[0] = repr(float(cells[0]) * scale)
            lines[k] = ",".join(cells)
        return lines
    return edit


DATA_EDITS = [
    ("a duplicated column name", _header(lambda h: h[:2] + [h[1]] + h[3:]), ("pitch_command",)),
    ("an empty column name", _header(lambda h: h[:2] + [""] + h[3:]), ("header",)),
    ("no time column", _header(lambda h: ["clock [s]"] + h[1:]), ("time",)),
    ("no pitch piston column", _header(lambda h: [x.replace("pitch_piston", "pitch_pistn") for x in h]),
     ("pitch_piston",)),
    ("time going backwards", set_cell(50, 0, "0.0"), ("time",)),
    ("a repeated time stamp", lambda ls: set_cell(51, 0, ls[_first_row(ls) + 50].split(",")[0])(ls), ("time",)),
    ("a 1e12 Hz sample rate (ps read as s)", _times(1e-9), ("sample rate",)),
    ("a 0.01 Hz sample rate", _times(1e4), ("sample rate",)),
    ("a command of 100 deg", set_cell(10, 1, "100"), ("pitch_command",)),
    ("a piston at 5 m", lambda ls: set_cell(10, next(i for i, h in enumerate(ls[_first_row(ls) - 1].split(","))
                                                if "pitch_piston" in h), "200")(ls), ("pitch_piston",)),
    ("a NaN cell", set_cell(10, 1, "nan"), ("finite",)),
    ("an inf cell", set_cell(10, 1, "inf"), ("finite",)),
    ("a text cell", set_cell(10, 1, "abc"), ("rows",)),
    ("a short row", lambda ls: ls[:_first_row(ls) + 5] + [ls[_first_row(ls) + 5].rsplit(",", 1)[0]] + ls[_first_row(ls) + 6:],
     ("rows",)),
    ("a power tower unit", _header(lambda h: [x.replace("[deg]", "[9**9**9 deg]") for x in h]), ("command",)),
    ("an unknown unit", _header(lambda h: [x.replace("[deg]", "[furlong]") for x in h]), ("command",)),
    ("a length unit for an angle", _header(lambda h: [x.replace("[deg]", "[in]") for x in h]), ("command",)),
    ("a 300-character unit", _header(lambda h: [x.replace("[deg]", "[" + "deg*" * 75 + "deg]") for x in h]),
     ("command",)),
    ("only the header", lambda ls: ls[:_first_row(ls)], ("time",)),
    ("nested metadata", lambda ls: ["# x = " + "[" * 2000 + "]" * 2000] + ls, ("nested",)),
    ("bad metadata", lambda ls: ["# condition = "] + ls, ("TOML",)),
    ("a metadata key typo", lambda ls: ["# conditon = \"hot\""] + ls, ("conditon",)),
    ("engine angles for one axis only", _header(lambda h: [x.replace("yaw_engine", "yaw_engin") for x in h]),
     ("yaw_engine",)),
]


def _data_cases():
    cases = []
    for label, edit, words in DATA_EDITS:
        cases.append(Case("data", f"estimate: {label}", lambda w, e=edit: ["estimate", csv_with(w, e)], expect=words))
        cases.append(Case("data", f"simulate replay: {label}", lambda w, e=edit: [
            "simulate", AMBIENT, "--profile", csv_with(w, e), "--out", w / "o.h5"], expect=words))
    return cases


# -- 6. conflicting or empty flags --------------------------------------------------------------------

def _fr(*more):
    return lambda w: ["freqresp", AMBIENT, *more]


def _lco(*more):
    return lambda w: ["lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, *more]


FLAG_CASES = [
    ("--linear with --amplitude-deg", _fr("--freq-hz", "1", "--linear", "--amplitude-deg", "0.4"), "--amplitude-deg"),
    ("--linear with --steady", _fr("--freq-hz", "1", "--linear", "--steady", "shoot"), "--steady"),
    ("--steady without --amplitude-deg", _fr("--freq-hz", "1", "--steady", "settle"), "--steady"),
    ("--cross with the planar engine", _fr("--freq-hz", "1", "--cross"), "--cross"),
    ("empty --freq-hz", _fr("--freq-hz", ""), "--freq-hz"),
    ("blank --freq-hz", _fr("--freq-hz", "  "), "--freq-hz"),
    ("double comma in --freq-hz", _fr("--freq-hz", "1,,2"), "--freq-hz"),
    ("trailing comma in --freq-hz", _fr("--freq-hz", "1,2,"), "--freq-hz"),
    ("leading comma in --freq-hz", _fr("--freq-hz", ",1"), "--freq-hz"),
    ("a lone comma in --freq-hz", _fr("--freq-hz", ","), "--freq-hz"),
    ("negative frequency", _fr("--freq-hz", "1,-2"), "--freq-hz"),
    ("zero frequency", _fr("--freq-hz", "0"), "--freq-hz"),
    ("nan frequency", _fr("--freq-hz", "nan"), "--freq-hz"),
    ("1e300 Hz", _fr("--freq-hz", "1e300"), "--freq-hz"),
    ("empty --amplitude-deg", _fr("--freq-hz", "1", "--amplitude-deg", ""), "--amplitude-deg"),
    ("double comma in --amplitude-deg", _fr("--freq-hz", "1", "--amplitude-deg", "0.1,,0.2"), "--amplitude-deg"),
    ("zero amplitude", _fr("--freq-hz", "1", "--amplitude-deg", "0"), "--amplitude-deg"),
    ("negative amplitude", _fr("--freq-hz", "1", "--amplitude-deg", "-0.4"), "--amplitude-deg"),
    ("amplitude beyond the gimbal", _fr("--freq-hz", "1", "--amplitude-deg", "40"), "--amplitude-deg"),
    ("--plot-map without --sweep", _lco("--no-time-domain", "--plot-map", "map.png"), "--plot-map"),
    ("--plot with --sweep", _lco("--sweep", "load_stiffness=2e7,3e7", "--plot", "n.png"), "--plot"),
    ("--df-out with --sweep", _lco("--sweep", "load_stiffness=2e7,3e7", "--df-out", "d.h5"), "--df-out"),
    ("--plot-time with --no-time-domain", _lco("--no-time-domain", "--plot-time", "t.png"), "--plot-time"),
    ("three --sweep", _lco(*["--sweep", "load_stiffness=2e7,3e7"] * 3), "--sweep"),
    ("one amplitude in the grid", _lco("--no-time-domain", "--amplitudes-deg", "0.1"), "--amplitudes-deg"),
    ("empty --amplitudes-deg list item", _lco("--no-time-domain", "--amplitudes-deg", "0.1,,1"), "--amplitudes-deg"),
    ("infinite --duration", _lco("--duration", "inf"), "--duration"),
    ("negative --duration", _lco("--duration", "-5"), "--duration"),
    ("empty --free", lambda w: ["fit", DATA, "--model", AMBIENT, "--free", ""], "--free"),
    ("double comma in --free", lambda w: ["fit", DATA, "--model", AMBIENT, "--free", "load_stiffness,,coulomb_torque"],
     "--free"),
    ("--starts 0", lambda w: ["fit", DATA, "--model", AMBIENT, "--free", "load_stiffness", "--starts", "0"], "--starts"),
    ("--min-coherence 2", lambda w: ["fit", DATA, "--model", AMBIENT, "--free", "load_stiffness",
                                     "--min-coherence", "2"], "--min-coherence"),
    ("an empty --labels item", lambda w: ["compare", AMBIENT, AMBIENT, "--out", w / "c", "--labels", "a,"], "--labels"),
    ("--paused-at without --html", lambda w: ["view", w / "r.h5", "--paused-at", "1"], "--paused-at"),
    ("--nperseg with --method dwell", lambda w: ["estimate", DATA, "--method", "dwell", "--nperseg", "64"], "--nperseg"),
    ("--nperseg 3", lambda w: ["estimate", DATA, "--nperseg", "3"], "--nperseg"),
    ("ascent --seed -1", lambda w: ["ascent", ASCENT, "--out", w / "a", "--seed", "-1"], "--seed"),
    ("ascent --seed 2**32", lambda w: ["ascent", ASCENT, "--out", w / "a", "--seed", str(2 ** 32)], "--seed"),
    ("ascent --dt 1", lambda w: ["ascent", ASCENT, "--out", w / "a", "--dt", "1"], "--dt"),
    ("simulate --dt nan", lambda w: ["simulate", AMBIENT, "--profile", PROFILE, "--out", w / "o.h5", "--dt", "nan"],
     "dt"),
    ("simulate --dt -1", lambda w: ["simulate", AMBIENT, "--profile", PROFILE, "--out", w / "o.h5", "--dt", "-1"],
     "dt"),
    ("--plot with a .txt name", _fr("--freq-hz", "1", "--linear", "--plot", "p.txt"), "--plot"),
    ("view --html with a .png name", lambda w: ["view", w / "r.h5", "--html", w / "v.png"], "--html"),
    ("an unknown --friction", lambda w: ["info", AMBIENT, "--friction", "sticky"], "sticky"),
    ("--axis roll", _fr("--freq-hz", "1", "--axis", "roll"), "--axis"),
    ("ascent --friction with a double comma", lambda w: ["ascent", ASCENT, "--out", w / "a", "--friction",
                                                         "dahl,,lugre"], "--friction"),
    ("ascent --friction with a trailing comma", lambda w: ["ascent", ASCENT, "--out", w / "a", "--friction", "dahl,"],
     "--friction"),
    ("ascent --friction a lone comma", lambda w: ["ascent", ASCENT, "--out", w / "a", "--friction", ","], "--friction"),
    ("empty ascent --friction", lambda w: ["ascent", ASCENT, "--out", w / "a", "--friction", ""], "--friction"),
]


def _flag_cases():
    return [Case("flags", name, build, expect=(opt,)) for name, build, opt in FLAG_CASES] + [
        Case("flags", "masv double comma in --freq-hz", lambda w: ["freqresp", MASV, "--freq-hz", "1,,2"],
             expect=("--freq-hz",), prog="masv"),
    ]


from .hostile_file_bounds import file_bound_cases  # noqa: E402 - it uses the helpers above

CASES: list[Case] = (_output_cases() + _bound_cases() + file_bound_cases() + _unit_cases() + _file_cases()
                     + _data_cases() + _flag_cases())
