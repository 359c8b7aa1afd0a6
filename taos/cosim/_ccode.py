"""C source emitted from the compiled kernels' own Python definitions (the standalone FMU's
dynamics; no second copy of any equation).

The planar kernels (:func:`taos.planar.dynamics._rk4_step` and ``_rates``, the avionics of
:mod:`taos.planar._avionics_kernels`, the limits of :mod:`taos.planar.saturation`, each
friction law's ``rates`` in :mod:`taos.friction`) are plain scalar Python that numba compiles:
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
* a function returning a tuple of k floats returns ``taos_tupk`` (``.v[0..k-1]``); tuple
  unpacking reads it; ``_`` targets are dropped.

Python semantics kept where C differs: true division ``/`` is always floating point, ``//``
and ``%`` on integers floor, ``max``/``min`` of two values are Python's (the first unless the
second is larger/smaller), ``int(x)`` truncates toward zero, ``abs`` is ``fabs`` or ``labs`` by
type. Anything outside this subset stops the translation with :class:`Untranslatable` naming
the construct and the kernel, so a kernel changed into something the translator cannot carry
fails the build, never the C.
"""

from __future__ import annotations

import ast
import inspect
import math
import textwrap
import types

_MATH = {"sqrt": "sqrt", "exp": "exp", "log": "log", "asin": "asin", "acos": "acos", "atan": "atan",
         "atan2": "atan2", "sin": "sin", "cos": "cos", "tan": "tan", "tanh": "tanh", "floor": "floor",
         "ceil": "ceil", "hypot": "hypot", "fabs": "fabs", "copysign": "copysign", "isfinite": "isfinite",
         "isnan": "isnan", "trunc": "trunc"}
_INT_RESULT = {"isfinite", "isnan"}
_BINOP = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*"}
_CMP = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}

PRELUDE = """#include <math.h>

/* tuples of floats returned by the kernels */
typedef struct { double v[2]; } taos_tup2;
typedef struct { double v[3]; } taos_tup3;
typedef struct { double v[4]; } taos_tup4;
/* Python's max/min of two values, floor division and modulo of integers */
static inline double taos_maxd(double a, double b) { return b > a ? b : a; }
static inline double taos_mind(double a, double b) { return b < a ? b : a; }
static inline long taos_maxl(long a, long b) { return b > a ? b : a; }
static inline long taos_minl(long a, long b) { return b < a ? b : a; }
static inline long taos_floordiv(long a, long b) { long q = a / b; return (q * b != a && ((a < 0) != (b < 0))) ? q - 1 : q; }
static inline long taos_mod(long a, long b) { long r = a % b; return (r != 0 && ((r < 0) != (b < 0))) ? r + b : r; }
"""


class Untranslatable(Exception):
    """A kernel uses Python outside the translated subset (module docstring)."""


class _Unknown(Exception):
    """A type that depends on a local whose type is not inferred yet (:meth:`_Func.infer_locals`)."""


def python_function(obj):
    """The Python function behind a kernel: a numba dispatcher's ``py_func``, a C callback's
    ``_pyfunc``, or the function itself."""
    for attr in ("py_func", "_pyfunc"):
        f = getattr(obj, attr, None)
        if f is not None:
            return f
    if isinstance(obj, types.FunctionType):
        return obj
    raise Untranslatable(f"{obj!r} is not a Python or numba function")


def kind_of(value):
    """The argument kind of a sample value: 'arr1'/'arr2' (float64 array), 'double', 'long', or
    ('fn', python function) for a kernel passed as an argument."""
    nd = getattr(value, "ndim", None)
    if nd is not None:
        if nd not in (1, 2):
            raise Untranslatable(f"a {nd}-D array argument")
        return f"arr{nd}"
    if isinstance(value, bool):
        return "long"
    if isinstance(value, int):
        return "long"
    if isinstance(value, float):
        return "double"
    return ("fn", python_function(value))


