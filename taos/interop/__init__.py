"""The TVC models leaving taos for other tools.

* :mod:`.python_control` - linear models and frequency responses to and from python-control
  (``control.StateSpace`` / ``control.FrequencyResponseData``) with their signal names;
* :mod:`.files` - the linear model and its response as MATLAB ``.mat`` or CSV files
  (``taos export``).

Names are resolved on first use (python-control costs seconds to import).
"""

from __future__ import annotations

import importlib

_API = {
    "to_control": ".python_control", "to_control_ss": ".python_control", "from_control_ss": ".python_control",
    "frd": ".python_control", "frd_samples": ".python_control", "freqresp_to_control": ".python_control", "freqresp_from_control": ".python_control",
    "measured_to_control": ".python_control", "masv_freqresp_to_control": ".python_control",
    "linear_export_data": ".files", "export_mat": ".files", "export_csv": ".files",
}
__all__ = sorted(_API)


def __getattr__(name: str):
    try:
        module = _API[name]
    except KeyError:
        raise AttributeError(f"module 'taos.interop' has no attribute {name!r}") from None
    return getattr(importlib.import_module(module, __name__), name)


def __dir__():
    return __all__
