"""The standalone FMU's ``modelDescription.xml`` (FMI 2.0 co-simulation;
:mod:`taos.cosim._standalone`).

Variables, in value-reference order, each with a description:

* Real 0, 1: inputs ``pitch_command_rad``, ``yaw_command_rad`` [rad] (FCS commands before the
  avionics, start 0, min/max the command range from the model's gimbal range);
* Real 2..18: outputs, the signals of :class:`~taos.cosim.BlockOutputs` (SI units);
* Real 19: ``internal_step_s`` [s], a fixed parameter (a constant for a plug-in law with a step
  rule taos cannot check in C; :mod:`taos.cosim._standalone_params`);
* Real 20: input ``thrust_N`` [N] (start: the model's engine.thrust; only the vehicle outputs
  use it: the planar model's friction levels are its own parameters);
* Real 21..26: outputs ``vehicle_force_{x,y,z}_N``, ``vehicle_moment_{x,y,z}_Nm``, the engine's
  thrust on the vehicle in the gimbal frame and its moment about the vehicle reference point;
* Real 27..: the parameters of :func:`taos.cosim._standalone_params.parameters` (load
  stiffness fixed; avionics gain, moment arm, friction levels tunable);
* Integer 0: ``command_mode`` (fixed parameter: 0 exact, 1 ramp, 2 hold).

Every output is computed at each communication point from the state there: no direct
feedthrough (``<Outputs>`` list no dependency); at initialisation the post-avionics commands
depend on their axis' command input and the vehicle outputs on the thrust
(``<InitialUnknowns>``), every other output is the rest value.

Capabilities as implemented by :file:`fmi2_glue.c`: FMU state get/set and serialisation, any
communication step that is a whole multiple of the internal step, the host's memory
functions; no directional derivatives, no input interpolation, no asynchronous steps.
"""

from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement, indent, tostring

from ._fmu import UNITS, fmi_unit

