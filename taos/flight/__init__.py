"""Flight: the notional vehicle loop around the TVC, describing functions, limit cycles.

* :mod:`taos.flight.vehicle` - rigid-body vehicle + flight-control system, loop response, margins;
* :mod:`taos.flight.describing` - the TVC describing-function map N(A, w) by sine dwells;
* :mod:`taos.flight.lco` - harmonic-balance LCO prediction and time-domain confirmation;
* :mod:`taos.flight.signoff` - the sign-off: stated limits checked over the cases, margin to each;
* :mod:`taos.flight.ascent_sim` - flying an ascent with the nonlinear TVC, and the study of one
  run per friction law (:func:`fly_ascent`).

Names are resolved on first use (PEP 562): a process that needs one module (a Monte Carlo
worker flying an ascent) imports that module's dependencies only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from taos import lazy_api

if TYPE_CHECKING:
    from .ascent import Ascent, load_ascent
    from .ascent_sim import AscentHistory, AscentStudy, fly_ascent, simulate_ascent
    from .describing import DescribingFunctionMap, describing_function_map
    from .lco import LcoPrediction, LcoReport, analyse_lco, predict_lco, simulate_flight
    from .signoff import Requirements, SignOff, load_requirements, sign_off
    from .vehicle import FlightModel, Margins, load_flight, loop_freqresp, margins

#: public name -> submodule that defines it
_WHERE = {
    "Ascent": "ascent", "load_ascent": "ascent", "AscentHistory": "ascent_sim", "AscentStudy": "ascent_sim",
    "fly_ascent": "ascent_sim", "simulate_ascent": "ascent_sim",
    "DescribingFunctionMap": "describing", "describing_function_map": "describing", "LcoPrediction": "lco",
    "LcoReport": "lco", "analyse_lco": "lco", "predict_lco": "lco", "simulate_flight": "lco",
    "Requirements": "signoff", "SignOff": "signoff", "load_requirements": "signoff", "sign_off": "signoff",
    "FlightModel": "vehicle", "Margins": "vehicle", "load_flight": "vehicle", "loop_freqresp": "vehicle",
    "margins": "vehicle",
}

__all__ = ["DescribingFunctionMap", "describing_function_map", "LcoPrediction", "LcoReport", "analyse_lco",
           "predict_lco", "simulate_flight", "FlightModel", "Margins", "load_flight", "loop_freqresp", "margins",
           "Requirements", "SignOff", "load_requirements", "sign_off", "Ascent", "load_ascent", "AscentHistory",
           "AscentStudy", "fly_ascent", "simulate_ascent"]

__getattr__, __dir__ = lazy_api(__name__, {k: f".{m}" for k, m in _WHERE.items()}, globals())
