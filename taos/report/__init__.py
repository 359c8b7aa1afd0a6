"""Analyses behind the Green Run report and the ``info`` summaries: spec masks (:mod:`.spec`)
and figures of merit (:mod:`.merit`)."""
