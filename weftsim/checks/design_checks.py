"""Is the scene a machine a designer would build?  Plausibility checks before and after a run.

Each check compares one number with a limit and names the scene key to change (docs/plausibility.md
gives every formula, default and source):

=======================  ===========================================  ============================================
check                    value                                        limit (scene key)
=======================  ===========================================  ============================================
``reflected_mass``       m_eff of the chain behind the pin (peak)     none: reported (:mod:`weftsim.mechanism.pin_loads`)
``clearance_ratio``      c / d, radial clearance over pin diameter    ``joint_*.design_clearance_per_mille``
``pin_pressure``         peak projected pressure F / (d L_b)          ``joint_*.bearing_material.max_pressure_mpa``
``pv``                   cycle mean of p x v, v = R_j abs(omega_rel)  ``joint_*.bearing_material.max_pv_mpa_m_s``
``hertz_pressure``       Hertz line-contact pressure at peak force    1.67 x the smaller ``yield_strength_mpa``
``penetration``          largest delta / c (after the run only)       the law's range (:mod:`weftsim.joint.contact`)
``rapier_acceleration``  peak of abs(rapier acceleration)             ``limits.max_rapier_acceleration_m_s2``
``film_temperature``     film temperature of an oiled joint           none: reported (:mod:`weftsim.joint.heat`)
=======================  ===========================================  ============================================

*Before the run* (:func:`before_run`) the loads come from the ideal mechanism at the scene's speed
(:func:`weftsim.mechanism.pin_loads.ideal_pin_loads`): no simulation.  *After the run* (:func:`after_run`) they
come from the run's contact force channels (peaks over every solver step, means over the output grid,
which is uniform in time) and the sliding speed of the ideal kinematics at the same crank angle, from
revolution 2 on when the run has two (:func:`running`: revolution 1 holds the start-up impact of the
centred journal, which a running machine does not see); the law's range (penetration, Hertz) is judged
over the whole run, as :mod:`weftsim.checks.plausibility` judges it.
Joint checks are made at each joint with a clearance (E, and F when it has one).  A check whose
limit the scene does not give has the verdict ``"no_limit"``; the reflected mass is always
``"info"``.  The ``hertz_pressure`` and ``penetration`` warnings after the run are
:func:`weftsim.checks.plausibility.validity_warnings`' own (not repeated here).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.mechanism.pin_loads import SAMPLES, ideal_pin_loads, sliding_speed_at
from weftsim.checks.plausibility import (
    TRESCA_LINE_CONTACT_YIELD,
    Plausibility,
    _yield_strength,
    joint_view,
    line_contact_pressure,
)

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.post.results import RunResult

VERDICTS = ("ok", "warning", "no_limit", "info")


@dataclass(frozen=True)
class Check:
    """One plausibility check: value against limit, and the verdict.

    Attributes
    ----------
    name : str
        The check (module table).
    stage : str
        ``"before"`` (ideal kinematics, no simulation) or ``"after"`` (the run's channels).
    table : str or None
        The scene table of the joint judged (``"joint_e"``, ``"joint_f"``); None for the mechanism.
    value : float
        The number judged, SI (``unit``).
    limit : float, list of float or None
        The limit, SI; ``[low, high]`` for a range; None when the scene gives none.
    unit : str
    key : str or None
        The scene key that sets the limit.
    verdict : str
        One of :data:`VERDICTS`.
    numbers : dict
        Further numbers of the check (means, peaks, forces), SI, names carry the unit.
    message : str
        The warning (one line naming the key to change); empty unless ``verdict == "warning"``.
    """

    name: str
    stage: str
    table: str | None
    value: float
    limit: float | list[float] | None
    unit: str
    key: str | None
    verdict: str
    numbers: dict = field(default_factory=dict)
    message: str = ""

    def as_dict(self) -> dict:
        """JSON-ready (plain floats and lists, so a saved result reloads equal)."""
        limit = [float(v) for v in self.limit] if isinstance(self.limit, (list, tuple)) else (
            None if self.limit is None else float(self.limit))
        return {"name": self.name, "stage": self.stage, "table": self.table, "value": float(self.value),
                "limit": limit, "unit": self.unit, "key": self.key, "verdict": self.verdict,
                "numbers": {k: float(v) for k, v in self.numbers.items()}, "message": self.message}


def _judge(value: float, limit: float | None) -> str:
    if limit is None:
        return "no_limit"
    return "warning" if value > limit else "ok"


def _when(stage: str) -> str:
    return "the ideal mechanism (before the run)" if stage == "before" else "the run"


def _pin(table: str, joint) -> str:
    return (f"a {2e3 * joint.journal_radius:g} x {1e3 * joint.bearing_length:g} mm pin "
            f"({table}.journal_radius_mm, {table}.bearing_length_mm)")


def pressure_checks(stage: str, table: str, joint, force_peak: float, force_mean: float, pv_mean: float,
                    pv_peak: float, speed_peak: float, hertz_force: float | None = None,
                    numbers: dict | None = None, note: str = "") -> list[Check]:
    """``pin_pressure``, ``pv`` and ``hertz_pressure`` of one pin's loads (the Hertz pressure of
    ``hertz_force``, default ``force_peak``); ``numbers`` are added to the first two checks' numbers."""
    numbers = numbers or {}
    hertz_force = force_peak if hertz_force is None else hertz_force
    area = 2.0 * joint.journal_radius * joint.bearing_length
    p_peak, p_mean = force_peak / area, force_mean / area
    out = []
    material = joint.bearing_material
    key = f"{table}.bearing_material.max_pressure_mpa"
    verdict = _judge(p_peak, material.max_pressure)
    message = "" if verdict != "warning" else (
        f"{table}: {_when(stage)} presses {_pin(table, joint)} with up to {p_peak / 1e6:.4g} MPa of projected "
        f"pressure F/(d B) (peak force {force_peak / 1e3:.4g} kN), above the bushing's {key} = "
        f"{material.max_pressure / 1e6:g}: a larger pin or a lighter chain behind it{note}")
    out.append(Check("pin_pressure", stage, table, p_peak, material.max_pressure, "Pa", key, verdict,
                     {"mean_pa": p_mean, "peak_force_n": force_peak, "mean_force_n": force_mean, **numbers}, message))
    key = f"{table}.bearing_material.max_pv_mpa_m_s"
    verdict = _judge(pv_mean, material.max_pv)
    message = "" if verdict != "warning" else (
        f"{table}: in {_when(stage)} the pin's p x v averages {pv_mean / 1e6:.4g} MPa m/s over a revolution (peak "
        f"{pv_peak / 1e6:.4g}, sliding speed up to {speed_peak:.3g} m/s), above the bushing's {key} = "
        f"{material.max_pv / 1e6:g}: a larger pin ({table}.bearing_length_mm), a slower drive (drive.speed_rpm) "
        f"or a bushing rated higher{note}")
    out.append(Check("pv", stage, table, pv_mean, material.max_pv, "Pa m/s", key, verdict,
                     {"peak_pa_m_s": pv_peak, "peak_sliding_speed_m_s": speed_peak, **numbers}, message))
    strength = _yield_strength(joint)
    yield_pressure = None if strength is None else TRESCA_LINE_CONTACT_YIELD * strength
    hertz = line_contact_pressure(hertz_force, joint)
    verdict = _judge(hertz, yield_pressure)
    # after: validity_warnings says it; a "warning" has a limit (_judge gives "no_limit" for yield_pressure None)
    message = "" if verdict != "warning" or stage == "after" or yield_pressure is None else (
        f"{table}: the ideal mechanism's peak pin force {hertz_force / 1e3:.4g} kN gives a Hertz contact pressure "
        f"of {hertz / 1e6:.4g} MPa (before the run), above first yield {yield_pressure / 1e6:.4g} MPa (1.67 x the "
        f"smaller {table}.*_material.yield_strength_mpa): a larger pin or a smaller clearance ({table}.clearance_mm)")
    out.append(Check("hertz_pressure", stage, table, hertz, yield_pressure, "Pa",
                     f"{table}.bearing_material.yield_strength_mpa", verdict, {"peak_force_n": hertz_force}, message))
    return out


