"""C source emitted from the compiled kernels' own Python definitions (the standalone FMU's
dynamics; no second copy of any equation).

The planar kernels (:func:`taos.planar.dynamics._rk4_step` and ``_rates``, the avionics of
:mod:`taos.planar._avionics_kernels`, the limits of :mod:`taos.planar.saturation`, each
friction law's ``rates`` in :mod:`taos.friction`) and the 3-D ones (:func:`taos.taos3d.dynamics._steps`
with the right-hand side, the SO(3) maps, the bearing's BDF2 substeps and each law's vector
bearing step of :mod:`taos.friction._vector`) are plain scalar Python that numba compiles:
float and integer arithmetic, ``if``/``elif``/``else``, ``for ... in range``, ``while``,
``math`` calls, indexing of float64 arrays, calls of other kernels and tuples of floats as
results. :class:`Translator` reads that Python source (a numba dispatcher's ``py_func``, a C
callback's ``_pyfunc``) and writes the same statements as C99, one C function per kernel and
argument kinds ("specialisation", as numba compiles one machine function per argument types):

* a float64 array argument ``x`` becomes ``double *x_`` with its shape ``long x_s0`` (and
  ``x_s1`` for 2-D, row-major, C-contiguous); ``x.shape[k]`` is ``x_sk``;
* a function argument (the friction law ``fid``) is bound at translation time: the call is a
  direct call of the bound kernel's C translation;
* a local is ``long`` if every value assigned to it is an integer (``range`` counters,
  ``int(...)``, integer constants and their sums), else ``double``; a module constant (a
  ``SLOT_*``, ``LIM_*``, ``AV_*`` slot, ``math.pi``) is written as its literal value;
* a function returning a tuple of k numbers returns ``taos_tupk`` (``.v[0..k-1]``); tuple
  unpacking reads it (into names or array elements); ``_`` targets are dropped; a tuple of
  numbers is also a value: an argument, a local (``R = _rotation(...)``), indexed by a constant
  or a runtime integer (``R[0]``, ``KLt[a]``);
* a named tuple argument (the 3-D model :class:`taos.taos3d._layout.TaosParams`) is a pointer to a
  generated C struct ``taos_nt_<Name>`` with one member per field (an array field as pointer
  and shapes ``<f>_s0``, ``<f>_s1``); ``P.field`` reads it;
* an array local (``Aa = P.act_A``, ``ko = k1``, the row ``k1 = ks[0]`` of a 2-D array) is a
  pointer and its shapes, reassigned by assignment (no copy: numba's views);
* a tuple of kernels (the friction law's ``fid`` = (bearing_step, zdot3, torque3)) is bound at
  translation time like a single kernel, as is a kernel passed by its global name
  (``coeff_bearing_step(lugre_coeffs, ...)``) and a local unpacked from such a tuple;

numba's fast-math flags of the 3-D kernels (reassociation, contraction) are not copied: the C
is compiled with standard IEEE arithmetic, so the 3-D results differ from numba's at the rounding
level (measured in tests/test_fmu_taos3d.py). Python semantics kept where C differs: true division ``/`` is always floating point, ``//``
and ``%`` on integers floor, ``max``/``min`` of two values are Python's (the first unless the
second is larger/smaller), ``int(x)`` truncates toward zero, ``abs`` is ``fabs`` or ``labs`` by
type. Anything outside this subset stops the translation with :class:`Untranslatable` naming
the construct and the kernel, so a kernel changed into something the translator cannot carry
fails the build, never the C.
"""

from __future__ import annotations

from ._ccode_func import Untranslatable, _Func, kind_of, python_function

__all__ = ["Translator", "Untranslatable", "kind_of", "python_function"]

