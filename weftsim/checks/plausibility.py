"""Plausibility of a finished run's contact history, and where the contact law is used outside its range.

Engine-independent: everything is read from a result's per-step channels (and the engines' own
counters where they report them), with numpy only.  Two kinds of finding:

**Defects** (the run fails, :func:`weftsim.checks.guards.plausibility_breach`): a contact history no
correct integration of the model produces.

- *Onset with a non-positive approach rate.*  An onset is a crossing of delta from negative to
  positive while the journal approaches (delta_dot > 0).  Read at the first state of each
  contact (the located onset in the reference engine, the end of the onset step in the Exudyn
  engine): delta_dot <= 0 there is a root of the previous separation found again by round-off,
  or an impact shorter than one step.  Its held impact velocity is then v_min, and the damping
  term xi delta_dot / v_imp of the rest of the contact is hundreds of times too large.
- *Damping above the isolated-impact bound, under the ``max_approach`` rule.*  Every law has
  F_N = F_el (1 + xi delta_dot / v_imp), so ``(F_N - F_el) / (xi F_el) = delta_dot / v_imp`` at
  each step in contact.  The laws were derived for an isolated impact, in which delta_dot only
  falls after the onset: the damping force stays within xi x the elastic force, the ratio within 1
  (Lankarani & Nikravesh 1990).  The default rule ``max_approach`` (v_imp = the largest approach
  rate since the onset) keeps every step of every contact within that bound by construction, so a
  step above ``limits.max_damping_ratio`` (default 1, beyond a relative round-off of
  :data:`DAMPING_ROUNDOFF`) is an engine that did not hold v_imp as the rule says.  Measured with
  the reference engine: 1 + 5e-15 at most, on the reference scene (2 revolutions) and the 500 rpm,
  c = 0.25 mm paper scene (10 revolutions).  Under the literature's ``onset`` rule a driven lasting
  contact exceeds the bound as a property of the model (14.3 and 33.8 on those two runs, while their
  peak forces per revolution stay within 1.1 x the median): counted, and a warning, not a failure.
- *Negative penetration inside a contact.*  A step of a contact segment whose delta is below
  -:func:`roundoff_penetration`: the journal left the bearing and came back between two step
  ends (a missed separation), and the contact force was applied across a free flight.

**Validity warnings** (the run stands; :attr:`Plausibility.warnings`):

- restitution outside the law's ``valid_restitution`` (the range its xi(ce) was derived for);
- largest penetration above the law's ``valid_penetration_ratio`` of the clearance
  (:mod:`weftsim.joint.contact`).  The Hertz-based laws (``lankarani_nikravesh``, ``flores``,
  ``hunt_crossley``, ``gonthier``: :data:`PENETRATION_WARNING_RATIO`) build on Hertz's contact of two
  cylinders, which assumes a contact width small against the radii.  Two conforming cylinders at
  approach delta overlap over a half-width of about R_j sqrt(2 delta / c) (the gap x^2 / (2 R*) with
  R* = R_j R_b / c closes there); at delta = c / 10 that is 0.45 R_j, an arc of +-25 deg: no longer
  small.  The conformal laws (``variable_kd``, ``elastic_foundation``) are Liu's elastic foundation,
  written for exactly that wide arc (small clearance, large load: a 30 kN load presses a 30 mm steel
  pin about 40 um into a bushing of 20 um clearance): the clearance sets them no bound;
- peak contact pressure above the first-yield pressure of the weaker material, when a scene
  gives ``yield_strength_mpa``: the Hertz line-contact pressure of a cylinder in a conforming
  bore (Johnson, *Contact Mechanics*, 1985, section 4.3),

      p0 = sqrt(P' E* / (pi R*)),   P' = F_N,max / L_b,   1/R* = 1/R_j - 1/R_b,

  against first yield at p0 = 1.67 Y below the surface (Tresca; Johnson 1985, section 6.2).
  Hertz overestimates the pressure of a wide conforming contact, so this is a first estimate;
- a lubricated joint's film below its floor (film ratio under ``lubrication.film_floor_ratio``): there the
  film force is the rigid film continued, not solved, and held below its wall (sigma / 4,
  :mod:`weftsim.physics.lubricated`), so the peaks of such a squeeze depend on the floor: measured on the
  reference scene's oiled start-up impact (c = 0.5 mm, 80 mPa s), the film force peaks at 33-41 MN (100 GPa
  over the pin) and the driving torque at 144, 155, 177 kN m for floors 0.25, 0.5, 1 sigma.  What would bound
  the film there, the solids' elastic deformation under it, is not in the transient film
  (docs/lubricated-joint.md).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from weftsim.joint.contact import _Law
    from weftsim.input.params import ClearanceJoint, Scene
    from weftsim.post.results import RunResult

PENETRATION_WARNING_RATIO = 0.1  # delta_max / c of the Hertz-based laws (contact._Law.valid_penetration_ratio)
TRESCA_LINE_CONTACT_YIELD = 1.67  # p0 / Y at first yield under a Hertz line contact (Johnson 1985, 6.2)
# delta = |e| - c with e a sum of four link-length terms (L_OG + L_FG cos a - L_EF cos psi - L_OE cos q):
# each rounds to within eps * L, hypot and the subtraction add a few eps more.  64 ulps of the summed
# lengths (9e-15 m for the reference mechanism) sits above the 1.4e-15 m measured at the located
# onsets of the reference scene (the root's own round-off) and nine orders below a micrometre.
ROUNDOFF_ULPS = 64
# (F_N - F_el) / (xi F_el) under max_approach, measured: at most 1 + 5e-15 in the reference engine (two
# evaluations of the law at the same delta), 1 - 4e-10 in Exudyn's rigid-body model and 1 + 8.1e-9 in its
# kinematic tree (the cause of the 8e-9 was not traced: an exceedance in the 8th digit at 3 steps of the
# start-up impact), with the max_approach implementation of the Exudyn engine's branch.  1e-6 sits 100x above that and far
# below the smallest real excess seen (1.08: Exudyn's start-up impact with the onset value held).
DAMPING_ROUNDOFF = 1e-6
# The ratio is judged only where the contact force is at least this fraction of the run's largest: at the
# first step of a contact (delta ~ 1e-9 m, F_N ~ 1e-5 N) the ratio of two vanishing forces carries the
# round-off of the in-step onset estimate, measured up to 1 + 1.03e-6 in the kinematic tree over 40
# revolutions at c = 0.5 mm (F_N 9.6e-6 N, an excess of 1e-11 N), and no force.  The defects this guard
# is for are damping forces of the order of the peaks (issue 11: 6.56 MN, 44 times the run's median).
DAMPING_FORCE_FLOOR = 1e-6


@dataclass(frozen=True)
class Plausibility:
    """Counts and warnings of one run (see the module docstring for each).

    Attributes
    ----------
    onsets : int
        Contact onsets seen in the per-step data.
    nonpositive_onsets : int
        Of those, onsets whose approach rate at the first contact state is <= 0 (defect).
    engine_nonpositive_onsets : int or None
        The engine's own ``nonpositive_onsets`` (``events`` or ``solver_stats``), if it reports
        one: for information, since engines differ in what they count (the reference engine
        counts the onsets it accepted without a rising root, which the per-step count sees too;
        an engine may also count estimates it replaced by a positive one, which are no defect).
    damping_steps : int
        Contact steps with (F_N - F_el) / (xi F_el) above ``damping_limit`` (a defect under the
        ``max_approach`` rule, a warning under ``onset``).
    max_damping_ratio : float
        Largest (F_N - F_el) / (xi F_el) = delta_dot / v_imp of the run (0 without contact).
    damping_limit : float
        ``limits.max_damping_ratio``.
    damping_bound_enforced : bool
        True under ``joint_e.impact_velocity_rule = "max_approach"``, which bounds the ratio: there a step above
        ``damping_limit`` is a defect (``damping_steps`` counts them; 0, none), under ``onset`` a warning.
    negative_penetration_steps : int
        Steps of a contact segment with delta < -``roundoff_m`` (defect).
    min_penetration_in_contact_m : float or None
        Smallest delta of a contact step, m.
    roundoff_m : float
        Round-off of delta, m (:func:`roundoff_penetration`).
    max_penetration_over_clearance : float
        Largest delta / c, the law's validity measure (not ``limits.max_penetration_ratio``, which bounds delta
        over the journal radius R_j during the run).
    peak_pressure_pa : float
        Hertz line-contact pressure at the peak contact force, Pa.
    yield_pressure_pa : float or None
        1.67 x the smaller yield strength given in the scene, Pa; None if none is given.
    warnings : tuple of str
        One sentence per validity warning.
    """

    onsets: int
    nonpositive_onsets: int
    engine_nonpositive_onsets: int | None
    damping_steps: int
    max_damping_ratio: float
    damping_limit: float
    damping_bound_enforced: bool
    negative_penetration_steps: int
    min_penetration_in_contact_m: float | None
    roundoff_m: float
    max_penetration_over_clearance: float
    peak_pressure_pa: float
    yield_pressure_pa: float | None
    warnings: tuple[str, ...]

    def defects(self) -> list[str]:
        """One phrase per defect count that is not zero."""
        out = []
        if self.nonpositive_onsets:
            out.append(f"{self.nonpositive_onsets} of {self.onsets} contact onsets have a non-positive approach rate")
        if self.damping_steps and self.damping_bound_enforced:
            out.append(f"{self.damping_steps} contact steps have a damping force above limits.max_damping_ratio = "
                       f"{self.damping_limit:g} times the law's xi x the elastic force (largest "
                       f"{self.max_damping_ratio:.3g})")
        if self.negative_penetration_steps:
            out.append(f"{self.negative_penetration_steps} contact steps have a negative penetration (down to "
                       f"{self.min_penetration_in_contact_m:.3g} m, round-off {self.roundoff_m:.2g} m)")
        return out

    def as_dict(self) -> dict:
        """JSON-ready (the ``plausibility`` block of summary.json)."""
        out = asdict(self)
        out["warnings"] = list(self.warnings)
        out["defects"] = self.defects()
        return out

    def summary_line(self) -> str:
        """The counts in one line (for stderr)."""
        engine = "" if self.engine_nonpositive_onsets is None else f" (engine's count {self.engine_nonpositive_onsets})"
        return (f"plausibility: {self.onsets} contact onsets, {self.nonpositive_onsets} with a non-positive approach "
                f"rate{engine}; {self.damping_steps} steps with damping above {self.damping_limit:g} x xi x elastic "
                f"(largest {self.max_damping_ratio:.3g}); {self.negative_penetration_steps} contact steps with "
                "negative penetration")


def roundoff_penetration(scene: Scene) -> float:
    """Round-off of ``delta = |e| - c``, m: :data:`ROUNDOFF_ULPS` ulps of the summed link lengths."""
    g = scene.geometry
    return ROUNDOFF_ULPS * float(np.finfo(float).eps) * (g.l_oe + g.l_ef + g.l_fg + g.l_og)


def contact_mode(steps: dict) -> np.ndarray:
    """Steps of a contact segment: both engines hold v_imp > 0 (>= v_min) there and write 0 in free flight."""
    return np.asarray(steps["impact_velocity_m_s"]) > 0.0


def onset_rows(mode: np.ndarray) -> np.ndarray:
    """Rows that start a contact segment (contact mode after a free-flight row)."""
    return np.flatnonzero(mode[1:] & ~mode[:-1]) + 1


def damping_excess(ratio: np.ndarray, limit: float) -> np.ndarray:
    """Steps whose damping ratio exceeds ``limit`` beyond round-off (:data:`DAMPING_ROUNDOFF`)."""
    return ratio > limit * (1.0 + DAMPING_ROUNDOFF)


def damping_ratio(steps: dict, law: _Law) -> np.ndarray:
    """(F_N - F_el) / (xi F_el) = delta_dot / v_imp at the steps in contact (delta > 0) whose force is at
    least :data:`DAMPING_FORCE_FLOOR` of the run's largest; 0 elsewhere."""
    delta = np.asarray(steps["penetration_m"])
    inside = contact_mode(steps) & (delta > 0.0)
    ratio = np.zeros(delta.size)
    if law.hysteresis <= 0.0 or not inside.any():
        return ratio
    f_el = np.asarray(law.elastic_force(delta[inside]), dtype=float)
    forces = np.asarray(steps["contact_force_N"])
    f_n = forces[inside]
    positive = (f_el > 0.0) & (f_n >= DAMPING_FORCE_FLOOR * forces.max())
    values = np.zeros(f_el.size)
    values[positive] = (f_n[positive] - f_el[positive]) / (law.hysteresis * f_el[positive])
    ratio[inside] = values
    return ratio