def joint_checks_before(scene: Scene, joint_name: str) -> list[Check]:
    """The before-run checks of one joint with a clearance (``"e"`` or ``"f"``)."""
    table = f"joint_{joint_name}"
    joint = scene.joint if joint_name == "e" else scene.joint_f
    loads = ideal_pin_loads(scene, joint_name)
    out = [Check("reflected_mass", "before", table, float(loads.reflected_mass.max()), None, "kg", None, "info",
                 {"mean_kg": float(loads.reflected_mass.mean())})]
    ratio = joint.clearance / (2.0 * joint.journal_radius)
    low, high = joint.design_clearance
    key = f"{table}.design_clearance_per_mille"
    inside = low <= ratio <= high
    message = "" if inside else (
        f"{table}: radial clearance / pin diameter is {1e3 * ratio:.4g} per mille ({table}.clearance_mm = "
        f"{1e3 * joint.clearance:g} on a {2e3 * joint.journal_radius:g} mm pin), outside the design range "
        f"{1e3 * low:g}-{1e3 * high:g} per mille ({key}): " + (
            "a worn or oversized joint; a new bushed pin has less" if ratio > high else
            "tighter than a running fit; a new bushed pin has more"))
    out.append(Check("clearance_ratio", "before", table, ratio, [low, high], "1", key,
                     "ok" if inside else "warning", {}, message))
    pv = loads.force / (2.0 * joint.journal_radius * joint.bearing_length) * loads.sliding_speed
    out += pressure_checks("before", table, joint, float(loads.force.max()), float(loads.force.mean()),
                           float(pv.mean()), float(pv.max()), float(loads.sliding_speed.max()))
    return out + film_temperature_checks(table, joint)


