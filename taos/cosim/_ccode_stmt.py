"""The statements of a kernel translated to C (the :class:`taos.cosim._ccode_func._Func` mixin;
the subset is described in :mod:`taos.cosim._ccode`)."""

from __future__ import annotations

import ast

_BINOP = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*"}
_SCALAR = ("long", "double")
_ARRAY = ("arr1", "arr2", "arr3", "iarr1")
#: dimensions of each array kind ('iarr1': a 1-D int64 array, ``long *``)
NDIM = {"arr1": 1, "arr2": 2, "arr3": 3, "iarr1": 1}


class Untranslatable(Exception):
    """A kernel uses Python outside the translated subset (:mod:`taos.cosim._ccode`)."""


def is_tup(t) -> bool:
    return isinstance(t, str) and t.startswith("taos_tup")


def _join(a, b):
    if a is None:
        return b
    if b is None or a == b:
        return a
    if {a, b} <= set(_SCALAR):
        return "double"
    raise Untranslatable(f"a local holding both {a} and {b}")


class _Statements:
    """Statements, assignments, loops and returns of :class:`taos.cosim._ccode_func._Func`."""

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
            if self.alloc(s.value) is not None:
                return self.allocate(t, s.value, p, ind)
            if isinstance(t, ast.Subscript) and all(isinstance(x, ast.Slice) and x.lower is None and x.upper is None
                                                    and x.step is None for x in
                                                    (t.slice.elts if isinstance(t.slice, ast.Tuple) else [t.slice])):
                return self.fill(t, s.value, p)
            if isinstance(t, ast.Tuple):
                return self.unpack(t, s.value, p)
            if isinstance(t, ast.Name) and t.id == "_":
                return [f"{p}(void){self.expr(s.value)};"]
            return [p + x for x in self.assign(t, s.value)]
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

    def alloc(self, v):
        """The size expression of ``np.empty(n)`` / ``np.zeros(n)`` (a 1-D float64 array), else None."""
        if isinstance(v, ast.Call) and len(v.args) == 1 and not v.keywords and isinstance(v.func, ast.Attribute):
            g = self.resolve(v.func)
            if (getattr(g, "__module__", None) or "").startswith("numpy") and getattr(g, "__name__", "") in ("empty", "zeros"):
                return v.args[0]
        return None

    def allocate(self, t, v, p, ind) -> list[str]:
        """``x = np.empty(n)`` / ``np.zeros(n)``: a C99 variable-length array of this call (so at
        the function's top level only: its storage lives until the function returns)."""
        if ind != 1 or not isinstance(t, ast.Name) or self.locals.get(t.id) != "arr1":
            self.fail(v, "an array allocation other than 'name = np.empty(n)' at the function's top level")
        buf, n = self.tmp(), self.tmp()
        out = [f"{p}long {n} = {self.expr(self.alloc(v))};", f"{p}double {buf}[{n} > 0 ? {n} : 1];",
               f"{p}{t.id}_ = {buf}; {t.id}_s0 = {n};"]
        if self.resolve(v.func).__name__ == "zeros":
            out.append(f"{p}for (long {n}_i = 0; {n}_i < {n}; {n}_i++) {buf}[{n}_i] = 0.0;")
        return out

    def fill(self, t, v, p) -> list[str]:
        """``a[:] = value`` / ``a[:, :] = value`` (every element of an array set to one number)."""
        a = self.arr(t.value)
        nd = len(t.slice.elts) if isinstance(t.slice, ast.Tuple) else 1
        if a is None or a[0] != nd or nd > 2 or self.etype(v) not in _SCALAR:
            self.fail(t, "a slice assignment other than every element of an array set to a number")
        i = self.tmp()
        size = a[2] if nd == 1 else f"{a[2]} * {a[3]}"
        return [f"{p}for (long {i} = 0; {i} < {size}; {i}++) {a[1]}[{i}] = {self.expr(v)};"]

    def assign(self, t, v) -> list[str]:
        """C statements of ``t = v`` for one target (an array local takes the pointer and shape)."""
        if isinstance(t, ast.Name) and t.id in self.fnloc:
            return []
        if isinstance(t, ast.Name) and self.locals.get(t.id) in _ARRAY:
            a = self.arr(v)
            if a is None:
                self.fail(v, f"a non-array assigned to the array local {t.id!r}")
            return [f"{t.id}_ = {a[1]}; {t.id}_s0 = {a[2]};" + (f" {t.id}_s1 = {a[3]};" if a[0] >= 2 else "")
                    + (f" {t.id}_s2 = {a[4]};" if a[0] == 3 else "")]
        if not isinstance(t, (ast.Name, ast.Subscript)):
            self.fail(t, "assignment to other than a name or an element")
        return [f"{self.expr(t)} = {self.expr(v)};"]

    def for_range(self, s, p, ind):
        it = s.iter
        if (s.orelse or not isinstance(s.target, ast.Name) or not isinstance(it, ast.Call)
                or self.resolve(it.func) is not range or not 1 <= len(it.args) <= 3):
            self.fail(s, "a loop other than 'for i in range(...)'")
        a = [self.expr(x) for x in it.args]
        lo, hi, st = ("0", a[0], "1") if len(a) == 1 else (a[0], a[1], a[2] if len(a) == 3 else "1")
        if len(a) == 3 and not (isinstance(it.args[2], ast.Constant) and it.args[2].value > 0):
            self.fail(s, "a range with a step that is not a positive constant")
        if s.target.id == "_":
            v = self.tmp()
            head = f"{p}for (long {v} = {lo}; {v} < {hi}; {v} += {st}) {{"
        else:
            v = s.target.id + "_"
            head = f"{p}for ({v} = {lo}; {v} < {hi}; {v} += {st}) {{"
        return [head] + self.body(s.body, ind + 1) + [f"{p}}}"]

    def unpack(self, t, value, p):
        for el in t.elts:
            if not isinstance(el, (ast.Name, ast.Subscript)):
                self.fail(el, "unpacking into other than names and elements")
        k = self.kind.get(value.id) if isinstance(value, ast.Name) else None
        if isinstance(k, tuple) and k[0] == "fns":
            return []   # kernels bound at translation time
        live = [(i, el) for i, el in enumerate(t.elts) if not (isinstance(el, ast.Name) and el.id == "_")]
        if isinstance(value, ast.Tuple):
            if len(value.elts) != len(t.elts):
                self.fail(value, "tuple lengths differ")
            decl, sets = [], []
            for i, el in live:
                x = value.elts[i]
                ty = self.etype(x)
                if ty == "fn":
                    continue
                if ty in _ARRAY:
                    sets += self.assign(el, x)   # pointers: no temporary (no kernel swaps arrays)
                    continue
                tmp = self.tmp()
                decl.append(f"{ty} {tmp} = {self.expr(x)};")
                sets.append(f"{self.expr(el)} = {tmp};")
            return [f"{p}{{ " + " ".join(decl + sets) + " }"]
        ty = self.etype(value)
        if not is_tup(ty):
            self.fail(value, f"unpacking {ty}")
        if ty != f"taos_tup{len(t.elts)}":
            self.fail(value, f"unpacking {len(t.elts)} names from {ty}")
        tmp = self.tmp()
        sets = [f"{self.expr(el)} = {tmp}.v[{i}];" for i, el in live]
        return [f"{p}{{ {ty} {tmp} = {self.expr(value)}; " + " ".join(sets) + " }"]

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
                if is_tup(t):
                    return t
                tys = _join(tys, t)
        return tys or "void"

