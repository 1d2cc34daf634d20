"""The optimiser: scipy's differential evolution over the design keys, constraints by feasibility rules.

Why differential evolution (``scipy.optimize.differential_evolution``): the objectives of a worn joint are peaks
of impact-driven runs, not smooth in the design (a gradient method would chase the impacts' noise); DE needs no
gradient, evaluates a whole generation at once (its ``workers=`` map is the sweep's pool), is reproducible from
its seed, takes integer coordinates (a choice of oil grade) and handles constraints by Lampinen's feasibility
rules: a design that violates a constraint is compared by its violation alone and its objectives are never run,
so the cheap kinematic constraints screen the designs before any dynamic run.  scipy is a dependency already.

Two objectives give a Pareto front by scalarisation (``front_points`` DE runs, each over ``1/front_points`` of the
budget, seeds ``seed + k``): the two single-objective optima first, then the augmented Tchebycheff problems
``max_i(w_i (f_i - z_i) / n_i) + 1e-3 sum_i (f_i - z_i) / n_i`` for weights ``w = (1 - k/(P-1), k/(P-1))``, with
the ideal point ``z`` and the spread ``n`` from the two optima (Tchebycheff weights reach non-convex parts of a
front, a weighted sum does not).  The front reported is the non-dominated set of every feasible design evaluated.

The budget ``max_evaluations`` counts designs whose objectives are evaluated (a design violating a constraint
costs only its kinematics); a DE run stops at its generation that would exceed it, or at DE's own convergence.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from weftsim.optimize.constraints import components
from weftsim.optimize.evaluate import Evaluator
from weftsim.optimize.problem import Design, design_of

# DE stops when the spread of its population's values falls below this fraction of their mean: 1e-3 places the
# kinematic test problems' optima within 0.5 mm of the dense grid's (tests/test_optimize.py); scipy's default
# 1e-2 stopped 1.6 mm short on a stroke-bound arm length.
CONVERGENCE_TOL = 1e-3
FRONT_WEIGHT_AUGMENT = 1e-3
# Designs proposed (constraints judged) per objective evaluation of the budget before a DE run gives up: a
# design that violates a constraint costs ~10 ms of kinematics, so a problem whose constraints few designs keep
# (or none: an infeasible one) still ends, after at most this many times the budget of such checks.
PROPOSALS_PER_EVALUATION = 10
MAX_GENERATIONS = 1000  # the augmented Tchebycheff term: keeps the front's ends off weakly dominated points


@dataclass
class Trajectory:
    """One DE run: the designs it asked objectives for, in order, and its best feasible value by generation."""

    label: str
    requested: list[str] = field(default_factory=list)
    history: list[tuple[int, float]] = field(default_factory=list)  # (objective evaluations, best scalar value)
    best: str | None = None
    stop: str = ""


def _scalar_of(names: tuple[str, ...], weights: tuple[float, float] | None, ideal: tuple[float, ...],
               spread: tuple[float, ...]) -> Callable[[dict], float]:
    """The value DE minimises for an entry: the one objective, or the Tchebycheff scalarisation of two."""

    def scalar(entry: dict) -> float:
        values = [entry["objectives"].get(n) for n in names]
        if entry["status"] != "success" or any(v is None for v in values):
            return math.inf  # a failed run: the worst value (its design is reported with the error)
        if weights is None:
            return float(values[0])
        terms = [(v - z) / n for v, z, n in zip(values, ideal, spread)]
        return max(w * t for w, t in zip(weights, terms)) + FRONT_WEIGHT_AUGMENT * sum(terms)

    return scalar


def minimise(evaluator: Evaluator, scalar: Callable[[dict], float], names: tuple[str, ...], seed: int,
             budget: int, population: int, label: str, start: Design | None = None) -> Trajectory:
    """One seeded DE run over the problem's design keys (module docstring)."""
    from scipy.optimize import NonlinearConstraint, differential_evolution

    problem = evaluator.problem
    variables = problem.variables
    bounds = [v.bounds for v in variables]
    size = population * len(variables)  # scipy's population: popsize x the number of coordinates
    trajectory = Trajectory(label)
    best = [math.inf]
    judged_names = components(problem.constraints)

    proposed = [0]

    def violations(x) -> np.ndarray:
        proposed[0] += 1
        judged = evaluator.check(design_of(x, variables)).judged
        return np.array([judged[n]["violation"] or 0.0 for n in judged_names])

    def mapper(func, xs) -> list[float]:
        designs = [design_of(x, variables) for x in xs]
        entries = evaluator.evaluate(designs)
        values = []
        for design, entry in zip(designs, entries):
            value = scalar(entry)
            trajectory.requested.append(design.id)
            if value < best[0]:
                best[0], trajectory.best = value, design.id
            values.append(value)
        trajectory.history.append((len(trajectory.requested), best[0]))
        return values

    def callback(intermediate_result) -> None:
        if len(trajectory.requested) + size > budget:
            trajectory.stop = f"the budget ({budget} evaluations)"
            raise StopIteration
        if proposed[0] + size > PROPOSALS_PER_EVALUATION * budget:
            trajectory.stop = (f"{proposed[0]} designs proposed, {PROPOSALS_PER_EVALUATION} times the budget: few "
                               "designs keep the constraints")
            raise StopIteration

    constraint = NonlinearConstraint(violations, -np.inf, 0.0)
    x0 = None
    if start is not None:
        coords = [v.coordinate(value) for v, value in zip(variables, start.values)]
        if all(lo <= c <= hi for c, (lo, hi) in zip(coords, bounds)):
            x0 = np.array(coords)  # the start design joins the first generation
    result = differential_evolution(
        _never_called, bounds, rng=seed, popsize=population, maxiter=MAX_GENERATIONS, polish=False,
        updating="deferred", workers=mapper, constraints=(constraint,), callback=callback, x0=x0,
        integrality=[v.integral for v in variables], tol=CONVERGENCE_TOL)
    if not trajectory.stop:
        trajectory.stop = "DE converged" if result.success else str(result.message)
    return trajectory


