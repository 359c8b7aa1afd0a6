"""Packed avionics-parameter slots (no numba here: :class:`taos.planar.avionics.Avionics`
packs by them without compiling anything; the kernels of :mod:`taos.planar._avionics_kernels`
and :mod:`taos.taos3d.dynamics` read the packed vector by them).

Packed layout (:meth:`taos.planar.avionics.Avionics.pack`, float64, length AV_TABLE + 2 n)::

    slot           name       quantity                                    unit
    0              AV_BITS    command word length N (0: no quantiser)     -
    1              AV_LSB     least significant bit (0: no quantiser)     rad
    2              AV_ROUND   1 rounding to nearest, 0 truncation         -
    3              AV_NTAB    crossover gain table length n (0: unity)    -
    4 .. 4+n-1     AV_TABLE   table magnitudes |c|, increasing            rad
    4+n .. 4+2n-1             table gains                                 -
"""

AV_BITS = 0
AV_LSB = 1
AV_ROUND = 2
AV_NTAB = 3
AV_TABLE = 4
