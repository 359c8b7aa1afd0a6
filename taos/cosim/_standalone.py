"""The standalone planar FMU (``taos fmu MODEL --out F.fmu``, the default): FMI 2.0
co-simulation in C, no Python at run time (the 3-D one: :mod:`taos.cosim._standalone3d`).

What the FMU holds:

* ``sources/taos_kernels.c`` (and ``.h``): the planar state equations and the RK4 step, C
  emitted from the compiled kernels' own Python definitions by :mod:`taos.cosim._ccode`
  (:func:`taos.planar.dynamics._rk4_step` and ``_rates`` with the model's friction law, the
  avionics of :mod:`taos.planar._avionics_kernels`, the limits of
  :mod:`taos.planar.saturation`, the thrust direction of
  :func:`taos.cosim._cores.planar_thrust_direction`): the dynamics are written once, in those
  kernels;
* ``sources/taos_model.h``: the loaded model's numbers as the defaults of the parameter block
  ``TaosParams`` (per axis (pitch, yaw) the plant arrays the kernels take,
  :class:`taos.planar.simulate.PlantArrays`: A, Br, bc, bf, cc, dc, cw, ca, the packed limits;
  the output rows of y = C x (engine angle [rad], engine rate [rad/s], piston [m], load force
  [N], load pressure [Pa]); the packed friction and avionics parameters; the internal step
  [s], K_L [N/m], the avionics gain and the vehicle moment arm [m]), the table of the FMU's
  parameters, the command range [rad] and the envelope (hard stops [rad], 3 x the stall force
  [N]), each number written to round-trip (``repr``);
* ``sources/taos_params.c``: what depends on a parameter, recomputed in C
  (:mod:`taos.cosim._standalone_params`: the plant of K_L by CasADi's code generation of the
  symbolic state space, the avionics gain, the friction law's explicit-step rule);
* ``sources/fmi2_glue.c``: the hand-written, model-independent FMI interface (life cycle,
  variables, communication step; :file:`taos/cosim/fmi2_glue.c`, with ``fmi2_glue_common.h``, the
  logging, state checks, FMU state and refused calls it shares with the 3-D FMU), and the FMI 2.0
  headers it includes (FMPy's copies);
* ``sources/buildDescription.xml`` (the FMI 3.0 build description, also read for FMI 2.0.4
  source FMUs) and ``<SourceFiles>`` in the model description: a user compiles the sources
  for another platform with ``cc -shared -fPIC -O2 -I sources sources/*.c -lm``;
* ``binaries/linux64/TaosTvcC.so``, compiled here (Linux x86-64 only; links libc and libm,
  no Python);
* ``resources/taos_fmu/config.json``: the build's provenance (model hash and overrides, taos
  version, friction law, avionics, internal step).

Parameters (:mod:`taos.cosim._standalone_params`): the internal step and the load stiffness
(fixed), the friction levels, the avionics gain and the vehicle moment arm (tunable),
``command_mode`` (fixed: 0 exact, 1 ramp, 2 hold); the thrust is an input. Every other model
value is compiled in: a change to it is a new FMU built from the model variant
(``model.with_values``, or a changed model file).
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import shutil
import subprocess
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, indent, tostring

import numpy as np

from ..errors import InputError
from ..model import TvcModel
from ._fmu import CONFIG, RESOURCE_DIR, FmuBuild, check_output_path, fmu_model
from ._standalone_params import VEHICLE_OUTPUTS, parameters, params_source
from ._standalone_xml import IDENTIFIER, SOURCES, envelope, model_description

GLUE = Path(__file__).with_name("fmi2_glue.c")
#: the FMI functions both standalone FMUs share, included by each glue (sources/fmi2_glue_common.h)
GLUE_COMMON = Path(__file__).with_name("fmi2_glue_common.h")
FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
#: the output rows of y = C x per axis, in the glue's order (its TAOS_NY rows)
OUTPUT_ROWS = ("theta_rad", "omega_rad_s", "x_p_m", "load_force_N", "p_load_Pa")
CFLAGS = ("-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden")
SOURCE = "taos fmu"


def kernel_sources(model) -> tuple[str, str]:
    """(C source, C header) of the planar kernels with ``model``'s friction law: entries
    ``taos_rates`` (the state equations: dx/dt into ``dx``, returns (dz/dt [rad/s], T_f [N m],
    u [rad])), ``taos_rk4_step`` (one RK4 step in place, returns (z [rad], T_f, u)),
    ``taos_finite`` and ``taos_thrust_direction`` (:mod:`taos.cosim._ccode`)."""
    from ..planar import dynamics as dyn
    from ..planar.simplex import simplex_plant
    from ..planar.simulate import kernel_args
    from ._ccode import Translator
    from ._cores import planar_thrust_direction

    pa = kernel_args(simplex_plant(model, "pitch"), model)
    n, nr = pa.A.shape[0], pa.Br.shape[1]
    v, r = np.zeros(n), np.zeros(nr)
    law = model.friction.entry.rates
    fp, avp = model.friction.pack(), model.avionics.pack()
    tr = Translator()
    tr.entry(dyn._rates, (v, 0.0, r, *pa, law, fp, avp, v), "taos_rates")
    tr.entry(dyn._rk4_step, (v, 0.0, r, r, r, 1.0, *pa, law, fp, avp, v, v, v, v, v), "taos_rk4_step")
    tr.entry(dyn._finite, (v, 0.0), "taos_finite")
    tr.entry(planar_thrust_direction, (0.0, 0.0), "taos_thrust_direction")
    head = (f"/* Generated by taos (taos.cosim._ccode) from the compiled kernels' Python source; friction law "
            f"{model.friction.name}. Do not edit: rebuild with taos fmu --standalone. */\n")
    return head + tr.source(), head + "#ifndef TAOS_KERNELS_H\n#define TAOS_KERNELS_H\n" + tr.header() + "#endif\n"


def model_header(model, dt_s: float, guid: str, allow_unstable: bool) -> str:
    """``taos_model.h``: the model's numbers as the parameter block's defaults
    (:func:`taos.cosim._standalone_params.params_header`)."""
    from ..planar.simplex import simplex_plant
    from ..planar.simulate import kernel_args
    from ._standalone_params import params_header

    axes = []
    for ax in ("pitch", "yaw"):
        plant = simplex_plant(model, ax)
        pa = kernel_args(plant, model)
        cy = np.array([plant.ss.C[plant.ss.output_index(k)] for k in OUTPUT_ROWS])
        axes.append((pa, cy))
    (p0, _), (p1, _) = axes
    if any(a.shape != b.shape for a, b in zip(p0, p1)):
        raise ValueError("the pitch and yaw plants differ in shape")
    if p0.lim.size == 0:
        raise InputError(model.source, "limits", "a model with its actuator limits (the standalone FMU packs them)",
                         got="none")
    return params_header(model, dt_s, guid, allow_unstable, axes, OUTPUT_ROWS, envelope(model))


def build_description(identifier: str = IDENTIFIER, sources: tuple[str, ...] = SOURCES,
                      what: str = "the standalone taos TVC FMU") -> str:
    """``sources/buildDescription.xml`` (FMI 3.0 schema; module docstring) of the FMU
    ``identifier`` compiled from ``sources`` (the 3-D FMU's too)."""
    root = Element("fmiBuildDescription", fmiVersion="3.0")
    bc = SubElement(root, "BuildConfiguration", modelIdentifier=identifier,
                    description=f"{what}: C99 sources, link with libm")
    fs = SubElement(bc, "SourceFileSet", language="C99", compilerOptions="-O2")
    for s in sources:
        SubElement(fs, "SourceFile", name=s)
    SubElement(bc, "Library", name="m", description="the C maths library (sqrt, exp, pow, asin, hypot)")
    indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="unicode") + "\n"


