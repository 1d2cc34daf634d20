"""The report of an optimisation: ``optimum.json``, ``designs.csv`` and the figures (no optimisation here).

``optimum.json`` holds the start design (the scene's values of the design keys) and the best design(s): one
for one objective, the Pareto front for two; each with its key values, objectives and constraints.
``designs.csv`` lists every design the optimiser proposed, feasible or not, with the constraints it violates
(none is silently dropped).  ``convergence.png`` draws each DE run's best value against the evaluations;
``pareto.png`` (two objectives) every feasible design evaluated, the front and the start.
"""

from __future__ import annotations

import csv
import io
import math
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from weftsim.optimize.evaluate import Checked, Evaluator
    from weftsim.optimize.driver import Trajectory

OPTIMUM_FILE = "optimum.json"
DESIGNS_FILE = "designs.csv"
CONVERGENCE_FILE = "convergence.png"
PARETO_FILE = "pareto.png"


def design_entry(evaluator: Evaluator, checked: Checked) -> dict[str, Any]:
    """A design as reported: its keys (dotted, file units), constraints, feasibility and objectives."""
    p = evaluator.problem
    entry = evaluator.stored.get(checked.design.id)
    return {"keys": checked.design.overrides(p.variables), "feasible": checked.feasible,
            "violated": [n for n, c in checked.judged.items() if c["violation"]],
            "constraints": checked.judged,
            "objectives": entry["objectives"] if entry else None,
            "status": entry["status"] if entry else ("not evaluated (violates a constraint)" if not checked.feasible
                                                     else "not evaluated"),
            "error": entry["error"] if entry else ""}


def binding(evaluator: Evaluator) -> tuple[str | None, str]:
    """The constraint that binds an infeasible problem, and a line saying so: the one violated by the design
    closest to feasible (smallest total violation), with how many of the designs checked violate it."""
    checked = list(evaluator.checked.values())
    if not checked:
        return None, ""
    counts: dict[str, int] = {}
    for c in checked:
        for name, entry in c.judged.items():
            if entry["violation"]:
                counts[name] = counts.get(name, 0) + 1
    closest = min(checked, key=lambda c: sum(e["violation"] or 0.0 for e in c.judged.values()))
    missed = {n: e for n, e in closest.judged.items() if e["violation"]}
    if not missed:
        return None, ""
    name = max(missed, key=lambda n: (counts.get(n, 0), missed[n]["violation"]))
    line = (f"no design within the bounds keeps every constraint ({len(checked)} designs checked): the binding "
            f"constraint is {name}, violated by {counts[name]} of them; the closest design misses it: "
            f"{missed[name]['message']}")
    return name, line


def designs_table(evaluator: Evaluator) -> str:
    p = evaluator.problem
    names = [v.name for v in p.variables]
    constraint_names = list(next(iter(evaluator.checked.values())).judged) if evaluator.checked else []
    columns = names + ["feasible", "violated"] + [f"constraint_{n}" for n in constraint_names] + \
        list(p.objectives) + ["status", "error"]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for checked in evaluator.checked.values():
        entry = design_entry(evaluator, checked)
        row: dict[str, Any] = dict(zip(names, checked.design.values))
        row.update(feasible=checked.feasible, violated=" ".join(entry["violated"]), status=entry["status"],
                   error=(entry["error"] or "").splitlines()[0] if entry["error"] else "")
        for n in constraint_names:
            value = checked.judged[n]["value"]
            row[f"constraint_{n}"] = "" if value is None else f"{value:.10g}"
        for n in p.objectives:
            value = (entry["objectives"] or {}).get(n)
            row[n] = "" if value is None else f"{value:.10g}"
        writer.writerow(row)
    return buffer.getvalue()


def convergence_figure(runs: list[Trajectory], names: tuple[str, ...], units: dict[str, str], title: str) -> Figure:
    from weftsim.post.plots import figure

    fig = figure(figsize=(7.5, 4.2))
    ax = fig.add_subplot(1, 1, 1)
    for run in runs:
        points = [(n, v) for n, v in run.history if math.isfinite(v)]
        if points:
            ax.step(*zip(*points), where="post", marker="o", markersize=3, label=run.label)
    single = len(names) == 1
    ax.set_xlabel("objective evaluations of the DE run")
    ax.set_ylabel(f"best {names[0]}, {units[names[0]]}" if single else "best scalarised value (Tchebycheff, 1 = spread)")
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def pareto_figure(points: list[tuple[float, ...]], front: list[tuple[float, ...]], start: tuple | None,
                  names: tuple[str, ...], units: dict[str, str], title: str) -> Figure:
    from weftsim.post.plots import figure

    fig = figure(figsize=(6.5, 4.8))
    ax = fig.add_subplot(1, 1, 1)
    if points:
        xs, ys = zip(*points)
        ax.scatter(xs, ys, s=8, color="0.7", label="feasible designs evaluated")
    if front:
        ax.plot(*zip(*front), "o-", color="C0", label="Pareto front")
    if start is not None and None not in start:
        ax.plot(*start, "*", color="C3", markersize=12, label="start (the scene)")
    ax.set_xlabel(f"{names[0]}, {units[names[0]]}")
    ax.set_ylabel(f"{names[1]}, {units[names[1]]}")
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
