"""Identification: test data in, frequency responses out, model parameters fitted, models compared.

* :mod:`taos.identify.data` - CSV/HDF5 time histories with units;
* :mod:`taos.identify.estimation` - sine-dwell and H1 frequency-response estimates;
* :mod:`taos.identify.segments` - the excitation per axis and per segment of a record;
* :mod:`taos.identify.surrogate` - the CasADi surrogate of the simplex model used by the fit;
* :mod:`taos.identify.fit` - least-squares fits with standard errors;
* :mod:`taos.identify.compare` - two model fits side by side;
* :mod:`taos.identify.series` - a series of records fitted one by one, with trends.
"""

from taos.identify.compare import Comparison, compare_models
from taos.identify.data import TestData, load_test_data
from taos.identify.estimation import MeasuredResponse, estimate
from taos.identify.fit import FitResult, fit_frequency_response

__all__ = ["Comparison", "compare_models", "TestData", "load_test_data", "MeasuredResponse", "estimate",
           "FitResult", "fit_frequency_response"]
