"""An FMI 2.0 co-simulation FMU of :class:`~taos.cosim.TvcBlock`, built with ``pythonfmu`` (``taos fmu
--python``; the default ``taos fmu`` builds the standalone C FMU, :mod:`taos.cosim._standalone`).

What the FMU holds (``resources/``): a two-line entry script whose class is
:class:`taos.cosim._slave.TvcSlave`, ``taos_fmu/config.json`` (engine, friction law, avionics,
internal step, the model's SHA-256) and ``taos_fmu/model/``, a copy of the model file and every
shared file it names (parameter sets, the 3-D stiffness file) in their relative layout. At run
time the FMU's binary (pythonfmu's, linux64 and win64) embeds the Python it finds, which must
import ``taos``: the slave loads the model copy, checks that its combined SHA-256 is the one the
FMU was built from, and runs the block.

Variables (names and units, FMI ``UnitDefinitions`` from the SI suffix of each name, :data:`UNITS`):

* inputs ``pitch_command_rad``, ``yaw_command_rad`` (the FCS engine-angle commands, before the
  avionics);
* outputs: every signal of :class:`~taos.cosim.BlockOutputs` (engine angles and rates, pistons,
  load forces and pressures, friction torques, commands after the avionics, thrust direction);
* parameters (``fixed``: set before initialisation, the block is built from them when
  initialisation ends, with every check of the model file's values): the model's
  ``engine.*``, ``actuator.*`` and ``structure.*`` values with their SI units, the internal
  step ``internal_step_s`` and ``command_hold`` (0 hold, 1 ramp; :data:`taos.cosim.HOLDS`). The
  friction law and the avionics are the build's (``taos fmu --friction/--avionics``).

The build validates the model exactly as every command does (the block is constructed, with
all its checks, before anything is written) and writes the FMU atomically
(:func:`taos.results.atomic_write`): a refused model leaves no file.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..model import TvcModel, load_model
from ..results import atomic_write, base_provenance, check_output_file

from ._options import AVIONICS

#: the FMU's model identifier (its binary's and entry script's name)
MODEL_IDENTIFIER = "TaosTvc"
CONFIG = "config.json"
RESOURCE_DIR = "taos_fmu"
#: the model sections whose values are FMU parameters
PARAMETER_SECTIONS = ("engine", "actuator", "structure")

#: FMI unit name -> SI base-unit exponents (FMI 2.0 BaseUnit attributes)
UNITS = {
    "kg": {"kg": 1}, "kg.m2": {"kg": 1, "m": 2}, "N.m/rad": {"kg": 1, "m": 2, "s": -2, "rad": -1},
    "N": {"kg": 1, "m": 1, "s": -2}, "N.m": {"kg": 1, "m": 2, "s": -2}, "rad": {"rad": 1},
    "rad/s": {"rad": 1, "s": -1}, "m": {"m": 1}, "m2": {"m": 2}, "m3": {"m": 3},
    "Pa": {"kg": 1, "m": -1, "s": -2}, "N.s/m": {"kg": 1, "s": -1}, "N/m": {"kg": 1, "s": -2},
    "1/s": {"s": -1}, "Hz": {"s": -1}, "s": {"s": 1}, "m/s": {"m": 1, "s": -1},
    "m3/(s.Pa)": {"kg": -1, "m": 4, "s": 1}, "m/(s.Pa)": {"kg": -1, "m": 2, "s": 1},
}
#: SI suffix of a taos field name -> its FMI unit (None: dimensionless); the first match wins
SUFFIXES = (("_m3_per_s_Pa", "m3/(s.Pa)"), ("_m_per_s_Pa", "m/(s.Pa)"), ("_Nm_per_rad", "N.m/rad"),
            ("_Ns_per_m", "N.s/m"), ("_N_per_m", "N/m"), ("_m_per_s", "m/s"), ("_rad_s", "rad/s"),
            ("_per_s", "1/s"), ("_kgm2", "kg.m2"), ("_m2", "m2"), ("_m3", "m3"), ("_Pa", "Pa"), ("_Nm", "N.m"),
            ("_kg", "kg"), ("_rad", "rad"), ("_hz", "Hz"), ("_N", "N"), ("_m", "m"), ("_s", "s"),
            ("_ratio", None), ("_order", None), ("_limited", None), ("_x", None), ("_y", None), ("_z", None))


def fmi_unit(name: str) -> str | None:
    """The FMI unit of a taos field or signal name from its SI suffix (:data:`SUFFIXES`)."""
    for suffix, unit in SUFFIXES:
        if name.endswith(suffix):
            return unit
    raise ValueError(f"no SI suffix in {name!r}")


def model_parameters(model: TvcModel) -> dict[str, float | int | bool]:
    """``section.field`` -> value of the model's :data:`PARAMETER_SECTIONS` (SI)."""
    out: dict[str, float | int | bool] = {}
    for sec in PARAMETER_SECTIONS:
        obj = getattr(model, sec)
        for f in dataclasses.fields(obj):
            out[f"{sec}.{f.name}"] = getattr(obj, f.name)
    return out