def film_temperature_checks(table: str, joint) -> list[Check]:
    """``film_temperature`` (info) of an oiled joint: the effective film temperature the heat balance found at the
    ideal mechanism's mean load and sliding speed, and the viscosity the run takes there (weftsim.joint.heat)."""
    lub = joint.lubrication
    if lub is None or not lub.has_oil or lub.film_temperature is None:
        return []
    numbers = {"viscosity_pa_s": lub.viscosity, "ambient_c": lub.ambient_temperature}
    return [Check("film_temperature", "before", table, lub.film_temperature, None, "C", f"{table}.lubrication.oil",
                  "info", numbers)]


def rapier_check(scene: Scene, stage: str, peak: float, numbers: dict | None = None, note: str = "") -> Check:
    """``rapier_acceleration``: ``peak`` abs(a) (m/s^2) against ``limits.max_rapier_acceleration_m_s2``."""
    limit = scene.limits.max_rapier_acceleration
    key = "limits.max_rapier_acceleration_m_s2"
    verdict = _judge(peak, limit)
    message = "" if verdict != "warning" else (
        f"the rapier's acceleration in {_when(stage)} peaks at {peak:.4g} m/s2, above what rapier heads are built "
        f"for ({key} = {limit:g}): a lower drive.speed_rpm, a longer insertion (mechanism) " + (
            "or a smaller clearance (the impacts' spikes)" if stage == "after" else "or a rapier head rated higher")
        + note)
    return Check("rapier_acceleration", stage, None, peak, limit, "m/s2", key, verdict, dict(numbers or {}), message)


# (scene, checks) of the last :func:`before_run`: a run asks for its scene's before-run checks twice (their
# warnings before the engine starts, then its plausibility block), so the second reads them here.  Keyed by
# the scene object itself (a Scene is frozen, and this holds it, so its identity cannot be reused).
_LAST_BEFORE: tuple = (None, ())


def before_run(scene: Scene) -> list[Check]:
    """Every check that needs no simulation: each loose joint's, then the rapier's."""
    global _LAST_BEFORE
    from weftsim.mechanism.kinematics import linkage_state

    last, checks = _LAST_BEFORE
    if last is scene:
        return list(checks)
    out = []
    for name in scene.loose_joints:
        out += joint_checks_before(scene, name)
    theta = np.arange(SAMPLES) * (2.0 * np.pi / SAMPLES)
    st = linkage_state(theta, scene.geometry, scene.inertia.rocker_com)
    peak = float(np.max(np.abs(st.dd_rapier_displacement))) * scene.drive.speed**2
    out.append(rapier_check(scene, "before", peak))
    _LAST_BEFORE = (scene, tuple(out))
    return out


# Said after an after-run warning of a run shorter than two revolutions, whose loads include the start-up.
STARTUP_NOTE = ("; the run is shorter than two revolutions, so the start-up impact of the centred journal in "
                "revolution 1 counts (drive.revolutions = 2 or more judges the running machine)")


