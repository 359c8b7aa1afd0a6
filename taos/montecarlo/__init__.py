"""Monte Carlo dispersions of the flight LCO verdict, run on Dask.

* :mod:`taos.montecarlo.campaign` - campaign files: dispersions, cases, seeds;
* :mod:`taos.montecarlo.run` - one run: disperse, fly the segment, measure the limit cycle;
* :mod:`taos.montecarlo.stats` - LCO fraction with its confidence interval, percentiles,
  envelopes and the parameters that drive the amplitude;
* :mod:`taos.montecarlo.executor` - the campaign on a Dask LocalCluster or scheduler, stored as
  the runs arrive (resumable).
"""

from taos.montecarlo.campaign import Campaign, Dispersion, load_campaign
from taos.montecarlo.executor import run_campaign
from taos.montecarlo.run import RunResult, run_one
from taos.montecarlo.stats import CampaignResult, summarise, wilson_interval

__all__ = ["Campaign", "Dispersion", "load_campaign", "run_campaign", "RunResult", "run_one", "CampaignResult",
           "summarise", "wilson_interval"]