def _c_compiler() -> str:
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        raise InputError(SOURCE, "C compiler", "cc or gcc on PATH (or $CC) to compile the FMU's binary", got="none found")
    return cc


def compile_sources(src: Path, out: Path, sources: tuple[str, ...] = SOURCES) -> None:
    """Compile the FMU's C ``sources`` in ``src`` into the shared library ``out``."""
    cmd = [_c_compiler(), *CFLAGS, "-I", str(src), *(str(src / s) for s in sources), "-o", str(out), "-lm"]
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if r.returncode != 0:
        raise RuntimeError(f"compiling the standalone FMU failed ({' '.join(cmd)}):\n{r.stderr[-4000:]}")


def write_fmu(root: Path, out: Path) -> None:
    """Zip the FMU folder ``root`` into ``out`` (atomically: a refusal or a kill leaves no half FMU)."""
    from ..results import atomic_write

    def write(p):
        with zipfile.ZipFile(p, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(root.rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(root).as_posix())
    atomic_write(out, write)


def fmi_headers() -> Path:
    """The folder of the FMI 2.0 C headers (FMPy's copies)."""
    try:
        import fmpy
    except ImportError:
        raise InputError(SOURCE, "fmpy", "FMPy installed (its FMI 2.0 headers are compiled into the FMU)",
                         got="not importable") from None
    d = Path(fmpy.__file__).parent / "c-code"
    if not all((d / h).is_file() for h in FMI_HEADERS):
        raise InputError(SOURCE, "fmpy", "FMPy with its FMI 2.0 headers (fmpy/c-code)", got=str(d))
    return d


def standalone_target(model_path, out, friction: str | None, avionics: str) -> tuple[Path, TvcModel]:
    """The checked output path and the model of a standalone FMU build (planar and 3-D): this
    platform builds the linux64 binary; a loaded model takes no ``friction``/``avionics``
    override (its variant is made with ``model.with_values``)."""
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "AMD64"):
        raise InputError(SOURCE, "platform", "Linux x86-64 (the binary built is linux64; the sources build elsewhere)",
                         got=f"{platform.system()} {platform.machine()}")
    out = check_output_path(out)
    if isinstance(model_path, TvcModel):
        if friction is not None or avionics != "model":
            raise InputError(SOURCE, "friction, avionics", "none with a loaded model (make the variant with "
                             "model.with_values)", got=f"{friction!r}, {avionics!r}")
        model = model_path
    else:
        model = fmu_model(model_path, friction, avionics)
    return out, model