def line_contact_pressure(force: float, joint: ClearanceJoint) -> float:
    """Hertz peak pressure p0 = sqrt(P' E* / (pi R*)) of a journal in a conforming bore, Pa.

    P' = force / L_b (N/m), 1/R* = 1/R_j - 1/R_b (Johnson 1985, section 4.3).
    """
    if force <= 0.0:
        return 0.0
    relative_radius = joint.journal_radius * joint.bearing_radius / joint.clearance
    return math.sqrt(force / joint.bearing_length * joint.effective_modulus / (math.pi * relative_radius))


def _yield_strength(joint) -> float | None:
    given = [m.yield_strength for m in (joint.journal_material, joint.bearing_material) if m.yield_strength is not None]
    return min(given) if given else None


def _engine_count(result) -> int | None:
    for source in (result.events, result.solver_stats):
        value = source.get("nonpositive_onsets")
        if value is not None:
            return int(value)
    return None


def validity_warnings(scene: Scene, law: _Law, max_penetration_ratio: float, peak_pressure: float,
                      yield_pressure: float | None, damping_steps: int = 0, max_damping: float = 0.0,
                      table: str = "joint_e") -> list[str]:
    """The law-range warnings of a clearance run (module docstring); ``damping_steps`` count under "onset".

    ``scene.joint`` is the joint judged, ``table`` its scene table (joint F's warnings name [joint_f]).
    """
    joint = scene.joint
    out = []
    if damping_steps and joint.impact_velocity_rule != "max_approach":
        out.append(f"{damping_steps} contact steps have a damping force above {scene.limits.max_damping_ratio:g} x xi "
                   f"x the elastic force (largest {max_damping:.3g}), beyond any isolated impact the law was derived "
                   "for: the \"onset\" rule in a lasting contact; joint_e.impact_velocity_rule = \"max_approach\" "
                   "bounds it".replace("joint_e", table))
    lo, hi = law.valid_restitution
    if not lo <= joint.restitution <= hi:
        out.append(f"{table}.restitution = {joint.restitution:g} is outside {lo:g}..{hi:g}, the range the "
                   f"'{law.name}' law's damping was derived for: its restitution is not what the scene asks; "
                   "choose a law valid there (e.g. 'flores' for any ce)")
    at = "" if table == "joint_e" else " at F"
    bound = law.valid_penetration_ratio
    if bound is not None and max_penetration_ratio > bound:
        out.append(f"the largest penetration{at} is {max_penetration_ratio:.3g} of the clearance (above {bound:g}, "
                   f"the range of the '{law.name}' law: {law.penetration_basis}); read peak forces as estimates, "
                   f"or choose a conformal-contact law ({table}.law = \"variable_kd\" or \"elastic_foundation\")")
    if yield_pressure is not None and peak_pressure > yield_pressure:
        out.append(f"the peak Hertz contact pressure{at} {peak_pressure / 1e6:.4g} MPa exceeds first yield "
                   f"{yield_pressure / 1e6:.4g} MPa (1.67 x the smaller {table}.*_material.yield_strength_mpa): the joint "
                   f"would deform plastically, which no law here models; a larger pin or a smaller clearance "
                   f"({table}.journal_radius_mm, {table}.bearing_length_mm, {table}.clearance_mm)")
    return out


