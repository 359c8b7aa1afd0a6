"""Python cross-reference look-ups answered once per distinct question while the pages are written.

With ``autodoc_typehints = "description"`` every parameter's type becomes a ``:type:`` field whose
names (``float``, ``np.ndarray``, ``Path``, ...) are resolved in Sphinx's "fuzzy" mode: a name
that is no documented object makes :meth:`sphinx.domains.python.PythonDomain.find_obj` scan every
object of the domain, and the API reference asks the same few questions about twelve thousand
times (about 4 CPU-s of a build). The objects do not change once every page has been read, so
from ``env-updated`` (reading done) to ``build-finished`` each distinct call (domain, module,
class, name, type, search mode) is answered once and its answer (a list of (name, entry)) copied
to later callers. Reading, and any incremental re-read, uses Sphinx's own method unchanged.
"""

from __future__ import annotations

_MEMO: dict | None = None   # None: not memoising (reading, or no build running)


def _install() -> None:
    from sphinx.domains.python import PythonDomain

    if getattr(PythonDomain.find_obj, "_taos_memo", False):
        return
    original = PythonDomain.find_obj

    def find_obj(self, *args, **kwargs):
        if _MEMO is None:
            return original(self, *args, **kwargs)
        try:
            key = (id(self), args[0].srcdir, *args[1:], tuple(sorted(kwargs.items())))
            hash(key)
        except (TypeError, IndexError, AttributeError):   # an unexpected call: not memoised
            return original(self, *args, **kwargs)
        if key not in _MEMO:
            _MEMO[key] = original(self, *args, **kwargs)
        return list(_MEMO[key])

    find_obj._taos_memo = True
    find_obj.__doc__ = original.__doc__
    PythonDomain.find_obj = find_obj


def _start(app, env) -> list:
    global _MEMO
    _MEMO = {}
    return []


def _stop(app, exception) -> None:
    global _MEMO
    _MEMO = None


def setup(app) -> None:
    """Connect the memo to the build (called from :func:`taosdocs.ext.setup`)."""
    _install()
    app.connect("env-updated", _start)
    app.connect("env-before-read-docs", lambda app, env, docnames: _stop(app, None))
    app.connect("build-finished", _stop)