def build_standalone_fmu(model_path, out, *, friction: str | None = None, avionics: str = "model",
                         dt_s: float | None = None, allow_unstable: bool = False) -> FmuBuild:
    """Build the standalone FMU (module docstring) of ``model_path`` (a model file, or a loaded
    :class:`~taos.model.TvcModel` such as a variant made with ``model.with_values``) into ``out``
    after every check of the model (:class:`~taos.cosim.TvcBlock`'s construction); options as
    :func:`taos.cosim.build_fmu` (simplex engine only). Nothing is written on a refusal."""
    from ..planar.envelope import check_run_step
    from ..results import base_provenance, model_provenance
    from ._block import BlockOutputs, TvcBlock

    out, model = standalone_target(model_path, out, friction, avionics)
    if dt_s is not None:
        check_run_step(dt_s, model, field="--dt")
    block = TvcBlock(model, dt_s=dt_s, allow_unstable=allow_unstable)   # every check taos simulate makes
    headers = fmi_headers()
    kernels_c, kernels_h = kernel_sources(model)
    prov = {**base_provenance(), **model_provenance(model), "friction": model.friction.name, "avionics": avionics,
            "dt_s": block.dt_s, "allow_unstable": allow_unstable, "engine": "simplex", "standalone": True}
    digest = hashlib.sha256(json.dumps(prov, sort_keys=True, default=str).encode() + kernels_c.encode()
                            + GLUE.read_bytes() + GLUE_COMMON.read_bytes()).hexdigest()
    guid = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, f"taos-standalone-fmu:{digest}")) + "}"
    prov["guid"] = guid
    with tempfile.TemporaryDirectory(prefix="taos_fmu_c_") as tmp:
        root = Path(tmp) / "fmu"
        src = root / "sources"
        src.mkdir(parents=True)
        (src / "taos_kernels.c").write_text(kernels_c)
        (src / "taos_kernels.h").write_text(kernels_h)
        (src / "taos_model.h").write_text(model_header(model, block.dt_s, guid, allow_unstable))
        (src / "taos_params.c").write_text(params_source(model))
        shutil.copyfile(GLUE, src / "fmi2_glue.c")
        shutil.copyfile(GLUE_COMMON, src / GLUE_COMMON.name)
        for h in FMI_HEADERS:
            shutil.copyfile(headers / h, src / h)
        (src / "buildDescription.xml").write_text(build_description())
        (root / "binaries" / "linux64").mkdir(parents=True)
        compile_sources(src, root / "binaries" / "linux64" / f"{IDENTIFIER}.so")
        (root / "resources" / RESOURCE_DIR).mkdir(parents=True)
        (root / "resources" / RESOURCE_DIR / CONFIG).write_text(json.dumps(prov, indent=1, default=str) + "\n")
        (root / "modelDescription.xml").write_bytes(model_description(model, block.dt_s, guid, prov, avionics))
        write_fmu(root, out)
    return FmuBuild(path=out, model_sha256=model.sha256, engine="simplex", dt_s=block.dt_s, n_inputs=3,
                    n_outputs=len(BlockOutputs.signal_names()) + len(VEHICLE_OUTPUTS),
                    n_parameters=len(parameters(model, block.dt_s)) + 1)

