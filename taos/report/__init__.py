"""The Green Run report and the ``info`` summaries, as library calls.

* :mod:`.analysis` - :func:`greenrun` (the analysis) -> :class:`GreenRunResult`, with
  ``.summary()`` (the ``summary.json`` dict) and ``.write(DIR)`` (the report folder);
* :mod:`.html` - the report page (rendering only; the one module here that draws);
* :mod:`.summary` - :func:`model_summary` (what ``taos info --json`` prints) and
  :func:`figures_of_merit`;
* :mod:`.merit` - the figures of merit; :mod:`.spec` - spec masks; :mod:`.verdict` - the mask on
  every basis (linear, dwell, measured, step) and the cause of each shortfall.

Layers: the analyses (:mod:`.merit`, :mod:`.spec`, :mod:`.verdict`, :mod:`.summary`) sit with the other analyses
(layer 4); :mod:`.analysis` and :mod:`.html` sit with the drawing (layer 5), because writing the
report draws it. Names are resolved on first use, so ``taos info`` imports none of the report.
"""

from __future__ import annotations

from taos import lazy_api

#: public name -> module that defines it
_API = {
    "greenrun": "taos.report.analysis", "GreenRunResult": "taos.report.analysis",
    "model_summary": "taos.report.summary", "figures_of_merit": "taos.report.summary",
    "spec_verdict": "taos.report.verdict", "Verdict": "taos.report.verdict",
}

__all__ = sorted(_API)


__getattr__, __dir__ = lazy_api(__name__, _API, globals())
