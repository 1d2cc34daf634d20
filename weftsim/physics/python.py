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
or loops: it embeds the function's address), and builds the reference engine's plain kernel
(:data:`weftsim.physics.chain_f.PLAIN`) with the drive law, the film, the wear and the topology
bound to their constant-speed, dry, round, E-only forms.  :func:`specialize` rebuilds only the functions
that read a bound name, directly or through a compiled callee (called by name or as ``module.function``);
the others stay the shared compiled functions.
"""

from __future__ import annotations

import types
from typing import TYPE_CHECKING, Any

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


def specialize(fn: Dispatcher, tag: str = "", lean: bool = False, *, counted: tuple[str, ...] = (),
               **bind: Callable) -> Dispatcher:
    """``fn`` and its callees compiled (``cache=True``) with the globals in ``bind`` replaced.

    Only functions that read a bound name (themselves or through a compiled callee, called by name or as
    ``module.function``) are rebuilt (every compiled callee under ``lean``); a bound compiled function is
    itself rebuilt with ``bind`` when it reads one.  numba's cache keys a function by its module, qualified name and signature, not by its globals:
    ``tag`` (a name) is appended to the qualified name of every rebuilt function, so that forms of the same
    source with different bindings keep separate cache entries; without a tag, bind each name to one
    function per process.

    ``lean``: the callees (not ``fn`` itself) are compiled without numba's reference counting
    (numba's ``_nrt=False``): each call of a compiled function that is not inlined otherwise increments and
    decrements the counts of its array arguments, atomic operations numba's pruning pass leaves wherever a
    call can fail or a branch returns early (docs/performance.md, "The plain kernel").  Such a callee must not
    create arrays (numba refuses to compile it then: "NRT required but not enabled"); name those that do in
    ``counted`` (they keep the counting).  A lean function reads and writes the arrays it is given; the results
    are the same to the bit.
    """
    key = (fn, tuple(sorted(bind.items(), key=lambda item: item[0])), "compiled", tag, lean, counted)
    form = _FORMS.get(key)
    if form is None:
        options = {"_nrt": False, "counted": counted} if lean else {}
        form = _FORMS[key] = _compiled_form(fn, bind, tag, {fn: None}, {}, options)
    return form


def _callees(fn, names: dict):
    """(global name, compiled function) of every compiled function ``fn`` calls by name or as module.attr."""
    code_names = fn.py_func.__code__.co_names
    for name in code_names:
        value = names.get(name)
        if isinstance(value, CPUDispatcher):
            yield name, value
        elif isinstance(value, types.ModuleType):
            for attr in code_names:
                callee = getattr(value, attr, None)
                if isinstance(callee, CPUDispatcher):
                    yield name, callee


def _reads(fn, bind: dict, memo: dict) -> bool:
    """True when the compiled function ``fn`` or one of its compiled callees reads a global of ``bind``."""
    if fn not in memo:
        memo[fn] = False  # a call cycle reads nothing new
        names = fn.py_func.__globals__
        memo[fn] = (any(name in bind for name in fn.py_func.__code__.co_names)
                    or any(_reads(callee, bind, memo) for _, callee in _callees(fn, names)))  # fmt: skip
    return memo[fn]


def _module_view(module: types.ModuleType, attrs: tuple, bind: dict, tag: str, memo: dict, reads: dict,
                 options: dict) -> types.ModuleType:
    """A copy of ``module`` whose compiled functions named in ``attrs`` are their bound or rebuilt forms."""
    view = types.ModuleType(module.__name__, module.__doc__)
    view.__dict__.update(module.__dict__)
    for attr in attrs:
        value = getattr(module, attr, None)
        if isinstance(value, CPUDispatcher):
            value = bind.get(attr, value)
            if isinstance(value, CPUDispatcher):
                value = _compiled_form(value, bind, tag, memo, reads, options)
            setattr(view, attr, value)
    return view


def _compiled_form(fn, bind: dict, tag: str, memo: dict, reads: dict, options: dict):
    """:func:`specialize`'s rebuild: ``fn`` itself when it reads no bound name, else its rebuilt form compiled
    with ``options`` (the root, marked None in ``memo``, without them)."""
    root = memo.get(fn, False) is None
    if fn in memo and not root:
        return memo[fn]
    if not root and not options and not _reads(fn, bind, reads):  # a lean form rebuilds every callee
        memo[fn] = fn
        return fn
    source = fn.py_func
    names = dict(source.__globals__)
    form = types.FunctionType(source.__code__, names, source.__name__, source.__defaults__, source.__closure__)
    form.__doc__ = source.__doc__
    form.__module__ = source.__module__
    form.__qualname__ = f"{source.__qualname__}.{tag}" if tag else source.__qualname__
    lean: dict[str, Any] = {} if root or source.__name__ in options.get("counted", ()) else {"_nrt": False} if options else {}
    result = memo[fn] = njit(cache=True, error_model="numpy", **lean)(form)
    code_names = source.__code__.co_names
    for name in code_names:
        value = bind[name] if name in bind else names.get(name)
        if isinstance(value, CPUDispatcher):
            names[name] = _compiled_form(value, bind, tag, memo, reads, options)
        elif name in bind:
            names[name] = value
        elif isinstance(value, types.ModuleType) and any((options or _reads(c, bind, reads))
                                                         for n, c in _callees(fn, names) if n == name):  # fmt: skip
            names[name] = _module_view(value, code_names, bind, tag, memo, reads, options)
    return result
