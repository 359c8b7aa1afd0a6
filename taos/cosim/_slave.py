"""The FMU's Python side: a ``pythonfmu`` slave around :class:`~taos.cosim.TvcBlock`.

Life cycle (FMI 2.0 co-simulation): instantiation reads ``resources/taos_fmu/config.json``,
loads the model copy and refuses it unless its SHA-256 is the build's; parameters may be set
until initialisation ends, when the block is built from them with every check
(:func:`taos.cosim._fmu.with_parameters`, the block's own checks) and put at rest with the
inputs' values; each ``fmi2DoStep`` steps the block by the communication step.

Errors never crash the importing tool; each logs one line with status ``fmi2Error`` (category
``logStatusError``; pythonfmu's binary forwards messages when the importer turns logging on, e.g.
FMPy's ``debug_logging=True``). A communication step that is not a multiple of the internal step,
a NaN or out-of-range command, an unstable state or a run beyond the physical envelope: the step
is not taken and ``fmi2DoStep`` returns ``fmi2Discard`` (the block stays at the last good
point). A refused parameter at the end of initialisation: ``fmi2ExitInitializationMode``
returns ``fmi2Fatal`` (pythonfmu turns every Python exception into that status; it has no way
to return ``fmi2Error`` from Python).
"""

from __future__ import annotations

import json
from operator import attrgetter
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from ..errors import InputError
from ._block import BlockOutputs, TvcBlock
from ._fmu import CONFIG, RESOURCE_DIR, UNITS, fmi_unit, fmu_model, model_parameters, with_parameters
from ._options import HOLDS


#: every block an FMU instance built, kept until the process ends. pythonfmu 0.7.0's
#: fmi2FreeInstance deallocates the slave's Python objects in a way that corrupts the heap once
#: compiled-kernel objects are among them (measured: about half of the FMPy hosts aborted at exit;
#: with the blocks kept alive, in none of the runs tried; tests/test_fmu.py), so they are never
#: deallocated: a few hundred kB per instantiation.
_ALIVE: list = []


def keep_alive(obj) -> None:
    """Keep ``obj`` referenced until the process ends (:data:`_ALIVE`). The FMU's entry script
    passes its own ``globals()`` at every execution: pythonfmu 0.7.0 runs the script again at each
    instantiation (to find the slave class) and then releases one reference to the module's
    dictionary that it never took, so without this the dictionary is freed under the module (a
    second instance in the same process crashed or found no class)."""
    _ALIVE.append(obj)


class _Real(Real):
    """A pythonfmu Real with an FMI ``unit`` attribute and a start value written to round-trip
    (pythonfmu writes 16 significant digits, which can lose the last bit: a host that sets every
    parameter to its start value would then change the model)."""

    def __init__(self, name: str, unit: str | None = None, **kwargs):
        super().__init__(name, **kwargs)
        self.unit = unit

    def to_xml(self) -> Element:
        el = super().to_xml()
        real = el.find("Real")
        if self.unit:
            real.set("unit", self.unit)
        if self.start is not None:
            real.set("start", repr(float(self.start)))
        return el