def with_parameters(model: TvcModel, values: dict) -> TvcModel:
    """``model`` with the ``section.field`` values changed (unchanged ones kept), refused like a
    model file's values: every changed value finite and of its field's sign class (a field the
    file holds positive stays positive, a non-negative one non-negative), the derived frequencies
    plausible (:func:`taos.bounds.check_model_plausible`)."""
    import math

    from ..bounds import check_model_plausible

    base = model_parameters(model)
    changed = {k: v for k, v in values.items() if v != base[k]}
    if not changed:
        return model
    secs = {}
    for sec in PARAMETER_SECTIONS:
        kw = {}
        for k, v in changed.items():
            s, f = k.split(".", 1)
            if s != sec:
                continue
            old = base[k]
            if isinstance(old, float):
                v = float(v)
                need = "positive" if old > 0 else "non-negative"
                if not math.isfinite(v) or v < 0 or (old > 0 and v <= 0):
                    raise InputError(model.source, k, f"a finite {need} value in {fmi_unit(f) or '1'} (FMU parameter)",
                                     got=repr(v))
            elif isinstance(old, int) and not isinstance(old, bool) and not (float(v) == int(v) and int(v) >= 1):
                raise InputError(model.source, k, "a positive whole number (FMU parameter)", got=repr(v))
            kw[f] = type(old)(v)
        secs[sec] = dataclasses.replace(getattr(model, sec), **kw) if kw else getattr(model, sec)
    check_model_plausible(model.source, secs["engine"], secs["actuator"], secs["structure"])
    return model.replace(**secs)


def check_output_path(out) -> Path:
    """``--out`` checked (:func:`check_fmu_output`, then :func:`taos.results.check_output_file`:
    the FMU's own refusal first, so that no message offers ``--force``, which ``taos fmu`` does
    not honour for a file it did not write)."""
    check_fmu_output(Path(out))
    return check_output_file(out, "--out", (".fmu",))


def check_fmu_output(out: Path) -> None:
    """Refuse an ``--out`` that is an existing regular file and not an FMU ``taos fmu`` wrote (a zip
    holding ``resources/taos_fmu/config.json``): an output never replaces a file the program did
    not write, ``--force`` or not."""
    import zipfile

    if not out.is_file():
        return
    try:
        with zipfile.ZipFile(out) as z:
            ours = f"resources/{RESOURCE_DIR}/{CONFIG}" in z.namelist()
    except (OSError, zipfile.BadZipFile):
        ours = False
    if not ours:
        raise InputError(str(out), "--out", "a new file or an FMU that taos fmu wrote (it never replaces a file it "
                         "did not write)", got="an existing file it did not write")


def fmu_model(path: str | Path, friction: str | None, avionics: str) -> TvcModel:
    """The model an FMU runs: the file (``--friction`` applied) with its avionics or the bounding ones."""
    if avionics not in AVIONICS:
        raise InputError("command line", "--avionics", " or ".join(AVIONICS), got=repr(avionics))
    model = load_model(path, friction=friction)
    if avionics == "bounding":
        from ..flight.lco import with_bounding_avionics
        model = with_bounding_avionics(model)
    return model


def _copy_model_files(model: TvcModel, dest: Path) -> str:
    """Copy the model's input files into ``dest`` in their relative layout (below their common
    folder); returns the model file's path relative to ``dest``."""
    files = {role: Path(f).resolve() for role, (f, _) in model.input_files.items()}
    root = Path(os.path.commonpath([str(p.parent) for p in files.values()]))
    for p in files.values():
        q = dest / p.relative_to(root)
        q.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(p, q)
    return files["model"].relative_to(root).as_posix()