def film_floor_warning(scene: Scene, steps: dict[str, np.ndarray], table: str = "joint_e") -> list[str]:
    """The warning of a lubricated joint whose film went below its floor (module docstring); [] otherwise.

    ``scene.joint`` is the joint judged, ``steps`` its channels under joint E's names (:func:`joint_view`).
    """
    lub = scene.joint.lubrication
    if lub is None or "film_ratio" not in steps:
        return []
    ratio = np.asarray(steps["film_ratio"])
    below = ratio < lub.film_floor_ratio
    if not below.any():
        return []
    first = float(np.asarray(steps["time_s"])[np.argmax(below)])
    count = int(below.sum())
    return [f"the film at {table[-1].upper()} went below its floor ({table}.lubrication.film_floor_ratio = "
            f"{lub.film_floor_ratio:g}): film ratio down to {float(ratio.min()):.3g} at {count} step{'s' * (count != 1)}, "
            f"first at t = {first:.4g} s; there the film is the rigid film continued, not solved (held below "
            "sigma / 4), so the peaks of that squeeze depend on the floor (the solids' elastic deformation, which "
            "would bound it, is not in the transient film): compare a run at another film_floor_ratio"]


def joint_view(result: RunResult, joint: str) -> tuple[Scene, dict[str, np.ndarray]]:
    """(scene, steps) of one clearance joint in E's place: ``scene.joint`` is the joint, the steps hold its
    channels under joint E's names (joint F's ``_f`` channels renamed), so every check reads one joint."""
    import dataclasses

    from weftsim.model.channels import JOINT_E_NAME, LUBRICATION_CHANNELS, LUBRICATION_CHANNELS_F

    if joint == "e":
        return result.scene, result.steps
    steps = dict(result.steps)
    steps.update({e_name: result.steps[f_name] for f_name, e_name in JOINT_E_NAME.items()})
    for f_name, e_name in zip(LUBRICATION_CHANNELS_F, LUBRICATION_CHANNELS):  # F's film, or none (E's is not F's)
        steps.pop(e_name, None)
        if f_name in result.steps:
            steps[e_name] = result.steps[f_name]
    steps.pop("joint_force_N", None)
    if "joint_force_f_N" in result.steps:  # the joint's load (weftsim.joint.load)
        steps["joint_force_N"] = result.steps["joint_force_f_N"]
    return dataclasses.replace(result.scene, joint=result.scene.joint_f), steps