#: FMI units: taos.cosim._fmu's and the friction laws' damping
ALL_UNITS = {**UNITS, "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1}}
#: the standalone FMU's model identifier (its shared library's name)
IDENTIFIER = "TaosTvcC"
#: the C files compiled into it (sources/)
SOURCES = ("fmi2_glue.c", "taos_kernels.c", "taos_params.c")


def envelope(model) -> tuple[float, float, float]:
    """(command range [rad], hard-stop envelope [rad], load-force bound [N]) of the FMU: the
    model's gimbal range (else :data:`taos.bounds.GIMBAL_RANGE_RAD`), 1.2 x it (as
    :data:`taos.bounds.HARD_STOP_RAD` is of the default range), and
    :data:`taos.bounds.LOAD_FORCE_FACTOR` x the stall force A P_s."""
    from ..bounds import GIMBAL_RANGE_RAD, HARD_STOP_RAD, LOAD_FORCE_FACTOR

    rng = model.engine.gimbal_range_rad if model.engine.gimbal_range_rad > 0 else GIMBAL_RANGE_RAD
    return rng, rng * HARD_STOP_RAD / GIMBAL_RANGE_RAD, LOAD_FORCE_FACTOR * model.actuator.stall_force_N


_DESCRIPTIONS = {
    "engine_rad": "engine angle about the {ax} gimbal axis",
    "engine_rate_rad_s": "engine angular rate about the {ax} gimbal axis",
    "piston_m": "{ax} actuator piston position",
    "load_force_N": "{ax} actuator load force F_L",
    "load_pressure_Pa": "{ax} actuator load pressure P_L",
    "friction_torque_Nm": "{ax} gimbal friction torque",
    "command_avionics_rad": "{ax} engine-angle command after the avionics (quantiser, crossover gain)",
}
_THRUST = "component {c} of the unit thrust vector on the vehicle in the gimbal frame (z along the undeflected " \
          "engine axis towards the thrust structure)"


def output_description(name: str) -> str:
    """The description of output ``name`` (a :class:`~taos.cosim.BlockOutputs` signal)."""
    if name.startswith("thrust_direction_"):
        return _THRUST.format(c=name[-1])
    ax, sig = name.split("_", 1)
    return _DESCRIPTIONS[sig].format(ax=ax) + ", at the communication point"


def model_description(model, dt_s: float, guid: str, prov: dict, avionics: str) -> bytes:
    """The model description (module docstring); ``prov`` the build's provenance (taos version,
    model hash and overrides), also written as the ``taos`` tool's vendor annotation."""
    from ._block import BlockOutputs
    from ._standalone_params import (
        VEHICLE_OUTPUTS,
        VR_DT,
        VR_THRUST,
        VR_VEHICLE0,
        parameters,
    )
    rng, stop, force = envelope(model)
    version = prov.get("package_version", "?")
    root = description_root(
        f"taos TVC {model.name}", guid,
        (f"taos nonlinear TVC of one engine, both axes (planar simplex model), standalone C (no Python "
         f"at run time): model {model.name!r}, model_sha256 {model.sha256}; friction "
         f"{model.friction.name}, avionics {avionics}; internal step {dt_s:g} s (communication steps: "
         f"whole multiples of it); commands within +-{rng:.6g} rad, envelope +-{stop:.6g} rad, "
         f"{force:.6g} N; taos {version}."),
        version, f"taos {version} (taos fmu)", IDENTIFIER, SOURCES)
    outputs = BlockOutputs.signal_names()
    pars = parameters(model, dt_s)
    units = sorted({u for u in [fmi_unit(n) for n in outputs] + ["rad", "s", "N", "N.m"] + [p.unit for p in pars]
                    if u})
    defs = SubElement(root, "UnitDefinitions")
    for u in units:
        SubElement(SubElement(defs, "Unit", name=u), "BaseUnit", {k: str(v) for k, v in ALL_UNITS[u].items()})
    cats = SubElement(root, "LogCategories")
    for name, what in (("logStatusError", "a refused call (a host mistake): status fmi2Error"),
                       ("logStatusDiscard", "a step not taken (unstable or beyond the envelope): fmi2Discard"),
                       ("logAll", "every message")):
        SubElement(cats, "Category", name=name, description=what)
    SubElement(root, "DefaultExperiment", startTime="0.0", stepSize=repr(float(dt_s)))
    tool = SubElement(SubElement(root, "VendorAnnotations"), "Tool", name="taos")
    SubElement(tool, "Provenance", {k: str(v) for k, v in sorted(prov.items())})
    mv = SubElement(root, "ModelVariables")
    index = {}

    def var(name, vr, desc, kind="Real", **attrs):
        sv = SubElement(mv, "ScalarVariable", {"name": name, "valueReference": str(vr), "description": desc,
                                               **{k: v for k, v in attrs.items() if k in ("causality", "variability",
                                                                                          "initial")}})
        SubElement(sv, kind, {k: v for k, v in attrs.items() if k in ("unit", "start", "min", "max")})
        index[name] = len(index) + 1

    for i, ax in enumerate(("pitch", "yaw")):
        var(f"{ax}_command_rad", i, f"FCS {ax} engine-angle command, before the avionics", causality="input",
            variability="continuous", unit="rad", start="0.0", min=repr(-rng), max=repr(rng))
    for j, name in enumerate(outputs):
        u = fmi_unit(name)
        var(name, 2 + j, output_description(name), causality="output", variability="continuous",
            **({"unit": u} if u else {}))
    if not any(p.vr == VR_DT for p in pars):
        var("internal_step_s", VR_DT, "the kernel's fixed RK4 step (built in: taos fmu --dt; the friction law's "
            "step rule is not known to the C code)", causality="local", variability="constant", initial="exact",
            unit="s", start=repr(float(dt_s)))

    def par(p):
        b = {"min": repr(p.lo)} if p.lo > 0 or not p.positive else {}
        b.update({"max": repr(p.hi)} if p.hi != float("inf") else {})
        var(p.name, p.vr, p.description + ("" if p.tunable else "; fixed: set before initialisation ends"),
            causality="parameter", variability="tunable" if p.tunable else "fixed", initial="exact",
            start=repr(float(p.start)), **({"unit": p.unit} if p.unit else {}), **b)

    for p in pars:
        if p.vr == VR_DT:
            par(p)
    var("thrust_N", VR_THRUST, "engine thrust T (vehicle outputs only: the planar model's friction levels are its "
        "friction parameters)", causality="input", variability="continuous", unit="N",
        start=repr(float(model.engine.thrust_N)), min="0.0")
    for j, name in enumerate(VEHICLE_OUTPUTS):
        comp = name.split("_")[2]
        what = (f"component {comp} of the engine thrust on the vehicle, F = T d (d the thrust direction), gimbal frame"
                if "force" in name else f"component {comp} of the thrust's moment about the vehicle reference point, "
                "M = (l F_y, -l F_x, 0) with the gimbal l behind it along -z, gimbal frame")
        var(name, VR_VEHICLE0 + j, what + ", at the communication point", causality="output",
            variability="continuous", unit="N" if "force" in name else "N.m")
    for p in pars:
        if p.vr != VR_DT:
            par(p)
    var("command_mode", 0, "command between communication points: 0 exact (taos simulate of the command held over "
        "each step: it enters over the first internal step), 1 ramped from the previous one over the step, 2 held "
        "(a staircase switching at the communication point)", kind="Integer", causality="parameter",
        variability="fixed", initial="exact", start="0", min="0", max="2")
    ms = SubElement(root, "ModelStructure")
    outs = SubElement(ms, "Outputs")
    for name in outputs + VEHICLE_OUTPUTS:
        SubElement(outs, "Unknown", index=str(index[name]), dependencies="")
    init = SubElement(ms, "InitialUnknowns")
    for name in sorted(outputs + VEHICLE_OUTPUTS, key=index.get):
        dep = ""
        if name.endswith("_command_avionics_rad"):
            dep = str(index[name.split("_", 1)[0] + "_command_rad"])
        elif name in VEHICLE_OUTPUTS:
            dep = str(index["thrust_N"])
        SubElement(init, "Unknown", {"index": str(index[name]), "dependencies": dep,
                                     **({"dependenciesKind": "dependent"} if dep else {})})
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8", xml_declaration=False) + b"\n"


def description_root(name: str, guid: str, description: str, version: str, tool: str, identifier: str,
                     sources: tuple[str, ...]) -> Element:
    """The ``fmiModelDescription`` element of a standalone FMU (planar and 3-D) with its
    ``CoSimulation`` capabilities (the truthful flags: variable steps, FMU state get/set and
    serialisation; no interpolation, derivatives or asynchronous steps) and source files."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": name, "guid": guid, "description": description,
        "author": "taos", "version": str(version), "generationTool": tool,
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0"})
    cs = SubElement(root, "CoSimulation", {
        "modelIdentifier": identifier, "needsExecutionTool": "false",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "false",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"})
    files = SubElement(cs, "SourceFiles")
    for s in sources:
        SubElement(files, "File", name=s)
    return root