class TvcSlave(Fmi2Slave):
    """One engine's nonlinear TVC (both axes) as an FMI 2.0 co-simulation slave."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        from ..results import package_version

        res = Path(str(self.resources)) / RESOURCE_DIR
        cfg = json.loads((res / CONFIG).read_text())
        self._cfg = cfg
        # the --friction option as given (None: the file's law; naming a law makes a variant, its own hash)
        model = fmu_model(res / "model" / cfg["model_file"], cfg.get("friction_option", cfg["friction"]),
                          cfg["avionics"])
        if model.sha256 != cfg["model_sha256"]:
            raise InputError(str(res / "model"), "model_sha256", f"the model the FMU was built from "
                             f"({cfg['model_sha256'][:12]}...)", got=f"{model.sha256[:12]}... (files changed)")
        self._model = model
        self.author = "taos"
        self.version = package_version()
        self.license = "Apache-2.0"
        self.description = (f"taos nonlinear TVC of one engine, both axes ({cfg['engine']} engine): model "
                            f"{cfg['model_name']!r}, model_sha256 {cfg['model_sha256']}; friction {cfg['friction']}, "
                            f"avionics {cfg['avionics']}; internal step {cfg['dt_s']:g} s (communication steps: "
                            f"multiples of it). Needs a Python with taos importable at run time.")
        self.default_experiment = DefaultExperiment(start_time=0.0, step_size=cfg["dt_s"])
        self.pitch_command_rad = 0.0
        self.yaw_command_rad = 0.0
        self._par = dict(model_parameters(model))
        self._dt = float(cfg["dt_s"])
        self._hold = 0
        #: the block, built when initialisation ends from the parameters then (the model was
        #: checked, with every check of the block, when the FMU was built; its SHA-256 above)
        self._block: TvcBlock | None = None
        #: the block's outputs since initialisation ended (None before: the outputs' getters then
        #: read :meth:`_rest_outputs`). An instance made only for its model description, as
        #: pythonfmu's builder makes one, builds no block and loads no compiled kernel.
        self._out = None
        self._register()
        #: value reference -> getter / setter of every Real (the fast path of get_real, set_real)
        self._real_get = {vr: v.getter for vr, v in self.vars.items() if isinstance(v, Real)}
        self._real_set = {vr: v.setter for vr, v in self.vars.items() if isinstance(v, Real) and v.setter is not None}
        #: every output's value reference, in the outputs' order (what a host records at each step)
        names = {v.name: vr for vr, v in self.vars.items()}
        self._output_vrs = [names[n] for n in BlockOutputs.signal_names()]
        self._output_values = attrgetter(*BlockOutputs.signal_names())

    # -- variables ------------------------------------------------------------------------
    def _register(self) -> None:
        for ax in ("pitch", "yaw"):
            self.register_variable(_Real(f"{ax}_command_rad", "rad", causality=Fmi2Causality.input,
                                         variability=Fmi2Variability.continuous,
                                         description=f"FCS {ax} engine-angle command, before the avionics"))
        for name in BlockOutputs.signal_names():
            self.register_variable(_Real(name, fmi_unit(name), causality=Fmi2Causality.output,
                                         variability=Fmi2Variability.continuous,
                                         getter=lambda n=name: getattr(self._out or self._rest_outputs(), n)))
        fixed = {"causality": Fmi2Causality.parameter, "variability": Fmi2Variability.fixed}
        self.register_variable(_Real("internal_step_s", "s", description="the kernel's fixed step", **fixed,
                                     getter=lambda: self._dt, setter=lambda v: setattr(self, "_dt", float(v))))
        self.register_variable(Integer("command_hold", description="command between communication points: "
                                       + ", ".join(f"{i} {h}" for i, h in enumerate(HOLDS)), **fixed,
                                       getter=lambda: self._hold, setter=lambda v: setattr(self, "_hold", int(v))))
        for key, value in self._par.items():
            get = lambda k=key: self._par[k]  # noqa: E731
            put = lambda v, k=key: self._par.__setitem__(k, v)  # noqa: E731
            kw = dict(description=f"model value {key}", getter=get, setter=put, **fixed)
            if isinstance(value, bool):
                var = Boolean(key, **kw)
            elif isinstance(value, int):
                var = Integer(key, **kw)
            else:
                var = _Real(key, fmi_unit(key), **kw)
            self.register_variable(var, nested=False)

    def to_xml(self, model_options: dict | None = None) -> Element:
        """pythonfmu's model description plus the FMI unit definitions of the units used and the
        outputs as initial unknowns (calculated at initialisation from the parameters)."""
        root = super().to_xml(model_options or {})
        structure = root.find("ModelStructure")
        outputs = structure.find("Outputs")
        if outputs is not None:
            initial = SubElement(structure, "InitialUnknowns")
            for u in outputs:
                SubElement(initial, "Unknown", index=u.get("index"))
        used = sorted({r.get("unit") for r in root.iter("Real") if r.get("unit")})
        defs = Element("UnitDefinitions")
        for u in used:
            SubElement(SubElement(defs, "Unit", name=u), "BaseUnit", {k: str(v) for k, v in UNITS[u].items()})
        kids = list(root)
        at = next(i for i, el in enumerate(kids) if el.tag == "CoSimulation") + 1
        root.insert(at, defs)
        return root

    # -- FMI calls ------------------------------------------------------------------------
    def get_real(self, vrs: list) -> list:
        """pythonfmu's ``get_real`` (every value as a float), through a value-reference map
        instead of a type check per variable (a host reads every output at every step); a value
        reference that is not a Real goes to pythonfmu's, which refuses it."""
        if vrs == self._output_vrs:   # every output, in order: read at once (floats already)
            return list(self._output_values(self._out or self._rest_outputs()))
        get = self._real_get
        try:
            return [float(get[vr]()) for vr in vrs]
        except KeyError:
            return super().get_real(vrs)

    def set_real(self, vrs: list, values: list) -> None:
        """pythonfmu's ``set_real`` through the value-reference map (as :meth:`get_real`)."""
        put = self._real_set
        for vr, value in zip(vrs, values):
            f = put.get(vr)
            if f is None:   # not a Real, or one without a setter: pythonfmu's error
                super().set_real([vr], [value])
            else:
                f(value)

    def _rest_outputs(self) -> BlockOutputs:
        """The outputs before initialisation ends: the model file's block (the build's internal
        step and hold) at rest, built when first asked for."""
        if self._block is None:
            cfg = self._cfg
            self._block = TvcBlock(self._model, engine=cfg["engine"], dt_s=float(cfg["dt_s"]),
                                   allow_unstable=cfg["allow_unstable"])
            _ALIVE.append(self._block)
        return self._block.outputs

    def _fail(self, err: Exception) -> None:
        """Log ``err`` (status error) and raise it: pythonfmu's binary returns ``fmi2Fatal``."""
        self.log(str(err), Fmi2Status.error)
        raise err

    def exit_initialization_mode(self):
        try:
            if not 0 <= self._hold < len(HOLDS):
                raise InputError("FMU", "command_hold", " or ".join(f"{i} ({h})" for i, h in enumerate(HOLDS)),
                                 got=repr(self._hold))
            model = with_parameters(self._model, self._par)
            cfg = self._cfg
            self._block = TvcBlock(model, engine=cfg["engine"], dt_s=self._dt, hold=HOLDS[self._hold],
                                   allow_unstable=cfg["allow_unstable"])
            _ALIVE.append(self._block)
            self._out = self._block.reset(self.pitch_command_rad, self.yaw_command_rad)
        except Exception as e:   # every refusal (and any other failure) logged, then fmi2Fatal
            self._fail(e)

    def do_step(self, current_time: float, step_size: float) -> bool:
        """One communication step; a refused one (bad step or command, unstable, beyond the
        envelope) is not taken: the error is logged (status error) and the step returns False,
        which pythonfmu's binary reports as ``fmi2Discard`` with the block left where it was
        (a NaN or out-of-range command never reaches the state)."""
        try:
            self._out = self._block.step(step_size, self.pitch_command_rad, self.yaw_command_rad)
        except Exception as e:   # InputError, SimulationUnstable; anything else is logged alike
            self.log(f"t = {current_time:.9g} s: {e}", Fmi2Status.error)
            return False
        return True