#: environment variable of a host without Python of its own: the site-packages folders (os.pathsep
#: separated) of the Python environment with taos, added as site directories (their .pth files
#: processed: editable installs, pinocchio's cmeel prefix) before the FMU imports taos
SITE_VARIABLE = "TAOS_FMU_SITE_PACKAGES"

SCRIPT = f'''"""Entry point of a taos TVC FMU (written by ``taos fmu``): needs a Python with taos importable
(or ${SITE_VARIABLE} naming the site-packages of an environment with taos)."""

import os
import site

for _d in os.environ.get("{SITE_VARIABLE}", "").split(os.pathsep):
    if _d:
        site.addsitedir(_d)

from taos.cosim._slave import TvcSlave, keep_alive  # noqa: E402


class {MODEL_IDENTIFIER}(TvcSlave):
    """One engine's nonlinear TVC (taos.cosim.TvcBlock); resources/{RESOURCE_DIR}/ holds its model."""


keep_alive(globals())   # one reference per execution of this script (taos.cosim._slave.keep_alive)
'''


@dataclass(frozen=True)
class FmuBuild:
    """What :func:`build_fmu` wrote: the FMU file, the model's SHA-256, the engine, the internal
    step [s] and the numbers of inputs, outputs and parameters."""

    path: Path
    model_sha256: str
    engine: str
    dt_s: float
    n_inputs: int
    n_outputs: int
    n_parameters: int


def build_fmu(model_path: str | Path, out: str | Path, *, engine: str = "simplex", friction: str | None = None,
              avionics: str = "model", dt_s: float | None = None, allow_unstable: bool = False) -> FmuBuild:
    """Build the FMI 2.0 co-simulation FMU of ``model_path`` into ``out`` (``*.fmu``), after every
    check of the model (:class:`~taos.cosim.TvcBlock`'s construction); ``engine``, ``friction``,
    ``avionics`` (:data:`AVIONICS`), the internal step ``dt_s`` [s] (default the engine's) and
    ``allow_unstable`` as ``taos simulate``'s options."""
    from ._block import BlockOutputs, TvcBlock

    from ..planar.envelope import check_run_step

    out = check_output_path(out)
    model = fmu_model(model_path, friction, avionics)
    if dt_s is not None:
        check_run_step(dt_s, model, field="--dt", pressure_limit=engine != "taos")
    block = TvcBlock(model, engine=engine, dt_s=dt_s, allow_unstable=allow_unstable)
    block.outputs   # the rest state through the kernels: a friction law whose kernel fails is refused now, not in the host
    try:
        from pythonfmu import FmuBuilder
    except ImportError:
        raise InputError("taos fmu", "pythonfmu", "the pythonfmu package installed (pip install pythonfmu)",
                         got="not importable") from None
    config = {"format": 1, "engine": engine, "friction": model.friction.name, "friction_option": friction,
              "avionics": avionics,
              "dt_s": block.dt_s, "allow_unstable": allow_unstable, "model_name": model.name,
              "model_sha256": model.sha256, "model_source": model.source,
              "model_inputs": {r: {"file": Path(f).name, "sha256": h} for r, (f, h) in model.input_files.items()},
              **base_provenance()}
    with tempfile.TemporaryDirectory(prefix="taos_fmu_") as tmp:
        src = Path(tmp) / "src"
        res = src / RESOURCE_DIR
        res.mkdir(parents=True)
        config["model_file"] = _copy_model_files(model, res / "model")
        (res / CONFIG).write_text(json.dumps(config, indent=1) + "\n")
        script = src / f"{MODEL_IDENTIFIER}.py"
        script.write_text(SCRIPT)
        built = FmuBuilder.build_FMU(script, dest=Path(tmp) / "build" / f"{MODEL_IDENTIFIER}.fmu", project_files=[res])
        atomic_write(out, lambda p: shutil.copyfile(built, p))
    return FmuBuild(path=out, model_sha256=model.sha256, engine=engine, dt_s=block.dt_s, n_inputs=2,
                    n_outputs=len(BlockOutputs.signal_names()), n_parameters=len(model_parameters(model)) + 2)
