"""The weft exchange at mid-shed: the giver head, the taker head, their overlap and relative speed, and each
head's position error against the ideal rigid mechanism (the one definition; docs/rapier-tape.md section 7).

The giver is the scene's mechanism; the taker is the same mechanism mirrored on the other side of the shed,
on the same crank, with its own clearance at E (``exchange.taker_clearance_mm``).  A mirror image of a
mechanism moves as the mirror image of its motion (Newton's laws, the contact and friction laws are
isotropic, gravity lies in the mirror plane), so the taker's head travels s_t(t) into the shed from its side
exactly as a run of the giver's scene with the taker's clearance does: no mirrored geometry is built.  Each
head's s is measured from its own outermost position; the heads' outermost positions are the gap
G = 2 s_i(pi) - overlap apart, s_i the ideal mechanism's rapier displacement and pi the dead centre (the
rocker's angle phi(theta) = -atan(tan beta cos theta) is even about theta = pi, so the ideal motion is
symmetric about it and deepest there).  Then

    overlap          o = s_g + s_t - G                 (how far the heads have passed each other; > 0 overlapped)
    relative speed   w = v_g + v_t                     (the rate of o: the heads' closing speed)
    position errors  e_g = s_g - s_i(theta),  e_t = s_t - s_i(theta)

and with ideal joints on both sides o = 2 s_i(theta) - G (the closed value), w = 2 v_i, e_g = e_t = 0.  The head
is the tape's head (``head_displacement_m``) with a flexible tape, the rapier's tip (``rapier_displacement_m``)
with the rigid rapier.

The cheapest correct taker (:func:`taker_source`): ``"giver"`` when its joint at E is the giver's (its run would
repeat the giver's, bit for bit), ``"ideal"`` when it has ideal joints and a rigid rapier (its motion is the
closed form, which every engine's ideal run reproduces to its tolerance), otherwise ``"run"``: one more run of
:func:`taker_scene` on the same engine, its head interpolated onto the giver's times by cubic Hermite from its
own positions and velocities (exact at its own steps).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from weftsim.input.params import Exchange, Scene
from weftsim.model.channels import EXCHANGE_CHANNELS

DEAD_CENTRE = math.pi  # crank angle of the deepest head position (theta = pi + 2 pi k)
TAKER_SOURCES = ("giver", "ideal", "run")


def exchange_of(scene: Scene) -> Exchange | None:
    """The scene's exchange when it is on, else None."""
    exchange = scene.exchange
    return exchange if exchange is not None and exchange.enabled else None


def _exchange(scene: Scene) -> Exchange:
    exchange = exchange_of(scene)
    if exchange is None:
        raise ValueError(f"scene {scene.name!r} has no [exchange] that is on")
    return exchange


def taker_clearance(scene: Scene) -> float:
    """The taker's radial clearance at E, m (the giver's when the scene does not give it)."""
    given = _exchange(scene).taker_clearance
    return scene.joint.clearance if given is None else given


def taker_scene(scene: Scene) -> Scene:
    """The scene of the taker's mechanism: the giver's with the taker's clearance at E (a round joint; the
    giver's joint itself when the taker's clearance is not given), without the exchange."""
    given = _exchange(scene).taker_clearance
    joint = scene.joint if given is None else replace(scene.joint, clearance=given, bearing_wear=(), journal_wear=())
    return replace(scene, name=f"{scene.name}_taker", joint=joint, exchange=None)


def _flexible(scene: Scene) -> bool:
    if scene.rapier_tape is None:
        return False
    from weftsim.model.tape_selection import tape_model

    return tape_model(scene) == "flexible"


def taker_source(scene: Scene) -> str:
    """How the taker's head is had: ``"giver"``, ``"ideal"`` or ``"run"`` (module docstring)."""
    taker = taker_scene(scene)
    if taker.joint == scene.joint:
        return "giver"
    if taker.is_ideal and not _flexible(taker):
        return "ideal"
    return "run"


def exchange_problem(scene: Scene) -> str:
    """Why the scene's exchange cannot be computed ('' when it can): one line naming the key
    (:func:`weftsim.input.params.exchange_problem`, with the tape's automatic choice of model)."""
    from weftsim.input.params import exchange_problem as problem

    if exchange_of(scene) is None:
        return ""
    stroke = float(ideal_displacement(scene, DEAD_CENTRE))
    return problem(scene, stroke, _flexible(scene))


