"""Rich displays of the library's results and models: a compact HTML table in a notebook
(``_repr_html_``), ``.plot()`` for the matplotlib figure the report uses and ``.show()`` for the
interactive plotly view — drawn by the presentation layer, which the library does not import.

The layering (the import-linter contract in ``pyproject.toml``) puts the presentation
(:mod:`poinsot.viz`) above the library: no library module imports it, not even inside a
method (a method-level import is an import all the same). So the drawing is a plug-in, as in
pandas, whose ``DataFrame.plot`` finds its plotting backend by name:

* the presentation registers one renderer per library class and kind of display
  (``"html"``, ``"plot"``, ``"interactive"``) with :func:`register` when its module
  :mod:`poinsot.viz.display` is imported;
* the library's classes inherit :class:`Displayable`, whose methods call :func:`render`;
* the first display of an object whose class has no renderer yet imports the module named by
  :data:`backend` (``"poinsot.viz.display"``) with :func:`importlib.import_module`: a name,
  as pandas' ``plotting.backend`` option is, not an import of the presentation. Set
  ``poinsot.display.backend`` to a module of your own to draw the results differently.

Renderers are looked up along the class's MRO, by qualified class name.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

__all__ = ["KINDS", "Displayable", "HTMLDisplay", "backend", "register", "render"]

#: The kinds of display: an HTML table, the matplotlib figure, the plotly figure.
KINDS = ("html", "plot", "interactive")
#: The module that registers the renderers (imported by name on the first display).
backend = "poinsot.viz.display"

_RENDERERS: dict[tuple[str, str], Callable] = {}


def _key(cls) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def register(cls_name: str, kind: str) -> Callable:
    """Decorator: register ``fn(obj, *args, **kwargs)`` as the ``kind`` display of the class
    named ``cls_name`` (``"poinsot.trajectory.Trajectory"``).

    Examples
    --------
    >>> @register("builtins.int", "html")
    ... def _(n):
    ...     return f"<b>{n}</b>"
    >>> render(3, "html")
    '<b>3</b>'
    """
    if kind not in KINDS:
        raise ValueError(f"`kind` must be one of {KINDS}, found {kind!r}")

    def decorate(fn):
        _RENDERERS[(cls_name, kind)] = fn
        return fn

    return decorate


def _lookup(obj, kind):
    for cls in type(obj).__mro__:
        fn = _RENDERERS.get((_key(cls), kind))
        if fn is not None:
            return fn
    return None


def render(obj, kind: str, *args, **kwargs):
    """The ``kind`` display of ``obj`` (:data:`KINDS`), by the renderer registered for its
    class; the :data:`backend` module is imported first if none is."""
    fn = _lookup(obj, kind)
    if fn is None:
        importlib.import_module(backend)
        fn = _lookup(obj, kind)
    if fn is None:
        raise TypeError(f"no {kind!r} display for {type(obj).__name__} (backend {backend!r})")
    return fn(obj, *args, **kwargs)


class HTMLDisplay:
    """The notebook display of a library object (a model, a system), drawn by
    :mod:`poinsot.viz` through :func:`render`."""

    def _repr_html_(self) -> str:
        """A compact HTML table of what matters, with units (Jupyter's rich display)."""
        return render(self, "html")


class Displayable(HTMLDisplay):
    """Notebook displays and figures of a library result, drawn by :mod:`poinsot.viz`
    through :func:`render`."""

    def plot(self, *args, **kwargs):
        """The matplotlib figure of this object that the reports use; returns the figure.
        Arguments choose among its figures where it has several (see its renderer in
        :mod:`poinsot.viz.display`)."""
        return render(self, "plot", *args, **kwargs)

    def show(self, *args, **kwargs):
        """Show the interactive (plotly) view inline, in a notebook or a browser (needs the
        ``report`` extra); returns None, as plotly's ``Figure.show`` does. The figure itself:
        ``poinsot.display.render(obj, "interactive")``."""
        render(self, "interactive", *args, **kwargs).show()