def assess(result: RunResult) -> Plausibility | None:
    """Counts and warnings of a run with clearance joints; None for the ideal mechanism or no steps.

    Each joint with a clearance is judged on its own channels (:func:`joint_view`); with two, the
    counts add up, the extremes are the larger and the warnings of both are kept.
    """
    if result.scene.is_ideal or result.steps["time_s"].size == 0:
        return None
    reports = [_assess_joint(result, *joint_view(result, joint), f"joint_{joint}")
               for joint in result.scene.loose_joints]
    if len(reports) == 1:
        return reports[0]
    e, f = reports
    present = [v for v in (e.min_penetration_in_contact_m, f.min_penetration_in_contact_m) if v is not None]
    return Plausibility(
        onsets=e.onsets + f.onsets,
        nonpositive_onsets=e.nonpositive_onsets + f.nonpositive_onsets,
        engine_nonpositive_onsets=e.engine_nonpositive_onsets,  # the engine's count covers both joints
        damping_steps=e.damping_steps + f.damping_steps,
        max_damping_ratio=max(e.max_damping_ratio, f.max_damping_ratio),
        damping_limit=e.damping_limit,
        damping_bound_enforced=e.damping_bound_enforced or f.damping_bound_enforced,
        negative_penetration_steps=e.negative_penetration_steps + f.negative_penetration_steps,
        min_penetration_in_contact_m=min(present) if present else None,
        roundoff_m=max(e.roundoff_m, f.roundoff_m),
        max_penetration_over_clearance=max(e.max_penetration_over_clearance, f.max_penetration_over_clearance),
        peak_pressure_pa=max(e.peak_pressure_pa, f.peak_pressure_pa),
        yield_pressure_pa=e.yield_pressure_pa if f.yield_pressure_pa is None else (
            f.yield_pressure_pa if e.yield_pressure_pa is None else min(e.yield_pressure_pa, f.yield_pressure_pa)),
        warnings=e.warnings + f.warnings,
    )


