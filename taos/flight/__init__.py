"""Flight: the notional vehicle loop around the TVC, describing functions, limit cycles.

* :mod:`taos.flight.vehicle` - rigid-body vehicle + flight-control system, loop response, margins;
* :mod:`taos.flight.describing` - the TVC describing-function map N(A, w) by sine dwells;
* :mod:`taos.flight.lco` - harmonic-balance LCO prediction and time-domain confirmation;
* :mod:`taos.flight.signoff` - the sign-off: stated limits checked over the cases, margin to each.
"""

from taos.flight.describing import DescribingFunctionMap, describing_function_map
from taos.flight.lco import LcoPrediction, LcoReport, analyse_lco, predict_lco, simulate_flight
from taos.flight.signoff import Requirements, SignOff, load_requirements, sign_off
from taos.flight.vehicle import FlightModel, Margins, load_flight, loop_freqresp, margins

__all__ = ["DescribingFunctionMap", "describing_function_map", "LcoPrediction", "LcoReport", "analyse_lco",
           "predict_lco", "simulate_flight", "FlightModel", "Margins", "load_flight", "loop_freqresp", "margins",
           "Requirements", "SignOff", "load_requirements", "sign_off"]