def _never_called(x):  # DE's func: the workers= map evaluates whole generations instead
    raise AssertionError("the objective is evaluated by the map of a generation")


def pareto(points: list[tuple[str, tuple[float, ...]]]) -> list[str]:
    """Ids of the non-dominated points (both minimised), ordered by the first objective."""
    ordered = sorted(points, key=lambda p: (p[1][0], p[1][1]))
    front, lowest = [], math.inf
    for design_id, (_, f2) in ordered:
        if f2 < lowest:
            front.append(design_id)
            lowest = f2
    return front


def feasible_values(evaluator: Evaluator, names: tuple[str, ...]) -> dict[str, tuple[float, ...]]:
    """Objective values of every feasible, successfully evaluated design, by id."""
    out = {}
    for design_id, entry in evaluator.stored.items():
        checked = evaluator.checked.get(design_id)
        values = tuple(entry["objectives"].get(n) for n in names)
        if checked is not None and checked.feasible and entry["status"] == "success" and None not in values:
            out[design_id] = values
    return out


def optimise(evaluator: Evaluator, seed: int, budget: int, population: int, front_points: int,
             start: Design) -> tuple[list[Trajectory], list[str]]:
    """Run the optimisation; returns the DE runs and the ids of the best design(s) (one, or the front)."""
    names = evaluator.problem.objectives
    if len(names) == 1:
        run = minimise(evaluator, _scalar_of(names, None, (0.0, 0.0), (1.0, 1.0)), names, seed, budget,
                       population, f"minimise {names[0]}", start)
        values = feasible_values(evaluator, names)
        best = min((v[0], i) for i, v in values.items() if i in set(run.requested)) if values else None
        return [run], [best[1]] if best else []
    share = max(budget // front_points, 1)
    runs = []
    for k, name in enumerate(names):
        runs.append(minimise(evaluator, _scalar_of((name,), None, (0.0, 0.0), (1.0, 1.0)), (name,), seed + k,
                             share, population, f"minimise {name}", start))
    values = feasible_values(evaluator, names)
    first, second = runs[0].best, runs[1].best
    if first in values and second in values:
        ends = (values[first], values[second])  # each optimum's two objectives
        ideal = (ends[0][0], ends[1][1])
        spread = tuple(max(ends[1 - i][i] - ideal[i], abs(ideal[i]) * 1e-9, 1e-300) for i in range(2))
        for k in range(1, front_points - 1):
            w = 1.0 - k / (front_points - 1)
            runs.append(minimise(evaluator, _scalar_of(names, (w, 1.0 - w), ideal, spread), names, seed + 1 + k,
                                 share, population, f"Tchebycheff weights {w:.3g}, {1 - w:.3g}", start))
    values = feasible_values(evaluator, names)
    return runs, pareto(list(values.items()))