def _assess_joint(result, scene, steps, table: str) -> Plausibility:
    """:func:`assess` of one joint: ``scene.joint`` and the E-named channels of ``steps`` are that joint's."""
    from weftsim.joint.contact import make_law

    law = make_law(scene.joint)
    mode = contact_mode(steps)
    delta = np.asarray(steps["penetration_m"])
    rate = np.asarray(steps["penetration_rate_m_s"])
    starts = onset_rows(mode)
    ratio = damping_ratio(steps, law)
    limit = scene.limits.max_damping_ratio
    roundoff = roundoff_penetration(scene)
    joint = scene.joint
    peak_pressure = line_contact_pressure(float(np.max(steps["contact_force_N"])), joint)
    strength = _yield_strength(joint)
    yield_pressure = None if strength is None else TRESCA_LINE_CONTACT_YIELD * strength
    max_penetration_ratio = max(float(np.max(delta)), 0.0) / joint.clearance
    damping_steps = int(np.count_nonzero(damping_excess(ratio, limit)))
    return Plausibility(
        onsets=int(starts.size),
        nonpositive_onsets=int(np.count_nonzero(rate[starts] <= 0.0)),
        engine_nonpositive_onsets=_engine_count(result),
        damping_steps=damping_steps,
        max_damping_ratio=float(ratio.max()),
        damping_limit=limit,
        damping_bound_enforced=joint.impact_velocity_rule == "max_approach",
        negative_penetration_steps=int(np.count_nonzero(mode & (delta < -roundoff))),
        min_penetration_in_contact_m=float(delta[mode].min()) if mode.any() else None,
        roundoff_m=roundoff,
        max_penetration_over_clearance=max_penetration_ratio,
        peak_pressure_pa=peak_pressure,
        yield_pressure_pa=yield_pressure,
        warnings=tuple(validity_warnings(scene, law, max_penetration_ratio, peak_pressure, yield_pressure,
                                         damping_steps, float(ratio.max()), table))
                 + tuple(film_floor_warning(scene, steps, table)),
    )


