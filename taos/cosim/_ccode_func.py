"""One kernel specialisation translated to C (:class:`_Func`) and the translator's value kinds:
the subset of Python and its C form are described in :mod:`taos.cosim._ccode`."""

from __future__ import annotations

import ast
import builtins
import inspect
import math
import textwrap
import types

from ._ccode_stmt import _ARRAY, _BINOP, _SCALAR, NDIM, Untranslatable, _join, _Statements, is_tup

_MATH = {"sqrt": "sqrt", "exp": "exp", "log": "log", "asin": "asin", "acos": "acos", "atan": "atan",
         "atan2": "atan2", "sin": "sin", "cos": "cos", "tan": "tan", "tanh": "tanh", "floor": "floor",
         "ceil": "ceil", "hypot": "hypot", "fabs": "fabs", "copysign": "copysign", "isfinite": "isfinite",
         "isnan": "isnan", "trunc": "trunc"}
_INT_RESULT = {"isfinite", "isnan"}
_CMP = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==", ast.NotEq: "!="}


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


def is_kernel(obj) -> bool:
    return getattr(obj, "py_func", None) is not None or getattr(obj, "_pyfunc", None) is not None or \
        isinstance(obj, types.FunctionType)


def kind_of(value):
    """The argument kind of a sample value: 'arr1'/'arr2'/'arr3' (float64 array), 'iarr1' (a
    1-D int64 array), 'double', 'long',
    'taos_tupN' (a tuple of N numbers), ('nt', class, field kinds) (a named tuple),
    ('fn', python function) (a kernel passed as an argument) or ('fns', functions) (a tuple of
    kernels)."""
    nd = getattr(value, "ndim", None)
    if nd is not None:
        if value.dtype.kind in "iu":
            if nd != 1 or value.dtype.itemsize != 8:
                raise Untranslatable(f"a {nd}-D {value.dtype} array argument")
            return "iarr1"
        if nd not in (1, 2, 3):
            raise Untranslatable(f"a {nd}-D array argument")
        return f"arr{nd}"
    if isinstance(value, (bool, int)):
        return "long"
    if isinstance(value, float):
        return "double"
    if isinstance(value, tuple) and hasattr(type(value), "_fields"):
        return ("nt", type(value), tuple(kind_of(getattr(value, f)) for f in type(value)._fields))
    if isinstance(value, tuple):
        kinds = tuple(kind_of(v) for v in value)
        if kinds and all(isinstance(k, tuple) and k[0] == "fn" for k in kinds):
            return ("fns", tuple(k[1] for k in kinds))
        if kinds and all(k in _SCALAR for k in kinds):
            return f"taos_tup{len(kinds)}"
        raise Untranslatable(f"a tuple argument of kinds {kinds}")
    return ("fn", python_function(value))


def literal(v) -> str:
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