def running(result: RunResult) -> RunResult:
    """``result`` from its second revolution on, when it covers at least two; else all of it.

    Revolution 1 starts from the centred journal with the ideal mechanism's velocities: the journal
    crosses the clearance freely and strikes the bearing (the start-up impact, docs/physics.md section 6),
    which a running machine, whose pin already bears on its bushing, does not see.  On the loom at
    600 rpm and c = 0.02 mm that impact reaches 35 kN against 11.7 kN in revolution 2.  The run's
    printed peaks are revolution 2's; the loads are judged on the same revolutions.
    """
    import dataclasses

    period = result.scene.drive.period
    if result.steps["time_s"].size == 0 or result.steps["time_s"][-1] < 2.0 * period * (1.0 - 1e-9):
        return result

    def after(channels):
        keep = np.asarray(channels["time_s"]) >= period
        return {name: np.asarray(values)[keep] for name, values in channels.items()}

    return dataclasses.replace(result, steps=after(result.steps), samples=after(result.samples))


def after_run(result: RunResult) -> list[Check]:
    """The checks of a finished run's channels (nothing for a run without steps).

    The machine's loads (pin pressure, p x v, rapier acceleration) are judged from revolution 2 on
    when the run has two or more (:func:`running`; ``numbers["from_time_s"]`` says where); the
    contact law's range (penetration, Hertz pressure) over the whole run, as
    :func:`weftsim.checks.plausibility.validity_warnings` judges and words it.
    """
    from weftsim.joint.contact import make_law
    from weftsim.joint.load import joint_load

    full = result
    result = running(full)
    scene = result.scene
    out: list[Check] = []
    if result.steps["time_s"].size == 0:
        return out
    window = {"from_time_s": float(result.steps["time_s"][0])}
    note = "" if result is not full or not scene.loose_joints else STARTUP_NOTE
    for name in scene.loose_joints:
        table = f"joint_{name}"
        joint_scene, steps = joint_view(result, name)
        joint = joint_scene.joint
        _, samples = joint_view(replace_steps(result), name)
        _, whole = joint_view(full, name)
        area = 2.0 * joint.journal_radius * joint.bearing_length
        # The load the joint carries (film + asperities + dry law, weftsim.joint.load); Hertz's pressure is the
        # dry law's contact alone.
        force_steps = np.asarray(joint_load(steps))
        force_samples = np.asarray(joint_load(samples)) if samples["time_s"].size else force_steps
        theta_steps = np.radians(np.asarray(steps["crank_angle_deg"]))
        theta_samples = np.radians(np.asarray(samples["crank_angle_deg"])) if samples["time_s"].size else theta_steps
        v_steps, v_samples = sliding_speed_at((theta_steps, theta_samples), scene, name, joint.journal_radius)
        out += pressure_checks("after", table, joint, float(force_steps.max()), float(force_samples.mean()),
                               float(np.mean(force_samples * v_samples)) / area,
                               float(np.max(force_steps * v_steps)) / area, float(v_steps.max()),
                               hertz_force=float(np.max(whole["contact_force_N"])), numbers=window, note=note)
        law = make_law(joint)
        ratio = max(float(np.max(whole["penetration_m"])), 0.0) / joint.clearance
        bound = law.valid_penetration_ratio
        out.append(Check("penetration", "after", table, ratio, bound, "1", f"{table}.law", _judge(ratio, bound),
                         {}, ""))
    peak = float(np.max(np.abs(result.steps["rapier_acceleration_m_s2"])))
    out.append(rapier_check(scene, "after", peak, window, note))
    return out


def replace_steps(result: RunResult) -> RunResult:
    """``result`` with its output samples in place of its steps (so :func:`joint_view` renames them)."""
    import dataclasses

    return dataclasses.replace(result, steps=result.samples)


def warnings_of(checks: list[Check]) -> list[str]:
    """The message of every check that warns, in order."""
    return [c.message for c in checks if c.verdict == "warning" and c.message]


def block(result: RunResult, report: dict) -> dict:
    """The ``plausibility`` block of a result: ``report`` (the contact-history counts and law warnings of
    :mod:`weftsim.checks.plausibility`, empty for the ideal mechanism) with ``checks`` (before and after the
    run) and the after-run checks' warnings added to ``warnings``."""
    before, after = before_run(result.scene), after_run(result)
    out = dict(report)
    out["checks"] = [c.as_dict() for c in before + after]
    out["warnings"] = list(report.get("warnings", [])) + warnings_of(after)
    return out


def before_run_lines(scene: Scene) -> list[str]:
    """The before-run numbers in one line, then ``warning: ...`` per before-run warning of ``scene`` (the
    command line prints them before the run)."""
    checks = before_run(scene)
    return [summary_line([c.as_dict() for c in checks], "before")] + [f"warning: {t}" for t in warnings_of(checks)]


