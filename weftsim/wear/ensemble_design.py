"""The design of a wear ensemble's dynamic keys and the interpolation between its points (docs/wear.md section 9).

Each dynamic key (one that changes the dynamics: clearance, speed, viscosity, ...) is simulated at a
few quantiles of its distribution, on the tensor grid of all of them.  A sample's hours at a clearance
level are interpolated between the design points:

- **every design point reaches the level**: log-hours, quadratically along a key of three points (the
  default 5/50/95 % quantiles), piecewise linearly along a key of two or more than three;
- **some design point never reaches it** (censored: a full film, or beyond the jobs' horizon): the
  inverse hours 1/h (the mean speed towards the level, 0 for a point that never gets there) piecewise
  linearly along every key.  Linear weights are non-negative, so the inverse hours stay >= 0 and a
  sample is censored exactly where they interpolate to 0 (all its neighbouring points censored).  Across a
  regime boundary (film / mixed) the true inverse hours rise from 0 like the asperity load, faster than
  linearly, so this rule spreads the wear of the wearing point towards the censored one: the fraction
  reaching the limit and the earliest hours are on the side of more wear (conservative for maintenance);
  design points placed densely along the key that moves the boundary narrow that band.

Values beyond the outer points are clamped there, as before.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import WearError

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.wear.uncertain import Uncertain

# The wear coefficients (the regimes' and the one-for-all override) and the hardnesses never enter the dynamics.
K_KEYS = ("joint_e.wear.wear_coefficient", "joint_e.wear.dry_wear_coefficient", "joint_e.wear.boundary_wear_coefficient",
          "joint_e.wear.mixed_wear_coefficient")
RESCALED = (*K_KEYS, "joint_e.wear.bearing_hardness_mpa", "joint_e.wear.journal_hardness_mpa")
DESIGN_QUANTILES = (0.05, 0.5, 0.95)
MAX_DESIGN_POINTS = 9  # per key: the job names carry one digit per key


def design_quantiles(points: int) -> tuple[float, ...]:
    """The probabilities of a key's design points: 5/50/95 % for 3, else equally spaced from 5 to 95 %."""
    if points == 3:
        return DESIGN_QUANTILES
    return tuple(float(q) for q in np.linspace(0.05, 0.95, points))


def last_bits(scene: Scene, j: int) -> Scene:
    """``scene`` with its wear coefficients j units in the last place larger (the same physics to 1e-15): the
    one-for-all ``wear_coefficient`` where the scene gives it, else every regime's."""
    w = scene.joint.wear

    def up(k: float) -> float:
        for _ in range(j):
            k = math.nextafter(k, math.inf)
        return k

    if w.wear_coefficient is not None:
        w = replace(w, wear_coefficient=up(w.wear_coefficient))
    else:
        w = replace(w, dry_wear_coefficient=up(w.dry_wear_coefficient),
                    boundary_wear_coefficient=up(w.boundary_wear_coefficient),
                    mixed_wear_coefficient=up(w.mixed_wear_coefficient))
    return replace(scene, joint=replace(scene.joint, wear=w))


def k_scale(scene: Scene, values: dict[str, np.ndarray], samples: int) -> np.ndarray:
    """The factor k0 / k on the hours of each sample from its uncertain wear coefficients (:data:`K_KEYS`).

    Hours scale exactly as 1 / k where one k carries the wear: the solid contact's k (the regime's, dry or
    boundary) of a joint without an oil film, the mixed regime's of an oiled one (the asperities carry its
    load; where the dry law carries some too, the factor is the asperities' to first order).  A regime's key
    that the joint does not wear in (``dry_wear_coefficient`` of a boundary-lubricated joint) changes nothing.
    """
    w = scene.joint.wear
    oiled = scene.joint.is_lubricated
    active = {"joint_e.wear.wear_coefficient": w.asperity_wear_coefficient if oiled else w.contact_wear_coefficient}
    if w.wear_coefficient is None:
        key = "mixed" if oiled else w.regime
        active = {f"joint_e.wear.{key}_wear_coefficient": getattr(w, f"{key}_wear_coefficient"),
                  **active}
    scale = np.ones(samples)
    for key in K_KEYS:
        if key in values and key in active:
            scale *= active[key] / values[key]
    return scale