class _Func(_Statements):
    """One specialisation being translated: its Python function, C name, parameter kinds."""

    def __init__(self, tr, fn, cname: str, kinds: tuple, static: bool):
        self.tr, self.fn, self.cname, self.kinds, self.static = tr, fn, cname, kinds, static
        self.node = ast.parse(textwrap.dedent(inspect.getsource(fn))).body[0]
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
        #: locals bound to a kernel (``fid, zdot3, torque3 = fk``): no C variable
        self.fnloc: dict[str, object] = {}
        self.ntmp = 0
        #: the C return type, known once translated (None while being translated)
        self.ret: str | None = None

    def where(self, node) -> str:
        return f"{self.fn.__module__}.{self.fn.__qualname__} line {self.fn.__code__.co_firstlineno + node.lineno - 1}"

    def fail(self, node, what: str):
        raise Untranslatable(f"{self.where(node)}: {what}")

    def tmp(self) -> str:
        self.ntmp += 1
        return f"_t{self.ntmp}"   # no trailing underscore: never a local's C name

    # -- names, kinds, arrays ----------------------------------------------------------------
    def resolve(self, node):
        """The Python object a global name or a module attribute chain names (None: a local or
        something of a local)."""
        if isinstance(node, ast.Name):
            if node.id in self.kind or node.id in self.assigned:
                return None
            if node.id in self.globals:
                return self.globals[node.id]
            if hasattr(builtins, node.id):
                return getattr(builtins, node.id)
            self.fail(node, f"unknown name {node.id!r}")
        if isinstance(node, ast.Attribute):
            base = self.resolve(node.value)
            if isinstance(base, types.ModuleType):
                return getattr(base, node.attr)
        return None

    def field(self, e):
        """(C lvalue, kind) of ``P.name`` for a named-tuple argument ``P``, else None."""
        if isinstance(e, ast.Attribute) and isinstance(e.value, ast.Name):
            k = self.kind.get(e.value.id)
            if isinstance(k, tuple) and k[0] == "nt":
                fields = k[1]._fields
                if e.attr not in fields:
                    self.fail(e, f"{k[1].__name__} has no field {e.attr!r}")
                return f"{e.value.id}_->{e.attr}", k[2][fields.index(e.attr)]
        return None

    def arr(self, e):
        """(ndim, base pointer, shape 0, shape 1, shape 2, kind) of an array expression (an
        argument, an array local, a named tuple's array field, a row ``a[i]`` of a 2-D array, a
        matrix ``a[i]`` of a 3-D one), else None."""
        if isinstance(e, ast.Name):
            k = self.kind.get(e.id) or self.locals.get(e.id)
            if k in _ARRAY:
                n = e.id
                return NDIM[k], f"{n}_", f"{n}_s0", f"{n}_s1", f"{n}_s2", k
            return None
        f = self.field(e)
        if f is not None:
            c, k = f
            return (NDIM[k], c, f"{c}_s0", f"{c}_s1", None, k) if k in ("arr1", "arr2") else None
        if isinstance(e, ast.Subscript) and not isinstance(e.slice, (ast.Tuple, ast.Slice)):
            a = self.arr(e.value)
            if a is not None and a[0] == 2:
                return 1, f"({a[1]} + ({self.expr(e.slice)}) * {a[3]})", a[3], None, None, "arr1"
            if a is not None and a[0] == 3:
                return 2, f"({a[1]} + ({self.expr(e.slice)}) * {a[3]} * {a[4]})", a[3], a[4], None, "arr2"
        return None

    def fn_of(self, e):
        """The Python function of a kernel expression (an argument, a local bound to one, a
        global kernel), else None."""
        if isinstance(e, ast.Name):
            k = self.kind.get(e.id)
            if isinstance(k, tuple) and k[0] == "fn":
                return k[1]
            if e.id in self.fnloc:
                return self.fnloc[e.id]
        if isinstance(e, (ast.Name, ast.Attribute)):
            g = self.resolve(e)
            if g is not None and not isinstance(g, (int, float, types.ModuleType)) and is_kernel(g) \
                    and getattr(g, "__module__", "") != "math":
                return python_function(g)
        return None

    def etype(self, e):
        """The kind of an expression: 'long', 'double', 'arr1', 'arr2', 'taos_tupN', 'fn', an
        argument's own kind, or None while a local's type is unknown."""
        if isinstance(e, ast.Constant):
            if isinstance(e.value, (bool, int)):
                return "long"
            if isinstance(e.value, float):
                return "double"
            self.fail(e, f"constant {e.value!r}")
        if isinstance(e, ast.Name) and (e.id in self.kind or e.id in self.assigned):
            if e.id in self.fnloc:
                return "fn"
            k = self.kind.get(e.id)
            if k is not None:
                return "fn" if isinstance(k, tuple) and k[0] == "fn" else k
            return self.locals.get(e.id)
        if isinstance(e, ast.Attribute) and e.attr == "shape":
            return "shape"
        f = self.field(e)
        if f is not None:
            return f[1]
        if isinstance(e, (ast.Name, ast.Attribute)):
            g = self.resolve(e)
            if g is None:
                self.fail(e, "an attribute of a local")
            if isinstance(g, (bool, int)):
                return "long"
            if isinstance(g, float):
                return "double"
            if self.fn_of(e) is not None:
                return "fn"
            self.fail(e, f"global {ast.unparse(e)!r} of type {type(g).__name__}")
        if isinstance(e, ast.Subscript):
            if isinstance(e.value, ast.Attribute) and e.value.attr == "shape":
                return "long"
            a = self.arr(e.value)
            if a is not None and a[0] >= 2 and not isinstance(e.slice, ast.Tuple):
                return f"arr{a[0] - 1}"
            return "long" if a is not None and a[5] == "iarr1" else "double"
        if isinstance(e, ast.Tuple):
            ts = [self.etype(x) for x in e.elts]
            if None in ts:
                return None
            if all(t in _SCALAR for t in ts):
                return f"taos_tup{len(ts)}"
            self.fail(e, f"a tuple of {ts} used as a value")
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
            return "arr1" if self.alloc(e) is not None else self.call(e)[1]
        self.fail(e, f"expression {type(e).__name__}")

    def infer_locals(self) -> None:
        """Every local's kind: the join of the kinds of the values assigned to it, iterated
        until no kind changes (a local may be assigned from another)."""
        for _ in range(20):
            before = (dict(self.locals), dict(self.fnloc))
            for node in ast.walk(self.node):
                if isinstance(node, ast.For):
                    self._bind(node.target, "long")
                elif isinstance(node, (ast.Assign, ast.AugAssign)):
                    targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                    for t in targets:
                        try:
                            self._infer_target(node, t)
                        except _Unknown:
                            continue
            if before == (self.locals, self.fnloc):
                return
        raise Untranslatable(f"{self.fn.__qualname__}: local types do not settle")

    def _infer_target(self, node, t) -> None:
        v = node.value
        if isinstance(t, ast.Name):
            ty = self.etype(v)
            if ty == "fn":
                self.fnloc[t.id] = self.fn_of(v)
                return
            if isinstance(node, ast.AugAssign):
                ty = "double" if isinstance(node.op, (ast.Div, ast.Pow)) else \
                    _join(ty, self.locals.get(t.id) or self.kind.get(t.id))
            self._bind(t, ty)
        elif isinstance(t, ast.Tuple):
            k = self.kind.get(v.id) if isinstance(v, ast.Name) else None
            if isinstance(k, tuple) and k[0] == "fns":
                for el, f in zip(t.elts, k[1]):
                    if isinstance(el, ast.Name):
                        self.fnloc[el.id] = f
            elif isinstance(v, ast.Tuple) and len(v.elts) == len(t.elts):
                for el, x in zip(t.elts, v.elts):
                    ty = self.etype(x)
                    if ty == "fn" and isinstance(el, ast.Name):
                        self.fnloc[el.id] = self.fn_of(x)
                    else:
                        self._bind(el, ty)
            else:
                for el in t.elts:
                    self._bind(el, "double")

    def _bind(self, target, ty) -> None:
        if not isinstance(target, ast.Name) or target.id == "_" or ty is None:
            return
        if target.id in self.kind:
            k = self.kind[target.id]
            if k not in _SCALAR:
                self.fail(target, f"assignment to the array, tuple or function argument {target.id!r}")
            if k == "long" and ty == "double":
                self.fail(target, f"a float assigned to the integer argument {target.id!r}")
            return
        if not (ty in _SCALAR or ty in _ARRAY or is_tup(ty)):
            self.fail(target, f"a local of kind {ty}")
        self.locals[target.id] = _join(self.locals.get(target.id), ty)

    # -- expressions -------------------------------------------------------------------------
    def expr(self, e) -> str:
        if isinstance(e, ast.Constant):
            return literal(e.value)
        f = self.field(e)
        if f is not None:
            if f[1] not in _SCALAR:
                self.fail(e, f"the field {ast.unparse(e)!r} used as a value")
            return f[0]
        if isinstance(e, (ast.Name, ast.Attribute)):
            g = self.resolve(e)
            if g is None:
                if isinstance(e, ast.Attribute):
                    self.fail(e, "an attribute of a local")
                if self.etype(e) in _ARRAY or e.id in self.fnloc:
                    self.fail(e, f"the array or kernel {e.id!r} used as a value")
                return e.id + "_"
            if isinstance(g, (bool, int, float)):
                return literal(g)
            self.fail(e, f"{ast.unparse(e)!r} used as a value")
        if isinstance(e, ast.Subscript):
            return self.subscript(e)
        if isinstance(e, ast.Tuple):
            return f"(({self.etype(e)}){{{{{', '.join(self.expr(x) for x in e.elts)}}}}})"
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
            a = self.arr(v.value)
            if a is None or not isinstance(e.slice, ast.Constant) or e.slice.value not in range(a[0]):
                self.fail(e, "shape of something that is not an array")
            return a[2 + e.slice.value]
        if is_tup(self.etype(v)):
            if isinstance(e.slice, (ast.Tuple, ast.Slice)):
                self.fail(e, "a slice or a 2-D index of a tuple")
            return f"{self.expr(v)}.v[{self.expr(e.slice)}]"
        a = self.arr(v)
        if a is None:
            self.fail(e, "indexing of something that is not an array or a tuple of numbers")
        if a[0] == 3:
            self.fail(e, "an element of a 3-D array (index its matrices: a[i])")
        if a[0] == 1:
            if isinstance(e.slice, (ast.Tuple, ast.Slice)):
                self.fail(e, "a slice or a 2-D index of a 1-D array")
            return f"{a[1]}[{self.expr(e.slice)}]"
        if not (isinstance(e.slice, ast.Tuple) and len(e.slice.elts) == 2):
            self.fail(e, "a 2-D array indexed by other than [i, j] used as a number")
        i, j = (self.expr(x) for x in e.slice.elts)
        return f"{a[1]}[({i}) * {a[3]} + ({j})]"

    def call(self, e):
        """(C text, C type) of a call."""
        if e.keywords:
            self.fail(e, "keyword arguments")
        f = e.func
        target = self.fn_of(f) if isinstance(f, ast.Name) and (f.id in self.kind or f.id in self.fnloc) \
            else self.resolve(f)
        if target is None:
            self.fail(e, f"call of {ast.unparse(f)!r}, which is not a bound kernel")
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
            return (f"taos_{target.__name__}{'l' if t == 'long' else 'd'}({self.expr(args[0])}, "
                    f"{self.expr(args[1])})", t)
        if target is float:
            return (f"((double)({self.expr(args[0])}))", "double")
        if target is int:
            return (f"((long)({self.expr(args[0])}))", "long")
        if target is bool:
            return (f"((long)(({self.expr(args[0])}) != 0))", "long")
        mod = getattr(target, "__module__", None) or ""
        name = getattr(target, "__name__", "")
        if (mod == "math" or mod.startswith("numpy")) and name in _MATH:
            return (f"{_MATH[name]}({', '.join(self.expr(a) for a in args)})",
                    "long" if name in _INT_RESULT else "double")
        try:
            pyf = python_function(target)
        except Untranslatable:
            self.fail(e, f"call of {ast.unparse(f)!r}")
        kinds, cargs = [], []
        for a in args:
            k = self.kind.get(a.id) if isinstance(a, ast.Name) else None
            if isinstance(k, tuple) and k[0] in ("fns", "nt"):
                kinds.append(k)   # a tuple of kernels: bound, no C argument; a named tuple: its pointer
                if k[0] == "nt":
                    cargs.append(f"{a.id}_")
                continue
            fk = self.fn_of(a)
            if fk is not None:
                kinds.append(("fn", fk))   # a bound kernel passed on: no C argument
                continue
            ar = self.arr(a)
            if ar is not None:
                kinds.append(ar[5])
                cargs += list(ar[1:2 + ar[0]])
                continue
            t = self.etype(a)
            if t is None:
                raise _Unknown
            if not (t in _SCALAR or is_tup(t)):
                self.fail(a, f"argument of kind {t}")
            kinds.append(t)
            cargs.append(self.expr(a))
        spec = self.tr.specialise(pyf, tuple(kinds))
        return (f"{spec.cname}({', '.join(cargs)})", spec.ret)

    def translate(self) -> str:
        self.infer_locals()
        ret = self.ret_type()
        sig = ", ".join(self.param_decls()) or "void"
        decls = []
        for n, t in sorted(self.locals.items()):
            if t in _SCALAR:
                decls.append(f"    {t} {n}_ = 0;")
            elif is_tup(t):
                decls.append(f"    {t} {n}_ = {{{{0}}}};")
            elif t in _ARRAY:
                decls.append(f"    {'long' if t == 'iarr1' else 'double'} *{n}_ = 0;"
                             + "".join(f" long {n}_s{d} = 0;" for d in range(NDIM[t])))
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
            if k in _SCALAR or is_tup(k):
                out.append(f"{k} {n}_")
            elif k in _ARRAY:
                out += [f"{'long' if k == 'iarr1' else 'double'} *{n}_"] + [f"long {n}_s{d}" for d in range(NDIM[k])]
            elif k[0] == "nt":
                out.append(f"{self.tr.struct(k)} *{n}_")
        return out
