"""Monte Carlo dispersions and global sensitivity of the flight LCO, run on Dask.

* :mod:`taos.montecarlo.campaign` - campaign files: dispersions, cases, seeds;
* :mod:`taos.montecarlo.run` - flight runs: disperse, fly the segment, measure the limit cycle;
* :mod:`taos.montecarlo.engine` - a design (parameter sets) and a run kind, run in batches on
  Dask with the inputs sent by value, stored as they arrive (resumable);
* :mod:`taos.montecarlo.store` - the result store (xarray on Zarr, a ``run`` dimension);
* :mod:`taos.montecarlo.inputs` - the content hash of every input file a load reads;
* :mod:`taos.montecarlo.stats` - LCO fraction with its interval, percentiles with order-statistic
  intervals, envelopes, Spearman with Holm's correction;
* :mod:`taos.montecarlo.sensitivity` - Sobol' and Morris indices (SALib), logistic regression;
* :mod:`taos.montecarlo.analytic` - analytic run kinds (Ishigami) and the engine on any design;
* :mod:`taos.montecarlo.executor` - a flight campaign end to end;
* :mod:`taos.montecarlo.sweep` - a parameter sweep over model-file keys (grid, Latin hypercube,
  Saltelli's design for Sobol' indices) run on the engine (``taos sweep``), its design
  (:mod:`taos.montecarlo.sweep_define`) and figures (:mod:`taos.montecarlo.sweep_metrics`).

Names are resolved on first use (PEP 562): a Dask worker importing the task function
(:func:`taos.montecarlo.engine.run_task`) and its run kind imports those modules only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from taos import lazy_api

if TYPE_CHECKING:
    from .analytic import Ishigami, run_design
    from .campaign import Campaign, Dispersion, load_campaign
    from .engine import Design, RunKind
    from .executor import run_campaign
    from .run import FlightRuns
    from .stats import CampaignResult, summarise, wilson_interval
    from .store import open_store
    from .sweep import SweepDefinition, SweepResult, run_sweep
    from .sweep_define import make_design, parse_set

#: public name -> submodule that defines it
_WHERE = {
    "Ishigami": "analytic", "run_design": "analytic", "Campaign": "campaign", "Dispersion": "campaign",
    "load_campaign": "campaign", "Design": "engine", "RunKind": "engine", "run_campaign": "executor",
    "FlightRuns": "run", "CampaignResult": "stats", "summarise": "stats", "wilson_interval": "stats",
    "open_store": "store", "SweepDefinition": "sweep", "SweepResult": "sweep", "run_sweep": "sweep",
    "make_design": "sweep_define", "parse_set": "sweep_define",
}

__all__ = ["Campaign", "Dispersion", "load_campaign", "run_campaign", "FlightRuns", "CampaignResult",
           "summarise", "wilson_interval", "Design", "RunKind", "Ishigami", "run_design", "open_store",
           "SweepDefinition", "SweepResult", "run_sweep", "make_design", "parse_set"]

__getattr__, __dir__ = lazy_api(__name__, {k: f".{m}" for k, m in _WHERE.items()}, globals())
