"""The block's and the FMU's option values (no imports: the command line's ``--help`` reads them)."""

#: how the command moves between communication points (:mod:`taos.cosim._block`): held over the
#: step, or ramped from the previous step's command to the new one
HOLDS = ("hold", "ramp")
#: ``taos fmu --avionics``: the model file's avionics, or the paper's bounding -1 dB gain without
#: quantisation (:func:`taos.flight.lco.with_bounding_avionics`)
AVIONICS = ("model", "bounding")
