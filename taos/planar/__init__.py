"""The planar "simplex" engine: one actuator, one engine axis (seed paper sections 2 and 3).

Its modules read like those of its 3-D sibling :mod:`taos.taos3d`:

* :mod:`.simplex` - the model: the Lur'e plant (linear block + friction + avionics + limits)
  built from the component models below;
* :mod:`.actuator`, :mod:`.avionics`, :mod:`.saturation` - the component models: the
  hydraulic position servo, the command electronics, and the servo's hard nonlinearities
  (valve flow, supply pressure, hard stops);
* :mod:`.dynamics` (with :mod:`._avionics_kernels`) - the compiled kernels: the fixed-step
  integrator of the Lur'e plant;
* :mod:`.simulate` - time histories (:mod:`.runfile` reads their files, and every HDF5 record,
  without trusting them);
* :mod:`.freqresp` - exact linear and sine-dwell frequency responses;
* :mod:`.steady` - the periodic steady state by shooting;
* :mod:`.envelope` - the checks a run needs before it starts (step, sizes, stability) and after
  (the physical envelope).

The public functions are exported from :mod:`taos` (``taos.simulate``, ``taos.linear_freqresp``,
...); no name here is both a function and a submodule.
"""
