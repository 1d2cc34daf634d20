"""Plain-Python forms of the kernel's compiled functions (the same source, no compilation).

``fn.py_func`` of a numba function is its Python source, but the kernel functions it calls are
still numba dispatchers: each call from Python pays numba's dispatch (~1 us) and loads compiled
code, and a dispatcher cannot take a Python callable as an argument.  :func:`python_form` rebuilds
the function with the same code object and globals in which every compiled callee is replaced by
its own plain-Python form, recursively.  Callers off the compiled paths use it: the array methods
of :mod:`weftsim.contact` and :mod:`weftsim.clearance`, the ``"python"`` callback route, and the
event search of the scipy path (whose state function is a Python closure over scipy's dense output).
"""

from __future__ import annotations

import types

from numba.core.registry import CPUDispatcher

_FORMS: dict = {}


def python_form(fn):
    """The plain-Python function of the numba function ``fn``, calling plain-Python callees."""
    form = _FORMS.get(fn)
    if form is not None:
        return form
    source = fn.py_func
    names = dict(source.__globals__)
    form = types.FunctionType(source.__code__, names, source.__name__, source.__defaults__, source.__closure__)
    form.__doc__ = source.__doc__
    _FORMS[fn] = form
    for name in source.__code__.co_names:
        value = names.get(name)
        if isinstance(value, CPUDispatcher):
            names[name] = python_form(value)
    return form