def _limit(check: dict, scale: float, unit: str) -> str:
    limit = check["limit"]
    return f" (limit {limit / scale:.4g}{unit})" if limit is not None else " (no limit given)"


def _short(check: dict) -> str:
    """One check's numbers in a few words."""
    name, value, numbers = check["name"], check["value"], check["numbers"]
    if name == "reflected_mass":
        return f"reflected mass {value:.4g} kg peak, {numbers['mean_kg']:.4g} mean"
    if name == "clearance_ratio":
        low, high = check["limit"]
        return f"c/d {1e3 * value:.3g} per mille (design {1e3 * low:g}-{1e3 * high:g})"
    if name == "pin_pressure":
        return f"pin pressure {value / 1e6:.4g} MPa peak, {numbers['mean_pa'] / 1e6:.4g} mean" + _limit(check, 1e6, "")
    if name == "pv":
        return f"p x v {value / 1e6:.4g} MPa m/s mean" + _limit(check, 1e6, "")
    if name == "hertz_pressure":
        limit = check["limit"]
        return f"Hertz {value / 1e6:.4g} MPa" + (f" (first yield {limit / 1e6:.4g})" if limit is not None
                                                 else " (no yield strength given)")
    if name == "penetration":
        limit = check["limit"]
        return f"delta/c {value:.3g}" + (f" (law's range {limit:g})" if limit is not None else " (law: no bound)")
    if name == "film_temperature":
        return (f"film {value:.4g} C at {numbers['ambient_c']:.4g} C ambient "
                f"({1e3 * numbers['viscosity_pa_s']:.4g} mPa s)")
    return f"rapier acceleration {value:.4g} m/s2 peak" + _limit(check, 1.0, "")


def summary_line(checks: list[dict], stage: str) -> str:
    """The numbers of one stage's checks (dicts of :meth:`Check.as_dict`) in one line, grouped by joint."""
    start = max((c["numbers"].get("from_time_s", 0.0) for c in checks if c["stage"] == stage), default=0.0)
    # After a run of two or more revolutions the machine's loads are judged from revolution 2 on, the contact
    # law's range (Hertz pressure, delta/c) over the whole run, start-up impact included: said apart.
    whole = stage == "after" and start > 0.0
    groups: dict = {}
    law: dict = {}
    for check in checks:
        if check["stage"] == stage:
            into = law if whole and check["name"] in WHOLE_RUN_CHECKS else groups
            into.setdefault(check["table"], []).append(_short(check))

    def joined(by_table: dict) -> str:
        return "; ".join((f"{table}: " if table else "") + ", ".join(texts) for table, texts in by_table.items())

    when = ("before the run (ideal mechanism)" if stage == "before" else
            f"of the run from t = {start:.4g} s (revolution 2 on)" if whole else "of the run")
    text = f"design checks {when}: " + joined(groups)
    if law:
        text += f"; the contact law's range over the whole run, the start-up impact included: {joined(law)}"
    return text


# The after-run checks judged over the whole run (the contact law's range), not from revolution 2 on.
WHOLE_RUN_CHECKS = ("hertz_pressure", "penetration")


def format_lines(result: RunResult) -> list[str]:
    """The counts line, the after-run design checks' numbers (:mod:`weftsim.checks.design_checks`), and one
    ``warning:`` line per validity warning and per after-run design-check warning (stderr)."""
    block = result.plausibility
    if not block:
        return []
    lines = []
    if "onsets" in block:  # a mechanism with a clearance joint: the contact-history counts
        names = {f.name for f in fields(Plausibility)}
        counts: dict[str, Any] = {k: v if k != "warnings" else tuple(v) for k, v in block.items() if k in names}
        report = Plausibility(**counts)
        lines.append(report.summary_line())
    if block.get("checks"):
        lines.append(summary_line(block["checks"], "after"))
    return lines + [f"warning: {text}" for text in block.get("warnings", [])]


def report_lines(result: RunResult, label: str) -> None:
    """The plausibility counts (:mod:`weftsim.checks.plausibility`), the after-run design checks' numbers and each
    warning of a finished run, one line each on stderr (``weftsim <label>: ...``; once per run, where its
    results are written).  A failed run says
    only why it failed (its summary.json still holds the block)."""
    if not result.ok:
        return
    for line in format_lines(result):
        print(f"weftsim {label}: {line}", file=sys.stderr)