def _lagrange(nodes: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(n, len(nodes)) weights of quadratic Lagrange interpolation at ``x`` (clamped to the nodes' range)."""
    x = np.clip(x, nodes.min(), nodes.max())
    w = np.ones((x.size, nodes.size))
    for i, xi in enumerate(nodes):
        for m, xm in enumerate(nodes):
            if m != i:
                w[:, i] *= (x - xm) / (xi - xm)
    return w


def _hat(nodes: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(n, len(nodes)) weights of piecewise-linear interpolation at ``x`` on sorted ``nodes`` (clamped)."""
    x = np.clip(x, nodes.min(), nodes.max())
    w = np.zeros((x.size, nodes.size))
    i = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
    t = (x - nodes[i]) / (nodes[i + 1] - nodes[i])
    rows = np.arange(x.size)
    w[rows, i] = 1.0 - t
    w[rows, i + 1] = t
    return w


def design_points_of(dynamic: list[Uncertain], design_points: dict[str, int] | None) -> list[int]:
    """Points per dynamic key (3 unless ``design_points`` says otherwise), checked."""
    design_points = dict(design_points or {})
    keys = {u.key for u in dynamic}
    for key, n in design_points.items():
        if key not in keys:
            raise WearError(f"--design-points {key}: not one of the simulated --uncertain keys "
                            f"({', '.join(sorted(keys)) or 'none'})")
        if not (isinstance(n, int) and 2 <= n <= MAX_DESIGN_POINTS):
            raise WearError(f"--design-points {key}={n!r}: give a whole number from 2 to {MAX_DESIGN_POINTS}")
    return [design_points.get(u.key, len(DESIGN_QUANTILES)) for u in dynamic]


def plan(scene: Scene, uncertain: list[Uncertain], chaos_runs: int = 6, design_points: dict[str, int] | None = None
         ) -> tuple[list[tuple[str, Scene]], list[Uncertain], np.ndarray]:
    """(jobs as (name, scene), the dynamic inputs, their design values (nodes, dims)); checks every design scene.

    The chaos runs are made at the centre point (index ``points // 2`` of every key)."""
    from weftsim.input.scene import SceneError, apply_overrides
    from weftsim.wear.uncertain_keys import check_uncertain_key, resolve

    # the names --set takes (a dotted key or its unique last part), each a key that changes the wear at E
    names = tuple(u.key for u in uncertain)
    uncertain = [replace(u, key=check_uncertain_key(u.key, scene, names)) for u in uncertain]
    design_points = {resolve(k): n for k, n in (design_points or {}).items()}
    seen = set()
    for u in uncertain:
        if u.key in seen:
            raise WearError(f"--uncertain {u.key} is given twice")
        seen.add(u.key)
        if u.key in RESCALED and not np.all(u.ppf(np.array([1e-6, 0.5, 1 - 1e-6])) > 0.0):
            raise WearError(f"--uncertain {u.text}: {u.key} must stay > 0; a lognormal keeps it positive")
    dynamic = [u for u in uncertain if u.key not in RESCALED]
    points = design_points_of(dynamic, design_points)
    design = [[float(v) for v in u.ppf(np.array(design_quantiles(n)))] for u, n in zip(dynamic, points)]
    nodes = np.array(list(itertools.product(*design))) if dynamic else np.zeros((1, 0))
    jobs = []
    centre = tuple(n // 2 for n in points)
    for index in itertools.product(*[range(n) for n in points]):
        values = {u.key: design[d][i] for d, (u, i) in enumerate(zip(dynamic, index))}
        try:
            node_scene = apply_overrides(scene, values, "--uncertain", refuse_ideal_keys=False) if values else scene
        except SceneError as exc:
            raise WearError(f"--uncertain: the design point {values} is not a valid scene: {exc}") from None
        name = "node_" + "_".join(str(i) for i in index) if dynamic else "centre"
        jobs.append((name, node_scene))
        if index == centre:
            jobs.extend((f"chaos_{j}", last_bits(node_scene, j)) for j in range(1, chaos_runs))
    return jobs, dynamic, nodes


def centre_name(nodes: np.ndarray, dynamic: list[Uncertain]) -> str:
    """The job name of the centre design point (where the chaos runs are)."""
    if not dynamic:
        return "centre"
    return "node_" + "_".join(str(len(set(nodes[:, d])) // 2) for d in range(len(dynamic)))


def interpolate(node_hours: np.ndarray, nodes: np.ndarray, dynamic: list[Uncertain], values: dict[str, np.ndarray],
                samples: int) -> np.ndarray:
    """(samples, levels) hours interpolated from the design's (nodes, levels) hours (module docstring).

    ``inf`` marks a design point that does not reach a level (censored); 0 one that starts above it.
    """
    if not dynamic:
        return np.repeat(node_hours, samples, axis=0)
    smooth = np.ones((samples, 1))
    linear = np.ones((samples, 1))
    for d, v in enumerate(dynamic):
        axis = np.array(sorted(set(nodes[:, d])))
        index = [int(np.searchsorted(axis, x)) for x in nodes[:, d]]
        hat = _hat(axis, values[v.key])
        smooth = smooth * (_lagrange(axis, values[v.key]) if axis.size == 3 else hat)[:, index]
        linear = linear * hat[:, index]
    reached = np.all(np.isfinite(node_hours), axis=0)  # no design point censored at the level
    positive = np.all(node_hours > 0.0, axis=0)
    out = np.empty((samples, node_hours.shape[1]))
    with np.errstate(divide="ignore", invalid="ignore"):
        # every point reaches the level: log-hours; some start above it (an uncertain clearance): hours
        log_ok = reached & positive
        out[:, log_ok] = np.exp(smooth @ np.log(node_hours[:, log_ok]))
        lin_ok = reached & ~positive
        out[:, lin_ok] = np.maximum(smooth @ node_hours[:, lin_ok], 0.0)
        # some never reach it: inverse hours, piecewise linear (0 = never); a point starting above the level
        # (0 h) counts as the fastest of the others there (a coarse rule for the band's lowest levels)
        cens = ~reached
        if np.any(cens):
            inverse = np.where(np.isfinite(node_hours[:, cens]), 1.0 / node_hours[:, cens], 0.0)
            fastest = np.max(np.where(np.isfinite(inverse), inverse, 0.0), axis=0)
            inverse = np.where(np.isinf(inverse), fastest, inverse)
            q = linear @ inverse
            out[:, cens] = np.where(q > 0.0, 1.0 / q, math.inf)
    return out
