"""The optimisation problem: design keys with their bounds, the base scene, and the design of a vector.

A design key is any scene key (:data:`weftsim.input.scene.SCHEMA`, by its dotted name or its short name as in
``weftsim sweep``) given as ``KEY=LOW:HIGH`` (a number or whole-number key: the range, both ends included) or
``KEY=A,B,C`` (a choice: a text, true/false, or a list of numbers, e.g. an oil grade).  The optimiser sees one
real coordinate per key: the value itself for a number, the index of the choice (an integer coordinate) for a
list.  Values are in the scene file's units (mm, deg), as everywhere on the command line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from weftsim.errors import OptimizeError, SweepError

if TYPE_CHECKING:
    from weftsim.input.params import Geometry, Scene


@dataclass(frozen=True)
class Variable:
    """One design key: its dotted scene key, short name, and range (``low``, ``high``) or its ``choices``."""

    key: str
    name: str
    kind: str  # "float", "int" or "choice"
    low: float
    high: float
    choices: tuple = ()

    def value(self, coordinate: float) -> Any:
        """The key's value (file units) at the optimiser's coordinate."""
        if self.kind == "choice":
            return self.choices[min(max(int(round(coordinate)), 0), len(self.choices) - 1)]
        if self.kind == "int":
            return int(round(coordinate))
        return float(coordinate)

    def coordinate(self, value: Any) -> float:
        """The optimiser's coordinate of a value of the key (the start design's)."""
        if self.kind == "choice":
            return float(self.choices.index(value)) if value in self.choices else math.nan
        return float(value)

    @property
    def bounds(self) -> tuple[float, float]:
        return (0.0, float(len(self.choices) - 1)) if self.kind == "choice" else (self.low, self.high)

    @property
    def integral(self) -> bool:
        return self.kind != "float"

    def as_dict(self) -> dict:
        out: dict[str, Any] = {"key": self.key, "name": self.name, "kind": self.kind}
        if self.kind == "choice":
            out["choices"] = list(self.choices)
        else:
            out.update(low=self.low, high=self.high)
        return out


def parse_variable(text: str) -> Variable:
    """``KEY=LOW:HIGH`` or ``KEY=A,B,...`` -> :class:`Variable`, or one OptimizeError line."""
    from weftsim.sweep.grid import parse_values, resolve_key, short_name

    name, sep, values = text.partition("=")
    if not sep or not name.strip() or not values.strip():
        raise OptimizeError(f"--vary: expected KEY=LOW:HIGH (e.g. l_oe_mm=200:280) or KEY=A,B for a choice, "
                            f"got {text!r}")
    try:
        key = resolve_key(name.strip())
    except SweepError as exc:
        raise OptimizeError(f"--vary: {exc}") from None
    flag = f"--vary {name.strip()}"
    if ":" in values:
        parts = values.split(":")
        if len(parts) != 2:
            raise OptimizeError(f"{flag}: a range is LOW:HIGH (two numbers, e.g. 200:280), got {values!r}")
        if key.kind not in ("float", "int"):
            raise OptimizeError(f"{flag}: '{key.path}' is not a number; give its choices as A,B,C")
        try:
            low, high = (float(p) for p in parts)
        except ValueError:
            raise OptimizeError(f"{flag}: LOW and HIGH must be numbers, got {values!r}") from None
        if not (math.isfinite(low) and math.isfinite(high)) or not low < high:
            raise OptimizeError(f"{flag}: needs LOW < HIGH (finite numbers), got {values!r}")
        for bound in (low, high):
            problem = _outside(key, bound)
            if problem:
                raise OptimizeError(f"{flag}: {bound:g} is outside what '{key.path}' allows ({key.allowed()})")
        if key.kind == "int" and not (low.is_integer() and high.is_integer()):
            raise OptimizeError(f"{flag}: '{key.path}' takes whole numbers, got {values!r}")
        return Variable(key.path, short_name(key), key.kind, low, high)
    try:
        choices = tuple(parse_values(key, values, flag))
    except SweepError as exc:
        raise OptimizeError(str(exc)) from None
    if len(choices) < 2:
        raise OptimizeError(f"{flag}: a choice needs at least two values (A,B), or a range LOW:HIGH; got {values!r}")
    return Variable(key.path, short_name(key), "choice", 0.0, float(len(choices) - 1), choices)


def _outside(key, value: float) -> bool:
    if key.low is not None and (value < key.low or (key.low_open and value == key.low)):
        return True
    return key.high is not None and (value > key.high or (key.high_open and value == key.high))


def check_variables(variables: list[Variable]) -> None:
    if not variables:
        raise OptimizeError("an optimisation needs at least one --vary KEY=LOW:HIGH")
    keys = [v.key for v in variables]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise OptimizeError(f"--vary: key(s) {', '.join(twice)} given more than once")


@dataclass(frozen=True)
class Design:
    """A design: the values of the design keys (file units), as overrides of the base scene."""

    values: tuple

    def overrides(self, variables: tuple[Variable, ...]) -> dict[str, Any]:
        return {v.key: value for v, value in zip(variables, self.values)}

    def named(self, variables: tuple[Variable, ...]) -> dict[str, Any]:
        return {v.name: value for v, value in zip(variables, self.values)}

    @property
    def id(self) -> str:
        """A key of the design in the evaluation store: the values' exact texts."""
        return ",".join(repr(v) for v in self.values)


def design_of(x, variables: tuple[Variable, ...]) -> Design:
    return Design(tuple(v.value(c) for v, c in zip(variables, x)))


def start_design(base: Scene, variables: tuple[Variable, ...]) -> Design:
    """The base scene's values of the design keys (they may lie outside the bounds)."""
    from weftsim.input.scene import to_file_keys

    keys = to_file_keys(base)
    return Design(tuple(keys.get(v.key) for v in variables))


def design_geometry(base: Scene, overrides: dict[str, Any]) -> Geometry:
    """The base scene's geometry with the ``mechanism.*`` overrides applied, not validated (the assembly
    constraint judges a linkage the scene validation would refuse)."""
    from dataclasses import replace

    from weftsim.input.scene import BRANCHES, SCHEMA

    by_path = {key.path: key for key in SCHEMA}
    geometry = base.geometry
    for path, value in overrides.items():
        key = by_path.get(path)
        if key is None or not key.target.startswith("geometry."):
            continue
        field = key.target.partition(".")[2]
        si: Any = BRANCHES[value] if path == "mechanism.fourbar_branch" else float(value) * key.scale
        changes: dict[str, Any] = {field: si}
        geometry = replace(geometry, **changes)
    return geometry