def _literal(v) -> str:
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, int):
        return str(v)
    if math.isnan(v):
        return "NAN"
    if math.isinf(v):
        return "INFINITY" if v > 0 else "(-INFINITY)"
    r = repr(float(v))
    return r if any(c in r for c in ".en") else r + ".0"


def _join(a: str, b: str) -> str:
    if a is None:
        return b
    if b is None or a == b:
        return a
    if {a, b} <= {"long", "double"}:
        return "double"
    raise Untranslatable(f"a local holding both {a} and {b}")


class _Func:
    """One specialisation being translated: its Python function, C name, parameter kinds."""

    def __init__(self, tr: Translator, fn, cname: str, kinds: tuple, static: bool):
        self.tr, self.fn, self.cname, self.kinds, self.static = tr, fn, cname, kinds, static
        src = textwrap.dedent(inspect.getsource(fn))
        tree = ast.parse(src)
        self.node = tree.body[0]
        if not isinstance(self.node, ast.FunctionDef):
            raise Untranslatable(f"{fn.__qualname__}: not a function definition")
        a = self.node.args
        if a.vararg or a.kwarg or a.kwonlyargs or a.defaults or a.posonlyargs:
            raise Untranslatable(f"{fn.__qualname__}: only plain positional arguments are translated")
        self.params = [p.arg for p in a.args]
        if len(self.params) != len(kinds):
            raise Untranslatable(f"{fn.__qualname__}: {len(kinds)} arguments for {len(self.params)} parameters")
        self.kind = dict(zip(self.params, kinds))
        self.globals = fn.__globals__
        #: every name the function assigns (its locals, typed by :meth:`infer_locals`)
        self.assigned = {n.id for n in ast.walk(self.node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        self.locals: dict[str, str] = {}
        self.ntmp = 0
        #: the C return type, known once translated (None while being translated)
        self.ret: str | None = None

    def where(self, node) -> str:
        return f"{self.fn.__module__}.{self.fn.__qualname__} line {self.fn.__code__.co_firstlineno + node.lineno - 1}"

    def fail(self, node, what: str):
        raise Untranslatable(f"{self.where(node)}: {what}")

    # -- names and types ---------------------------------------------------------------------
    def resolve(self, node):
        """The Python object a global name or a module attribute chain names (None: a local)."""
        if isinstance(node, ast.Name):
            if node.id in self.kind or node.id in self.assigned:
                return None
            if node.id in self.globals:
                return self.globals[node.id]
            import builtins
            if hasattr(builtins, node.id):
                return getattr(builtins, node.id)
            self.fail(node, f"unknown name {node.id!r}")
        if isinstance(node, ast.Attribute):
            base = self.resolve(node.value)
            if isinstance(base, types.ModuleType):
                return getattr(base, node.attr)
            return None
        return None

    def etype(self, e):
        if isinstance(e, ast.Constant):
            if isinstance(e.value, (bool, int)):
                return "long"
            if isinstance(e.value, float):
                return "double"
            self.fail(e, f"constant {e.value!r}")
        if isinstance(e, (ast.Name, ast.Attribute)):
            if isinstance(e, ast.Attribute) and e.attr == "shape":
                return "shape"
            g = self.resolve(e)
            if g is None:
                if isinstance(e, ast.Attribute):
                    self.fail(e, "an attribute of a local")
                k = self.kind.get(e.id) or self.locals.get(e.id)
                return k
            if isinstance(g, (bool, int)):
                return "long"
            if isinstance(g, float):
                return "double"
            self.fail(e, f"global {ast.unparse(e)!r} of type {type(g).__name__}")
        if isinstance(e, ast.Subscript):
            if isinstance(e.value, ast.Attribute) and e.value.attr == "shape":
                return "long"
            return "double"
        if isinstance(e, ast.BinOp):
            a, b = self.etype(e.left), self.etype(e.right)
            if a is None or b is None:
                return None
            if isinstance(e.op, (ast.Div, ast.Pow)):
                return "double"
            return "long" if a == b == "long" else "double"
        if isinstance(e, ast.UnaryOp):
            return "long" if isinstance(e.op, ast.Not) else self.etype(e.operand)
        if isinstance(e, (ast.Compare, ast.BoolOp)):
            return "long"
        if isinstance(e, ast.IfExp):
            a, b = self.etype(e.body), self.etype(e.orelse)
            return None if a is None or b is None else _join(a, b)
        if isinstance(e, ast.Call):
            return self.call(e)[1]
        self.fail(e, f"expression {type(e).__name__}")

    def infer_locals(self) -> None:
        """Every local's C type: the join of the types of the values assigned to it, iterated
        until no type changes (a local may be assigned from another)."""
        for _ in range(20):
            before = dict(self.locals)
            for node in ast.walk(self.node):
                if isinstance(node, ast.For):
                    self._bind(node.target, "long")
                elif isinstance(node, (ast.Assign, ast.AugAssign)):
                    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                    for t in targets:
                        if isinstance(t, ast.Name):
                            try:
                                ty = self.etype(node.value)
                            except _Unknown:
                                continue
                            if isinstance(node, ast.AugAssign):
                                ty = "double" if isinstance(node.op, (ast.Div, ast.Pow)) else \
                                    _join(ty, self.locals.get(t.id) or self.kind.get(t.id))
                            self._bind(t, ty)
                        elif isinstance(t, ast.Tuple):
                            for el in t.elts:
                                self._bind(el, "double")
            if before == self.locals:
                return
        raise Untranslatable(f"{self.fn.__qualname__}: local types do not settle")

    def _bind(self, target, ty) -> None:
        if not isinstance(target, ast.Name) or target.id == "_" or ty is None:
            return
        if target.id in self.kind:
            k = self.kind[target.id]
            if k not in ("double", "long"):
                self.fail(target, f"assignment to the array or function argument {target.id!r}")
            if k == "long" and ty == "double":
                self.fail(target, f"a float assigned to the integer argument {target.id!r}")
            return
        self.locals[target.id] = _join(self.locals.get(target.id), ty)

    # -- expressions -------------------------------------------------------------------------
    def expr(self, e) -> str:
        if isinstance(e, ast.Constant):
            return _literal(e.value)
        if isinstance(e, (ast.Name, ast.Attribute)):
            g = self.resolve(e)
            if g is None:
                if isinstance(e, ast.Attribute):
                    self.fail(e, "an attribute of a local")
                return e.id + "_"
            if isinstance(g, (bool, int, float)):
                return _literal(g)
            self.fail(e, f"{ast.unparse(e)!r} used as a value")
        if isinstance(e, ast.Subscript):
            return self.subscript(e)
        if isinstance(e, ast.BinOp):
            a, b = self.expr(e.left), self.expr(e.right)
            ta, tb = self.etype(e.left), self.etype(e.right)
            if type(e.op) in _BINOP:
                return f"({a} {_BINOP[type(e.op)]} {b})"
            if isinstance(e.op, ast.Div):
                return f"((double)({a}) / (double)({b}))"
            if isinstance(e.op, ast.Pow):
                return f"pow({a}, {b})"
            if isinstance(e.op, (ast.FloorDiv, ast.Mod)) and ta == tb == "long":
                return f"taos_{'floordiv' if isinstance(e.op, ast.FloorDiv) else 'mod'}({a}, {b})"
            self.fail(e, f"operator {type(e.op).__name__} on {ta}, {tb}")
        if isinstance(e, ast.UnaryOp):
            v = self.expr(e.operand)
            if isinstance(e.op, ast.USub):
                return f"(-{v})"
            if isinstance(e.op, ast.UAdd):
                return v
            if isinstance(e.op, ast.Not):
                return f"(!{v})"
            self.fail(e, f"unary {type(e.op).__name__}")
        if isinstance(e, ast.BoolOp):
            op = " && " if isinstance(e.op, ast.And) else " || "
            return "(" + op.join(self.expr(v) for v in e.values) + ")"
        if isinstance(e, ast.Compare):
            parts, left = [], e.left
            for op, right in zip(e.ops, e.comparators):
                if type(op) not in _CMP:
                    self.fail(e, f"comparison {type(op).__name__}")
                parts.append(f"({self.expr(left)} {_CMP[type(op)]} {self.expr(right)})")
                left = right
            return "(" + " && ".join(parts) + ")"
        if isinstance(e, ast.IfExp):
            return f"({self.expr(e.test)} ? {self.expr(e.body)} : {self.expr(e.orelse)})"
        if isinstance(e, ast.Call):
            return self.call(e)[0]
        self.fail(e, f"expression {type(e).__name__}")

    def subscript(self, e) -> str:
        v = e.value
        if isinstance(v, ast.Attribute) and v.attr == "shape":
            if not (isinstance(v.value, ast.Name) and self.kind.get(v.value.id) in ("arr1", "arr2")
                    and isinstance(e.slice, ast.Constant)):
                self.fail(e, "shape of something that is not an array argument")
            return f"{v.value.id}_s{e.slice.value}"
        if not isinstance(v, ast.Name) or self.kind.get(v.id) not in ("arr1", "arr2"):
            self.fail(e, "indexing of something that is not an array argument")
        if self.kind[v.id] == "arr1":
            if isinstance(e.slice, (ast.Tuple, ast.Slice)):
                self.fail(e, "a slice or a 2-D index of a 1-D array")
            return f"{v.id}_[{self.expr(e.slice)}]"
        if not (isinstance(e.slice, ast.Tuple) and len(e.slice.elts) == 2):
            self.fail(e, "a 2-D array indexed by other than [i, j]")
        i, j = (self.expr(x) for x in e.slice.elts)
        return f"{v.id}_[({i}) * {v.id}_s1 + ({j})]"

    def call(self, e):
        """(C text, C type) of a call."""
        if e.keywords:
            self.fail(e, "keyword arguments")
        f = e.func
        if isinstance(f, ast.Name) and f.id in self.kind:
            k = self.kind[f.id]
            if not (isinstance(k, tuple) and k[0] == "fn"):
                self.fail(e, f"call of the argument {f.id!r}, which is not a bound kernel")
            target = k[1]
        else:
            target = self.resolve(f)
        args = e.args
        if target is abs:
            t = self.etype(args[0])
            return (f"{'labs' if t == 'long' else 'fabs'}({self.expr(args[0])})", t)
        if target in (max, min):
            if len(args) != 2:
                self.fail(e, "max/min of other than two values")
            ts = [self.etype(a) for a in args]
            if None in ts:
                raise _Unknown
            t = "long" if all(x == "long" for x in ts) else "double"
            name = f"taos_{target.__name__}{'l' if t == 'long' else 'd'}"
            return (f"{name}({self.expr(args[0])}, {self.expr(args[1])})", t)
        if target is float:
            return (f"((double)({self.expr(args[0])}))", "double")
        if target is int:
            return (f"((long)({self.expr(args[0])}))", "long")
        mod = getattr(target, "__module__", None) or ""
        name = getattr(target, "__name__", "")
        if (mod == "math" or mod.startswith("numpy")) and name in _MATH:
            c = f"{_MATH[name]}({', '.join(self.expr(a) for a in args)})"
            return (c, "long" if name in _INT_RESULT else "double")
        try:
            pyf = python_function(target)
        except Untranslatable:
            self.fail(e, f"call of {ast.unparse(f)!r}")
        kinds, cargs = [], []
        for a in args:
            if isinstance(a, ast.Name) and a.id in self.kind and not isinstance(self.kind[a.id], str):
                kinds.append(self.kind[a.id])   # a bound kernel passed on: no C argument
                continue
            if isinstance(a, ast.Name) and self.kind.get(a.id) in ("arr1", "arr2"):
                k = self.kind[a.id]
                kinds.append(k)
                cargs += [f"{a.id}_", f"{a.id}_s0"] + ([f"{a.id}_s1"] if k == "arr2" else [])
                continue
            t = self.etype(a)
            if t is None:
                raise _Unknown
            if t not in ("long", "double"):
                self.fail(a, f"argument of type {t}")
            kinds.append(t)
            cargs.append(self.expr(a))
        spec = self.tr.specialise(pyf, tuple(kinds))
        return (f"{spec.cname}({', '.join(cargs)})", spec.ret)

    # -- statements --------------------------------------------------------------------------
    def body(self, stmts, ind: int) -> list[str]:
        out = []
        for s in stmts:
            out += self.stmt(s, ind)
        return out

    def stmt(self, s, ind: int) -> list[str]:
        p = "    " * ind
        if isinstance(s, ast.Expr):
            if isinstance(s.value, ast.Constant) and isinstance(s.value.value, str):
                return []   # a docstring
            if isinstance(s.value, ast.Call):
                return [f"{p}{self.expr(s.value)};"]
            self.fail(s, "an expression statement that is not a call")
        if isinstance(s, ast.Pass):
            return []
        if isinstance(s, (ast.Break, ast.Continue)):
            return [f"{p}{'break' if isinstance(s, ast.Break) else 'continue'};"]
        if isinstance(s, ast.Assign):
            if len(s.targets) != 1:
                self.fail(s, "chained assignment")
            t = s.targets[0]
            if isinstance(t, ast.Tuple):
                return self.unpack(t, s.value, p)
            if isinstance(t, ast.Name) and t.id == "_":
                return [f"{p}(void){self.expr(s.value)};"]
            return [f"{p}{self.expr(t)} = {self.expr(s.value)};"]
        if isinstance(s, ast.AugAssign):
            if type(s.op) not in _BINOP and not isinstance(s.op, ast.Div):
                self.fail(s, f"augmented {type(s.op).__name__}")
            op = "/" if isinstance(s.op, ast.Div) else _BINOP[type(s.op)]
            return [f"{p}{self.expr(s.target)} {op}= {self.expr(s.value)};"]
        if isinstance(s, ast.If):
            out = [f"{p}if ({self.expr(s.test)}) {{"] + self.body(s.body, ind + 1)
            if s.orelse:
                out += [f"{p}}} else {{"] + self.body(s.orelse, ind + 1)
            return out + [f"{p}}}"]
        if isinstance(s, ast.While):
            if s.orelse:
                self.fail(s, "while ... else")
            return [f"{p}while ({self.expr(s.test)}) {{"] + self.body(s.body, ind + 1) + [f"{p}}}"]
        if isinstance(s, ast.For):
            return self.for_range(s, p, ind)
        if isinstance(s, ast.Return):
            return self.return_stmt(s, p)
        self.fail(s, f"statement {type(s).__name__}")

    def for_range(self, s, p, ind):
        it = s.iter
        if (s.orelse or not isinstance(s.target, ast.Name) or not isinstance(it, ast.Call)
                or self.resolve(it.func) is not range or not 1 <= len(it.args) <= 3):
            self.fail(s, "a loop other than 'for i in range(...)'")
        a = [self.expr(x) for x in it.args]
        lo, hi, st = ("0", a[0], "1") if len(a) == 1 else (a[0], a[1], a[2] if len(a) == 3 else "1")
        if len(a) == 3 and not (isinstance(it.args[2], ast.Constant) and it.args[2].value > 0):
            self.fail(s, "a range with a step that is not a positive constant")
        v = s.target.id + "_"
        return ([f"{p}for ({v} = {lo}; {v} < {hi}; {v} += {st}) {{"] + self.body(s.body, ind + 1) + [f"{p}}}"])

    def unpack(self, t, value, p):
        names = [el.id if isinstance(el, ast.Name) else self.fail(el, "unpacking into other than names")
                 for el in t.elts]
        tmp = f"t{self.ntmp}_"
        self.ntmp += 1
        if isinstance(value, ast.Tuple):
            if len(value.elts) != len(names):
                self.fail(value, "tuple lengths differ")
            decl = [f"double {tmp}{i} = {self.expr(v)};" for i, v in enumerate(value.elts)]
            sets = [f"{n}_ = {tmp}{i};" for i, n in enumerate(names) if n != "_"]
            return [f"{p}{{ " + " ".join(decl + sets) + " }"]
        code, ty = self.call(value) if isinstance(value, ast.Call) else self.fail(value, "unpacking a non-call")
        if ty != f"taos_tup{len(names)}":
            self.fail(value, f"unpacking {len(names)} names from {ty}")
        sets = [f"{n}_ = {tmp}.v[{i}];" for i, n in enumerate(names) if n != "_"]
        return [f"{p}{{ {ty} {tmp} = {code}; " + " ".join(sets) + " }"]

    def return_stmt(self, s, p):
        if s.value is None:
            return [f"{p}return;"]
        if isinstance(s.value, ast.Tuple):
            return [f"{p}return ({self.ret_type()}){{{{{', '.join(self.expr(v) for v in s.value.elts)}}}}};"]
        return [f"{p}return {self.expr(s.value)};"]

    def ret_type(self) -> str:
        """The C return type: the tuple of the first tuple ``return``, else the join of the
        returned values' types, else void."""
        tys = None
        for node in ast.walk(self.node):
            if isinstance(node, ast.Return) and node.value is not None:
                if isinstance(node.value, ast.Tuple):
                    return f"taos_tup{len(node.value.elts)}"
                t = self.etype(node.value)
                if isinstance(t, str) and t.startswith("taos_tup"):
                    return t
                tys = _join(tys, t)
        return tys or "void"

    def translate(self) -> str:
        self.infer_locals()
        ret = self.ret_type()
        sig = ", ".join(self.param_decls()) or "void"
        decls = [f"    {t} {n}_ = 0;" for n, t in sorted(self.locals.items()) if t in ("long", "double")]
        body = self.body(self.node.body, 1)
        self.ret = ret
        head = f"{'static ' if self.static else ''}{ret} {self.cname}({sig})"
        self.prototype = head + ";"
        doc = f"/* {self.fn.__module__}.{self.fn.__qualname__} */"
        return "\n".join([doc, head + " {"] + decls + body + ["}"])

    def param_decls(self) -> list[str]:
        out = []
        for n in self.params:
            k = self.kind[n]
            if k in ("double", "long"):
                out.append(f"{k} {n}_")
            elif k == "arr1":
                out += [f"double *{n}_", f"long {n}_s0"]
            elif k == "arr2":
                out += [f"double *{n}_", f"long {n}_s0", f"long {n}_s1"]
        return out


class Translator:
    """Translates kernels and every kernel they call into one C source (module docstring)."""

    def __init__(self):
        self._specs: dict = {}
        self._order: list[_Func] = []
        self._code: dict[int, str] = {}
        self._names: set[str] = set()

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

    def entry(self, kernel, samples: tuple, cname: str) -> _Func:
        """Translate ``kernel`` as the exported C function ``cname`` for arguments like
        ``samples`` (values whose kinds fix the specialisation: arrays, floats, ints, kernels)."""
        return self.specialise(python_function(kernel), tuple(kind_of(v) for v in samples), cname, static=False)

    def source(self) -> str:
        """The C source: the prelude, every static prototype, then every function (callees first)."""
        protos = [s.prototype for s in self._order if s.static]
        return "\n".join([PRELUDE] + protos + [""] + [self._code[id(s)] + "\n" for s in self._order])

    def header(self) -> str:
        """Prototypes of the exported entries (and the tuple types)."""
        tups = PRELUDE.split("/* Python's")[0].replace("#include <math.h>\n", "")
        return "\n".join([tups] + [s.prototype for s in self._order if not s.static]) + "\n"
