"""Other forms of the kernel's compiled functions, rebuilt from the same source.

``fn.py_func`` of a numba function is its Python source, but the kernel functions it calls are
still numba dispatchers: each call from Python pays numba's dispatch (~1 us) and loads compiled
code, and a dispatcher cannot take a Python callable as an argument.  :func:`python_form` rebuilds
the function with the same code object and globals in which every compiled callee is replaced by
its own plain-Python form, recursively.  Callers off the compiled paths use it: the array methods
of :mod:`weftsim.joint.clearance`, the ``"python"`` callback route, and the event search of the scipy
path.  :func:`specialize` does the same with some globals bound to other functions and compiles the
result: the compiled path binds the event search of :mod:`.roots` to its dense output that way
(numba cannot cache a function that passes a compiled function on as an argument through branches
or loops: it embeds the function's address).
"""

from __future__ import annotations

import types
from typing import TYPE_CHECKING

from numba import njit
from numba.core.registry import CPUDispatcher

if TYPE_CHECKING:
    from collections.abc import Callable

    from numba.core.dispatcher import Dispatcher

_FORMS: dict = {}


def _rebuild(fn, bind: dict, compile_it: bool, memo: dict):
    if fn in memo:
        return memo[fn]
    source = fn.py_func
    names = dict(source.__globals__)
    names.update(bind)
    form = types.FunctionType(source.__code__, names, source.__name__, source.__defaults__, source.__closure__)
    form.__doc__ = source.__doc__
    form.__module__ = source.__module__
    form.__qualname__ = source.__qualname__
    result = njit(cache=True, error_model="numpy")(form) if compile_it else form
    memo[fn] = result
    for name in source.__code__.co_names:
        value = names.get(name)
        if name not in bind and isinstance(value, CPUDispatcher):
            names[name] = _rebuild(value, bind, compile_it, memo)
    return result


def python_form(fn: Dispatcher, **bind: Callable) -> Callable:
    """The plain-Python function of the numba function ``fn``, calling plain-Python callees.

    ``bind``: globals of ``fn`` and its callees to replace (by name), e.g. a state function.
    """
    key = (fn, tuple(sorted(bind.items(), key=lambda item: item[0])))
    form = _FORMS.get(key)
    if form is None:
        form = _FORMS[key] = _rebuild(fn, bind, False, {})
    return form


def specialize(fn: Dispatcher, **bind: Callable) -> Dispatcher:
    """``fn`` and its callees compiled (``cache=True``) with the globals in ``bind`` replaced.

    Bind each name to one function per process: numba's cache keys a function by its source and
    signature, not by its globals.
    """
    key = (fn, tuple(sorted(bind.items(), key=lambda item: item[0])), "compiled")
    form = _FORMS.get(key)
    if form is None:
        form = _FORMS[key] = _rebuild(fn, bind, True, {})
    return form
