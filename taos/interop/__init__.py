"""The TVC models leaving taos for other tools.

* :mod:`.python_control` - linear models and frequency responses to and from python-control
  (``control.StateSpace`` / ``control.FrequencyResponseData``) with their signal names;
* :mod:`.files` - the linear model and its response as MATLAB ``.mat`` or CSV files
  (``taos export``).

Names are resolved on first use (python-control costs seconds to import).
"""

from __future__ import annotations

from taos import lazy_api

_API = {
    "to_control": ".python_control", "to_control_ss": ".python_control", "from_control_ss": ".python_control",
    "frd": ".python_control", "frd_samples": ".python_control", "freqresp_to_control": ".python_control", "freqresp_from_control": ".python_control",
    "measured_to_control": ".python_control", "masv_freqresp_to_control": ".python_control",
    "linear_export_data": ".files", "export_mat": ".files", "export_csv": ".files",
}
__all__ = sorted(_API)


__getattr__, __dir__ = lazy_api(__name__, _API, globals())
