"""
What flight shows: the loop reconstructed at the PTI
====================================================

A short late-burn stretch of the ascent is flown with LuGre gimbal friction (the limit cycle
running), the 400 s multisine PTI is read back from the record at its own lines, and the
reconstructed flight-control open loop is set against the model's linear and
describing-function loops (seed paper sec. 5).
"""

import taos
from taos.flight.ascent import load_ascent
from taos.flight.ascent_sim import simulate_ascent
from taos.flight.lco import with_bounding_avionics
from taos.flight.pti import analyse_ptis
from taos.flight.pti_record import FlightRecord
from taos.plotting.pti import plot_pti

ascent = load_ascent("ascent")
model = with_bounding_avionics(taos.load_model(ascent.tvc_model, friction="lugre"))
h = simulate_ascent(ascent, model, axes=("yaw",), start_s=380.0, end_s=441.0, attitude0_rad=0.002)
res = analyse_ptis(FlightRecord.from_history(h), ascent, model, describing=False)
for r in res.responses:
    print(r.friction()["verdict"])
fig = plot_pti(res)