HINT = ("the contact history is broken, so its forces are not to be trusted: for a non-positive onset or a negative "
        "penetration in contact try a tighter solver tolerance or a smaller step (an impact or a free flight shorter "
        "than one step); damping above the limit under the max_approach rule means the engine did not hold the "
        "impact velocity as the rule says (report it; limits.max_damping_ratio only sets the round-off margin)")


def first_defect_row(result: RunResult, report: Plausibility) -> int:
    """Index of the first step showing one of the defects (for the failure message's time), at any joint."""
    from weftsim.joint.contact import make_law

    rows = []
    for joint in result.scene.loose_joints:
        scene, steps = joint_view(result, joint)
        mode = contact_mode(steps)
        starts = onset_rows(mode)
        bad_onsets = starts[np.asarray(steps["penetration_rate_m_s"])[starts] <= 0.0]
        rows.extend(bad_onsets[:1].tolist())
        if report.damping_steps and report.damping_bound_enforced:
            excess = np.flatnonzero(damping_excess(damping_ratio(steps, make_law(scene.joint)), report.damping_limit))
            rows.extend(excess[:1].tolist())
        negative = np.flatnonzero(mode & (np.asarray(steps["penetration_m"]) < -report.roundoff_m))
        rows.extend(negative[:1].tolist())
    return min(rows) if rows else 0
