"""Identification: test data in, frequency responses out, model parameters fitted, models compared.

* :mod:`taos.identify.data` - CSV/HDF5 time histories with units;
* :mod:`taos.identify.estimation` - sine-dwell and H1 frequency-response estimates;
* :mod:`taos.identify.segments` - the excitation per axis and per segment of a record;
* :mod:`taos.identify.surrogate` - the CasADi surrogate of the simplex model used by the fit;
* :mod:`taos.identify.fit` - least-squares fits with standard errors;
* :mod:`taos.identify.compare` - two model fits side by side;
* :mod:`taos.identify.series` - a series of records fitted one by one, with trends;
* :mod:`taos.identify.reduce` - the planar-equivalent friction of a 3-D model (``taos reduce``).

Names are resolved on first use (PEP 562): a module taking one table from a submodule
(:data:`taos.identify.surrogate.PARAMETERS`) does not import the fit and the estimators.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from taos import lazy_api

if TYPE_CHECKING:
    from .compare import Comparison, compare_models
    from .data import TestData, load_test_data
    from .estimation import MeasuredResponse, estimate
    from .fit import FitResult, fit_frequency_response
    from .reduce import ReductionResult, reduce_to_planar

#: public name -> submodule that defines it
_WHERE = {
    "Comparison": "compare", "compare_models": "compare", "TestData": "data", "load_test_data": "data",
    "MeasuredResponse": "estimation", "estimate": "estimation", "FitResult": "fit",
    "fit_frequency_response": "fit", "ReductionResult": "reduce", "reduce_to_planar": "reduce",
}

__all__ = ["Comparison", "compare_models", "TestData", "load_test_data", "MeasuredResponse", "estimate",
           "FitResult", "fit_frequency_response", "ReductionResult", "reduce_to_planar"]

__getattr__, __dir__ = lazy_api(__name__, {k: f".{m}" for k, m in _WHERE.items()}, globals())