def ideal_displacement(scene: Scene, theta) -> np.ndarray:
    """s_i(theta): the ideal rigid mechanism's head position (rapier displacement), m."""
    from weftsim.mechanism.kinematics import linkage_state

    return linkage_state(theta, scene.geometry).rapier_displacement


def gap(scene: Scene) -> float:
    """G = 2 s_i(pi) - overlap: the distance between the heads' outermost positions, m."""
    return float(2.0 * ideal_displacement(scene, DEAD_CENTRE) - _exchange(scene).overlap)


def half_window(scene: Scene) -> float:
    """Half the transfer window's crank angle, rad: ``exchange.window_deg`` / 2, or where the ideal heads
    start to overlap, 2 s_i(pi - x) = G (s_i rises monotonically to the dead centre)."""
    exchange = _exchange(scene)
    if exchange.window is not None:
        return 0.5 * exchange.window
    from scipy.optimize import brentq

    target = 0.5 * gap(scene)
    return float(brentq(lambda x: float(ideal_displacement(scene, DEAD_CENTRE - x)) - target, 0.0, math.pi,
                        xtol=1e-14))


def head(table: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(s, v) of the head in a run's channel table: the tape's head, or the rigid rapier's tip."""
    if "head_displacement_m" in table:
        return table["head_displacement_m"], table["head_velocity_m_s"]
    return table["rapier_displacement_m"], table["rapier_velocity_m_s"]


def hermite(t: np.ndarray, nodes: np.ndarray, s: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cubic Hermite interpolant of (s, s' = v) given at increasing ``nodes``, and its rate, at ``t``;
    NaN outside the nodes (a run that stopped early has no head there).  Exact at the nodes."""
    t = np.asarray(t, dtype=float)
    out_s, out_v = np.full(t.shape, np.nan), np.full(t.shape, np.nan)
    if nodes.size == 0:
        return out_s, out_v
    inside = (t >= nodes[0]) & (t <= nodes[-1])
    tt = t[inside]
    k = np.clip(np.searchsorted(nodes, tt, side="right") - 1, 0, max(nodes.size - 2, 0))
    if nodes.size == 1:
        out_s[inside], out_v[inside] = s[0], v[0]
        return out_s, out_v
    h = nodes[k + 1] - nodes[k]
    safe = np.where(h > 0.0, h, 1.0)
    u = np.where(h > 0.0, (tt - nodes[k]) / safe, 0.0)
    s0, s1, v0, v1 = s[k], s[k + 1], v[k] * h, v[k + 1] * h
    u2, u3 = u * u, u * u * u
    out_s[inside] = (2 * u3 - 3 * u2 + 1) * s0 + (u3 - 2 * u2 + u) * v0 + (-2 * u3 + 3 * u2) * s1 + (u3 - u2) * v1
    rate = (6 * u2 - 6 * u) * (s0 - s1) + (3 * u2 - 4 * u + 1) * v0 + (3 * u2 - 2 * u) * v1
    out_v[inside] = np.where(h > 0.0, rate / safe, v[k])
    return out_s, out_v


def exchange_channels(scene: Scene, giver: dict[str, np.ndarray],
                      taker: dict[str, np.ndarray] | None) -> dict[str, np.ndarray]:
    """:data:`EXCHANGE_CHANNELS` on the rows of the giver's table ``giver`` (samples or steps of its run).

    ``taker``: the taker's table of the same kind (its head interpolated onto the giver's times), the giver's
    own table when :func:`taker_source` is ``"giver"``, None for the ideal taker (the closed form).
    """
    from weftsim.mechanism.kinematics import linkage_state

    theta = np.radians(giver["crank_angle_deg"])
    ideal = linkage_state(theta, scene.geometry)
    s_i, v_i = ideal.rapier_displacement, scene.drive.speed * ideal.d_rapier_displacement
    s_g, v_g = head(giver)
    if taker is None:
        s_t, v_t = s_i, v_i
    elif taker is giver:
        s_t, v_t = s_g, v_g
    else:
        s_t, v_t = hermite(giver["time_s"], taker["time_s"], *head(taker))
    values = (s_t, v_t, s_g + s_t - gap(scene), v_g + v_t, s_g - s_i, s_t - s_i)
    return {name: np.array(value, dtype=float) for name, value in zip(EXCHANGE_CHANNELS, values)}


def _at(x: float, xp: np.ndarray, fp: np.ndarray) -> float:
    return float(np.interp(x, xp, fp))


def transfers(scene: Scene, steps: dict[str, np.ndarray]) -> list[dict]:
    """One record per transfer window the run covers whole (the heads' meeting at theta = pi + 2 pi k):

    the window, the ideal overlap and the overlap at the dead centre and its largest value, the relative speed
    at the dead centre, each head's position error there and its extremes over the window, and the largest
    departures of the overlap and of the relative speed from the ideal mechanism's over the window.  At the dead
    centre, the departures from the ideal mechanism are interpolated linearly between the steps around it and
    added to the ideal's exact values there (the overlap's own curvature would cost 5e-7 m over a 0.5 deg step);
    extremes are over the steps.
    """
    from weftsim.mechanism.kinematics import linkage_state

    if not steps["time_s"].size or "exchange_overlap_m" not in steps:
        return []
    theta = np.radians(steps["crank_angle_deg"])
    half = half_window(scene)
    exchange = _exchange(scene)
    out = []
    k = 0
    while DEAD_CENTRE + 2.0 * math.pi * k + half <= theta[-1] * (1.0 + 1e-12):
        centre = DEAD_CENTRE + 2.0 * math.pi * k
        k += 1
        if centre - half < theta[0]:
            continue
        keep = (theta >= centre - half) & (theta <= centre + half)
        if not np.any(keep):
            continue
        th = theta[keep]
        ideal = linkage_state(th, scene.geometry)
        overlap_ideal = 2.0 * ideal.rapier_displacement - gap(scene)
        speed_ideal = 2.0 * scene.drive.speed * ideal.d_rapier_displacement
        o, w = steps["exchange_overlap_m"][keep], steps["exchange_relative_speed_m_s"][keep]
        e_g, e_t = steps["giver_head_error_m"][keep], steps["taker_head_error_m"][keep]
        top = int(np.nanargmax(o)) if np.any(np.isfinite(o)) else 0
        out.append({
            "revolution": k, "dead_centre_crank_deg": math.degrees(centre),
            "window_crank_deg": [math.degrees(centre - half), math.degrees(centre + half)],
            "overlap_ideal_m": float(exchange.overlap),
            "overlap_at_dead_centre_m": exchange.overlap + _at(centre, th, o - overlap_ideal),
            "overlap_max_m": float(o[top]), "overlap_max_crank_deg": float(math.degrees(th[top])),
            "overlap_error_max_abs_m": float(np.max(np.abs(o - overlap_ideal))),
            "relative_speed_at_dead_centre_m_s": _at(centre, th, w - speed_ideal),
            "relative_speed_error_max_abs_m_s": float(np.max(np.abs(w - speed_ideal))),
            "giver_error_at_dead_centre_m": _at(centre, th, e_g),
            "giver_error_min_m": float(np.min(e_g)), "giver_error_max_m": float(np.max(e_g)),
            "taker_error_at_dead_centre_m": _at(centre, th, e_t),
            "taker_error_min_m": float(np.min(e_t)), "taker_error_max_m": float(np.max(e_t)),
        })
    return out


def exchange_summary(scene: Scene, steps: dict[str, np.ndarray], source: str | None = None) -> dict | None:
    """The ``exchange`` block of ``summary.json`` (None without an exchange that is on)."""
    exchange = exchange_of(scene)
    if exchange is None:
        return None
    return {
        "taker_clearance_mm": taker_clearance(scene) * 1e3,
        "taker": source or taker_source(scene),
        "overlap_mm": exchange.overlap * 1e3,
        "gap_m": gap(scene),
        "window_deg": math.degrees(2.0 * half_window(scene)),
        "head": "tape head" if "head_displacement_m" in steps else "rapier tip",
        "transfers": transfers(scene, steps),
    }
