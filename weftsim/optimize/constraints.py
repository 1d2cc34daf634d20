"""Constraints a loom must keep, judged on the ideal mechanism (no simulation) before any objective is run.

=========================  ===============================================================  =====================
constraint                 value (ideal joints, one crank revolution at 0.25 deg)           bounds
=========================  ===============================================================  =====================
``assembly``               largest abs(acos argument) of the four-bar closure, minus 1      always: <= 0
``scene``                  the design's scene passes the scene validation                   always
``stroke_mm``              rapier stroke max(s) - min(s), mm                                 ``stroke_mm=LOW:HIGH``
``dead_centre_deg``        crank angle of the rapier's inner dead centre (largest s), deg    ``=LOW:HIGH``
``transmission_angle_deg`` smallest min(mu, 180 - mu) of the transmission angle mu at F      ``=LOW:``
``bushing``                ideal peak pin pressure and mean p x v at E over the bushing's    ``bushing``
                           ``max_pressure_mpa`` / ``max_pv_mpa_m_s`` (the design checks)
=========================  ===============================================================  =====================

``--constraint NAME=LOW:HIGH`` (either bound may be left out: ``transmission_angle_deg=40:``); ``assembly``
and ``scene`` always apply.  Each constraint gives a *violation* >= 0 (0 when kept), in its own unit (mm,
deg; percent of the limit for ``assembly`` and ``bushing``), whose sum the optimiser drives to 0 (scipy's
feasibility rules: a design that keeps every constraint beats one that does not; among those that do not,
the smaller violation wins).  A linkage that does not assemble cannot be judged on the others (they are
reported as not judged).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from weftsim.errors import OptimizeError

if TYPE_CHECKING:
    from weftsim.input.params import Geometry, Scene

# name -> (unit, what it is): the constraints with bounds
BOUNDED = {
    "stroke_mm": ("mm", "rapier stroke max(s) - min(s)"),
    "dead_centre_deg": ("deg", "crank angle of the rapier's inner dead centre (largest s)"),
    "transmission_angle_deg": ("deg", "smallest min(mu, 180 - mu) of the transmission angle at F"),
}
FLAGS = {"bushing": "the ideal peak pin pressure and mean p x v at E within the bushing's limits"}
ALWAYS = ("assembly", "scene")
NAMES = ALWAYS + tuple(BOUNDED) + tuple(FLAGS)


@dataclass(frozen=True)
class Constraint:
    """One requested constraint: a bounded one (``low``/``high`` in its unit, None = open) or a flag."""

    name: str
    low: float | None = None
    high: float | None = None

    def as_dict(self) -> dict:
        return {"name": self.name, "low": self.low, "high": self.high}

    def text(self) -> str:
        if self.name not in BOUNDED:
            return self.name
        unit = BOUNDED[self.name][0]
        if self.low is not None and self.high is not None:
            return f"{self.name} in [{self.low:g}, {self.high:g}] {unit}"
        return f"{self.name} >= {self.low:g} {unit}" if self.low is not None else f"{self.name} <= {self.high:g} {unit}"


def parse_constraint(text: str) -> Constraint:
    """``NAME=LOW:HIGH`` / ``NAME=LOW:`` / ``NAME=:HIGH`` / ``bushing`` -> :class:`Constraint`, or one line."""
    from weftsim.errors import closest

    name, sep, bounds = text.partition("=")
    name = name.strip()
    if name in FLAGS:
        if sep:
            raise OptimizeError(f"--constraint {name} takes no bounds (its limits are the scene's), got {text!r}")
        return Constraint(name)
    if name in ALWAYS:
        raise OptimizeError(f"--constraint {name} always applies; leave it out")
    if name not in BOUNDED:
        near = closest(name, list(BOUNDED) + list(FLAGS))
        hint = f"did you mean {near}? " if near else ""
        raise OptimizeError(f"--constraint: unknown constraint {name!r}; {hint}the constraints are "
                            f"{', '.join(f'{n}=LOW:HIGH' for n in BOUNDED)} and {', '.join(FLAGS)}")
    parts = bounds.split(":")
    if not sep or len(parts) != 2 or not any(p.strip() for p in parts):
        raise OptimizeError(f"--constraint {name}: expected {name}=LOW:HIGH, {name}=LOW: or {name}=:HIGH, "
                            f"got {text!r}")
    try:
        low, high = (float(p) if p.strip() else None for p in parts)
    except ValueError:
        raise OptimizeError(f"--constraint {name}: the bounds must be numbers, got {bounds!r}") from None
    if any(b is not None and not math.isfinite(b) for b in (low, high)):
        raise OptimizeError(f"--constraint {name}: the bounds must be finite numbers, got {bounds!r}")
    if low is not None and high is not None and not low <= high:
        raise OptimizeError(f"--constraint {name}: needs LOW <= HIGH, got {bounds!r}")
    return Constraint(name, low, high)


def check_constraints(constraints: list[Constraint]) -> None:
    names = [c.name for c in constraints]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise OptimizeError(f"--constraint: {', '.join(twice)} given more than once")


def components(constraints: tuple[Constraint, ...]) -> tuple[str, ...]:
    """The constraint names judged for every design, in order (the always-on ones first)."""
    return ALWAYS + tuple(c.name for c in constraints)


# Crank angles of one revolution the constraints are judged on: weftsim.mechanism.pin_loads's 0.25 deg grid.
def _grid() -> np.ndarray:
    from weftsim.mechanism.pin_loads import SAMPLES

    return np.arange(SAMPLES) * (2.0 * np.pi / SAMPLES)


def assembly_violation(geometry: Geometry) -> float:
    """Percent by which the four-bar's closure fails over a revolution (largest abs(acos argument) - 1), 0 if it
    closes everywhere; a crank inclination outside (0, 90) deg counts as 100."""
    from weftsim.mechanism.kinematics import fourbar_assembly_argument, rocker_angle

    if not 0.0 < geometry.crank_inclination < 0.5 * np.pi:
        return 100.0
    phi, _, _ = rocker_angle(_grid(), geometry.crank_inclination)
    worst = float(np.max(np.abs(fourbar_assembly_argument(geometry.rocker_arm_angle + phi, geometry))))
    return max(100.0 * (worst - 1.0), 0.0)


def _peak_angle(theta: np.ndarray, s: np.ndarray) -> float:
    """Crank angle (deg, in [0, 360)) of the largest s, refined by the parabola through the three samples
    about it (the grid is periodic)."""
    i = int(np.argmax(s))
    left, mid, right = s[i - 1], s[i], s[(i + 1) % s.size]
    curvature = left - 2.0 * mid + right
    shift = 0.5 * (left - right) / curvature if curvature < 0.0 else 0.0
    step = theta[1] - theta[0]
    return float(np.degrees(theta[i] + shift * step)) % 360.0


def kinematic_values(scene: Scene) -> dict[str, float]:
    """The bounded constraints' values of a valid scene's ideal mechanism (module table)."""
    from weftsim.mechanism.kinematics import linkage_state

    theta = _grid()
    st = linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    s = st.rapier_displacement
    mu = np.degrees(st.transmission_angle)
    return {"stroke_mm": float(1e3 * (s.max() - s.min())), "dead_centre_deg": _peak_angle(theta, s),
            "transmission_angle_deg": float(np.min(np.minimum(mu, 180.0 - mu)))}


def bushing_values(checks: list[dict]) -> dict[str, Any]:
    """Ideal pin pressure and p x v at E against their limits (percent over, 0 when within or no limit)."""
    out: dict[str, Any] = {}
    for check in checks:
        if check["stage"] == "before" and check["table"] == "joint_e" and check["name"] in ("pin_pressure", "pv"):
            limit = check["limit"]
            out[check["name"]] = (check["value"], limit)
    return out


def _excess(value: float, low: float | None, high: float | None) -> float:
    if low is not None and value < low:
        return low - value
    if high is not None and value > high:
        return value - high
    return 0.0


def judge(constraints: tuple[Constraint, ...], geometry: Geometry, scene: Scene | None, scene_error: str,
          checks: Callable[[], list[dict]]) -> dict[str, dict]:
    """Each constraint's ``value``, ``violation`` (>= 0, None where not judged) and ``message`` for one design.

    ``geometry``: the design's linkage (judged even where the scene validation refuses it); ``scene``: its
    validated scene, or None with ``scene_error`` the validation's line; ``checks()``: its before-run design
    checks (:func:`weftsim.checks.design_checks.before_run`, as dicts), asked for only when the kinematic
    constraints hold (the pin loads cost four times the kinematics).
    """
    out: dict[str, dict] = {}
    assembly = assembly_violation(geometry)
    out["assembly"] = {"value": assembly, "violation": assembly,
                       "message": "" if assembly == 0.0 else "the four-bar O-E-F-G cannot be assembled over the "
                       f"whole revolution (closure fails by {assembly:.3g} %)"}
    valid = scene is not None
    out["scene"] = {"value": 0.0 if valid else 1.0, "violation": 0.0 if valid or assembly > 0.0 else 100.0,
                    "message": "" if valid or assembly > 0.0 else scene_error}
    values = kinematic_values(scene) if scene is not None else {}
    for c in constraints:
        if not valid:
            out[c.name] = {"value": None, "violation": None, "message": "not judged (the design is not a valid scene)"}
        elif c.name in BOUNDED:
            value = values[c.name]
            excess = _excess(value, c.low, c.high)
            out[c.name] = {"value": value, "violation": excess,
                           "message": "" if excess == 0.0 else f"{c.name} = {value:.5g}, outside {c.text()}"}
    kinematics_kept = valid and not any(entry["violation"] for entry in out.values())
    for c in constraints:
        if c.name in FLAGS and valid and not kinematics_kept:
            out[c.name] = {"value": None, "violation": None, "message": "not judged (a kinematic constraint fails)"}
        elif c.name in FLAGS and valid:  # bushing
            over = []
            violation = 0.0
            for name, (value, limit) in sorted(bushing_values(checks()).items()):
                if limit is not None and value > limit:
                    violation += 100.0 * (value / limit - 1.0)
                    over.append(f"ideal {name} {value / 1e6:.4g} above {limit / 1e6:.4g}")
            out[c.name] = {"value": violation, "violation": violation, "message": "; ".join(over)}
    return out


def feasible(judged: dict[str, dict]) -> bool:
    return all(entry["violation"] in (0.0, None) for entry in judged.values()) and judged["assembly"]["violation"] == 0.0 \
        and judged["scene"]["violation"] == 0.0


def violated(judged: dict[str, dict]) -> list[str]:
    """Names of the constraints a design violates."""
    return [name for name, entry in judged.items() if entry["violation"]]