PRELUDE = """#include <math.h>

/* Python's max/min of two values, floor division and modulo of integers */
static inline double taos_maxd(double a, double b) { return b > a ? b : a; }
static inline double taos_mind(double a, double b) { return b < a ? b : a; }
static inline long taos_maxl(long a, long b) { return b > a ? b : a; }
static inline long taos_minl(long a, long b) { return b < a ? b : a; }
static inline long taos_floordiv(long a, long b) { long q = a / b; return (q * b != a && ((a < 0) != (b < 0))) ? q - 1 : q; }
static inline long taos_mod(long a, long b) { long r = a % b; return (r != 0 && ((r < 0) != (b < 0))) ? r + b : r; }
"""


class Translator:
    """Translates kernels and every kernel they call into one C source (module docstring)."""

    def __init__(self):
        self._specs: dict = {}
        self._order: list[_Func] = []
        self._code: dict[int, str] = {}
        self._names: set[str] = set()
        self._structs: dict = {}

    def specialise(self, pyf, kinds: tuple, cname: str | None = None, static: bool = True) -> _Func:
        """The translation of ``pyf`` for argument ``kinds`` (made once per kinds)."""
        key = (pyf, kinds)
        spec = self._specs.get(key)
        if spec is not None:
            if spec.ret is None:
                raise Untranslatable(f"{pyf.__qualname__}: recursive kernels are not translated")
            return spec
        if cname is None:
            base = f"taos_{pyf.__module__.rsplit('.', 1)[-1].strip('_')}_{pyf.__name__.strip('_')}"
            cname, i = base, 1
            while cname in self._names:
                i += 1
                cname = f"{base}_{i}"
        self._names.add(cname)
        spec = _Func(self, pyf, cname, kinds, static)
        self._specs[key] = spec
        code = spec.translate()
        self._code[id(spec)] = code
        self._order.append(spec)
        return spec

    def struct(self, kind) -> str:
        """The C struct type of a named-tuple kind ('nt', class, field kinds), declared once."""
        _, cls, fk = kind
        name = f"taos_nt_{cls.__name__}"
        if self._structs.setdefault(name, kind) != kind:
            raise Untranslatable(f"{cls.__name__} passed with two different field kinds")
        return name

    def types(self) -> str:
        """The tuple and named-tuple struct typedefs the translated code uses."""
        import re

        code = "\n".join(self._code.values())
        sizes = sorted({2, 3, 4} | {int(n) for n in re.findall(r"taos_tup(\d+)", code)})
        out = ["/* tuples of numbers (the kernels' tuple values) */"]
        out += [f"typedef struct {{ double v[{n}]; }} taos_tup{n};" for n in sizes]
        for name, (_, cls, fk) in self._structs.items():
            out.append(f"/* {cls.__module__}.{cls.__qualname__} */")
            out.append("typedef struct {")
            for f, k in zip(cls._fields, fk):
                if k in ("double", "long"):
                    out.append(f"    {k} {f};")
                elif k in ("arr1", "arr2"):
                    out.append(f"    double *{f}; long {f}_s0; long {f}_s1;")
                else:
                    raise Untranslatable(f"{cls.__name__}.{f}: a field of kind {k}")
            out.append(f"}} {name};")
        return "\n".join(out) + "\n"

    def entry(self, kernel, samples: tuple, cname: str) -> _Func:
        """Translate ``kernel`` as the exported C function ``cname`` for arguments like
        ``samples`` (values whose kinds fix the specialisation: arrays, floats, ints, kernels)."""
        return self.specialise(python_function(kernel), tuple(kind_of(v) for v in samples), cname, static=False)

    def source(self) -> str:
        """The C source: the prelude, every static prototype, then every function (callees first)."""
        protos = [s.prototype for s in self._order if s.static]
        return "\n".join([PRELUDE, self.types()] + protos + [""] + [self._code[id(s)] + "\n" for s in self._order])

    def header(self) -> str:
        """Prototypes of the exported entries (and the tuple types)."""
        return "\n".join([self.types()] + [s.prototype for s in self._order if not s.static]) + "\n"
