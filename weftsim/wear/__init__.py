"""Wear prediction at the clearance joints E and F: how the clearances grow over operating hours (docs/wear.md).

Public entry::

    predict_to_directory(scene, hours, outdir, ...) -> dict   (the summary written to wear.json)

- :mod:`weftsim.physics.wear`: the worn clearance c(psi) the contact sees, Archard's deposit on the
  contact arc (compiled; the reference engine's right-hand side reads the worn geometry);
- :mod:`.archard`: the wear of one run from its step rows;
- :mod:`.extrapolate`: the cycle extrapolation with the adaptive update interval;
- :mod:`.updates`: the updates (each joint's profiles and rates) and their advance;
- :mod:`.store`: the resumable state and the tables; :mod:`.figures`: the figures.

Every loose joint wears, each with its own ``[joint_e.wear]`` / ``[joint_f.wear]`` numbers: E, F, or E
and F together (one run simulates both; :func:`~.updates.wearing_joints`).  A worn F's tables
follow E's in the kernel parameter array (:mod:`weftsim.physics.chain_f`), its profiles are
:attr:`~.updates.Update.second` (or the first when E is ideal), and every output names the joint
(``effective_clearance_f_mm``, ``wear_profile_f.png``).  A ``--limit-clearance-mm`` applies to every
wearing joint: ``hours_to_limit`` is the first joint's to reach it (``limit_joint``), each joint's is
``hours_to_limit_<j>``.
"""

from __future__ import annotations

import math
import sys
import time
import types
from pathlib import Path
from typing import TYPE_CHECKING

from weftsim.errors import WearError

if TYPE_CHECKING:
    from collections.abc import Callable

    from weftsim.input.params import Scene

__all__ = ["ENGINES", "WearError", "check_engine", "predict", "predict_to_directory", "wear"]


def __getattr__(name: str):
    # ``predict`` loads the numba kernels: imported when asked for, so that building the command line
    # (which imports this package for the ``wear`` flags) does not pay for them.
    if name == "predict":
        from weftsim.wear.extrapolate import predict

        return predict
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


ENGINES = ("reference", "exudyn")  # weftsim.wear.engines.ENGINES: the same names (not imported: no numba here)


def check_request(scene: Scene, hours: float, engine: str, limit: float | None) -> None:
    """Refuse what cannot be predicted, with one line naming what is wrong and what is allowed."""
    import math

    if engine not in ENGINES:
        raise WearError(f"--engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    if engine == "exudyn" and not scene.joint_f.is_ideal:
        raise WearError("--engine exudyn: the Exudyn wear prediction covers joint E alone (the kinematic tree carries "
                        "the clearance at E only), and the scene gives a clearance at F; use --engine reference")
    if engine == "exudyn" and not scene.joint.is_ideal:
        from weftsim.exudyn_engine.selection import select_model

        if select_model(scene)[0] != "kinematic_tree":
            raise WearError("--engine exudyn: the wear prediction runs on the Exudyn engine's kinematic tree, and "
                            f"solver.exudyn.model = {scene.exudyn_solver.model!r} asks for another model; use "
                            "'auto' or 'kinematic_tree'")
    from weftsim.wear.extrapolate import MAX_HOURS

    if not (0.0 < hours <= MAX_HOURS):
        raise WearError(f"--hours must be > 0 and at most {MAX_HOURS:g} h (114 years of continuous running), "
                        f"got {hours:g}")
    joints = [(name, scene.joint if name == "e" else scene.joint_f) for name in scene.loose_joints]
    if not joints:
        raise WearError("joint_e.clearance_mm is 0 (ideal joint) and F has no clearance: there is no contact to "
                        "wear; give joint_e.clearance_mm (or joint_f.clearance_mm) > 0")
    widest = max(joints, key=lambda nj: nj[1].clearance)
    if limit is not None and not (limit > widest[1].clearance and math.isfinite(limit)):
        raise WearError(f"--limit-clearance-mm must be larger than the clearance of every wearing joint (the "
                        f"limit applies to each; joint_{widest[0]}.clearance_mm = {widest[1].clearance * 1e3:g} mm), "
                        f"got {limit * 1e3:g}")
    smallest = min(joints, key=lambda nj: nj[1].journal_radius)
    if limit is not None and limit >= smallest[1].journal_radius:
        raise WearError(f"--limit-clearance-mm must be smaller than the journal radius "
                        f"{smallest[1].journal_radius * 1e3:g} mm at {smallest[0].upper()} (the prediction ends before "
                        f"the clearance reaches it, docs/wear.md), got {limit * 1e3:g}")


def check_engine(outdir: str | Path, engine: str, force: bool = False) -> None:
    """Refuse to resume a wear state that ``outdir`` holds from another engine (its record names the engine;
    a record without one is the reference engine's); with ``force`` that state is deleted (starting over)."""
    import json

    from weftsim.post.record import MANIFEST
    from weftsim.wear.store import STATE, StateMismatch

    outdir = Path(outdir)
    if not ((outdir / MANIFEST).is_file() and (outdir / STATE).is_file()):
        return
    try:
        record = json.loads((outdir / MANIFEST).read_text())
    except (OSError, ValueError):
        return  # a damaged record is refused where it is read (weftsim.post.output, weftsim.post.record)
    stored = record.get("engine", "reference") if isinstance(record, dict) and record.get("kind") == "wear" else engine
    if stored == engine:
        return
    if force:
        (outdir / STATE).unlink(missing_ok=True)
        return
    raise StateMismatch(f"{outdir / STATE} holds a wear prediction on the {stored} engine, not the {engine} engine "
                        f"asked for: use --engine {stored} to resume it, another output directory with -o, or "
                        "--force to start over")


def predict_to_directory(scene: Scene, hours: float, outdir: str | Path, engine: str = "reference",
                         limit: float | None = None, progress: Callable[[float], None] | None = None,
                         stop: Callable[[], bool] | None = None, figures: bool = True, force: bool = False,
                         until_limit: bool = False, past_limit: bool = False) -> dict:
    """Predict the wear over ``hours`` of operation into ``outdir``, resuming a stored state.

    Parameters
    ----------
    scene : Scene
        With ``scene.joint.wear`` (the ``[joint_e.wear]`` keys).
    hours : float
        Operating hours to predict.
    outdir : str or path-like
        Created if needed and checked by :func:`weftsim.post.output.prepare_directory` (``force``: also a
        directory weftsim did not write); ``wear_state.npz`` in it is resumed when it belongs to the
        same scene and passes :func:`weftsim.wear.resume.read_state` (:class:`~.store.StateMismatch`
        otherwise, as for a request of fewer hours than it holds).
    limit : float, optional
        Clearance limit, m, for every wearing joint: ``wear.json`` gives the hours at which each joint's
        effective clearance reaches it (``hours_to_limit_e``, ``hours_to_limit_f``) and the first of them
        (``hours_to_limit``, ``limit_joint``).
    progress : callable, optional
        Called with the fraction of the hours done.
    stop : callable, optional
        Returns True to end after the current update (Ctrl-C): the state is kept for a resume.
    until_limit : bool
        ``hours`` is only a bound: the prediction is asked to run until the clearance limit (``limit`` is then
        required, and the progress is the share of the clearance's way to it).
    past_limit : bool
        Go on wearing past ``limit`` up to ``hours``.  By default a prediction with a ``limit`` ends where the
        first wearing joint's effective clearance reaches it (the update that crosses it extrapolates only up
        to it, as at a geometric limit; ``"ended"`` says so), even before ``hours``.

    Returns
    -------
    dict
        The summary (``wear.json``) with ``"files"``: kind -> path written.  ``"ended"`` says why a
        prediction stopped short of ``hours`` at a geometric limit (None otherwise); the hours and
        final wear are then those at the limit.

    Raises
    ------
    WearError
        The request is refused, or an update failed (its simulation, or wear too fast to
        extrapolate): every update before it is written first (``wear.csv``, ``wear.json``, the
        profiles) and the message says so.
    """
    from weftsim.post.output import begin_directory, prepare_directory
    from weftsim.post.record import provenance
    from weftsim.wear import store
    from weftsim.wear.engines import simulator
    from weftsim.wear.extrapolate import predict

    check_request(scene, hours, engine, limit)
    if until_limit and limit is None:
        raise WearError("until_limit needs a clearance limit (--limit-clearance-mm)")
    if until_limit and past_limit:
        raise WearError("--past-limit needs --hours: without them the prediction runs until the clearance limit")
    at_limit = limit is not None and not past_limit  # end where the first joint reaches the limit
    cap = limit if limit is not None else math.inf  # the limit, m, where at_limit uses it
    outdir = prepare_directory(outdir, force, scene, kind="wear")
    check_engine(outdir, engine, force)
    what = {"kind": "wear", "scene": scene.name, "engine": engine, **provenance(scene)}  # from the first update on
    begin_directory(outdir, what)  # ours from the first update on: an interrupted prediction resumes here
    wall0 = time.perf_counter()
    done = store.load_state(outdir, scene)
    from weftsim.wear.resume import check_resume

    check_resume(done, scene, hours, outdir)
    # The last stored update's rates are the one part of the state its history does not pin down (the
    # next update's profiles would): resume from where that update started, simulating it again.
    done = done[:-1]

    latest = list(done)
    kept = [len(done)]  # updates the state file on disk holds

    def save(updates):
        try:
            store.save_state(outdir, scene, updates)
        except OSError as exc:  # a full disk, a quota: the state written before is whole (atomic writes)
            from weftsim.errors import WriteFailed

            held = f"the {kept[0]} updates before it are kept there" if kept[0] else "no update was stored yet"
            raise WriteFailed(f"cannot write {outdir / store.STATE}: {exc.strerror or exc}; {held}: free space "
                              "and run the same command again to resume") from None
        kept[0] = len(updates)

    def on_update(updates):
        latest[:] = updates
        save(updates)
        if progress is not None and updates[-1].hours > 0.0:  # no time-left estimate from a zero fraction
            # the share of the hours, or of the clearance's way to the limit where the prediction ends there:
            # whichever is nearer its end (the estimate of the time left then follows what ends the run)
            done_share = 0.0 if until_limit else updates[-1].hours / hours
            if at_limit:
                done_share = max(done_share, _grown(scene, updates[-1], share=cap))
            progress(min(done_share, 1.0))

    asked_stop = stop
    if at_limit:

        def stop() -> bool:
            return (asked_stop is not None and asked_stop()) or (bool(latest) and _beyond(scene, latest[-1], cap))

    try:
        updates = predict(scene, hours, done, on_update=on_update, stop=stop, simulate=simulator(engine))
        if at_limit and updates and _beyond(scene, updates[-1], cap):
            updates[-1] = _cut_at(scene, updates[-1], cap)
            save(updates)
        if not updates:  # stopped (Ctrl-C) before the first update was done: nothing to write
            raise KeyboardInterrupt
    except WearError as exc:
        if not latest:
            raise
        data = _write_results(scene, latest, hours, limit, time.perf_counter() - wall0, outdir, what, figures,
                              str(exc), engine)
        raise WearError(f"{exc}; the prediction stopped there, {reached_text(scene, data)}: the {len(latest)} "
                        f"updates before it are in {outdir}/wear.csv and wear.json") from None
    reached = at_limit and _beyond(scene, updates[-1], cap * (1.0 - 1e-12))
    return _write_results(scene, updates, hours, limit, time.perf_counter() - wall0, outdir, what, figures,
                          engine=engine, reached_limit=reached)


def duty_summary(scene: Scene, updates: list, data: dict) -> dict:
    """``wear.json``'s duty-cycle fields: the duty (``duty_text``), the calendar days to the limit of each joint
    (``calendar_days_to_limit_<j>``, :meth:`~weftsim.input.params.Duty.calendar_days`) and the stop-starts' share
    of the worn volume over the prediction (``stop_start_share_<j>``, N-weighted over the updates)."""
    import numpy as np

    from weftsim.wear.extrapolate import wearing_joints

    duty = scene.duty
    out = {"duty_text": f"{duty.hours_per_day:g} h a day, {duty.days_per_week:g} days a week, {duty.stops_per_hour:g} "
                        f"stops an hour of {duty.stop_minutes:g} min",
           "stops_per_hour": duty.stops_per_hour}
    for j in wearing_joints(scene):
        hours = data.get(f"hours_to_limit_{j}")
        out[f"calendar_days_to_limit_{j}"] = None if hours is None else duty.calendar_days(hours)
        rows = [(u.step_revolutions * u.part(j).volume_rate, u.response.get(f"stop_start_share_{j}", 0.0))
                for u in updates if u.step_revolutions > 0.0]
        volume = np.array([r[0] for r in rows]) if rows else np.zeros(0)
        share = np.nan_to_num(np.array([r[1] for r in rows], dtype=float)) if rows else np.zeros(0)
        out[f"stop_start_share_{j}"] = float(np.dot(volume, share) / volume.sum()) if volume.sum() > 0.0 else 0.0
    if data.get("hours_to_limit") is not None:
        out["calendar_days_to_limit"] = duty.calendar_days(data["hours_to_limit"])
    return out


def reached_text(scene: Scene, data: dict) -> str:
    """How far a prediction got: "after 460.2 h at an effective clearance of 1.04 mm at E" (``data``: the
    summary of :func:`_write_results`), with the hours to the limit where it was reached before."""
    from weftsim.wear.extrapolate import wearing_joints

    joints = wearing_joints(scene)
    text = f"after {data['hours_reached']:.6g} h at an effective clearance of " + ", ".join(
        f"{data[f'final_effective_clearance_{j}_mm']:.4g} mm at {j.upper()}" for j in joints)
    if data.get("hours_to_limit") is not None:
        text += (f" (the limit {data['limit_clearance_mm']:g} mm was reached at {data['limit_joint'].upper()} after "
                 f"{data['hours_to_limit']:.6g} h)")
    return text


def _beyond(scene: Scene, update, limit: float) -> bool:
    """True when ``update`` extrapolated over its N revolutions brings a wearing joint's effective clearance to
    ``limit`` (m)."""
    return update.step_revolutions > 0.0 and _grown(scene, update, advance=True) >= limit


def _grown(scene: Scene, update, advance: bool = False, share: float | None = None) -> float:
    """The largest effective clearance of the wearing joints (m) at the start of ``update`` (or after its N
    revolutions with ``advance``); with ``share`` = limit, the largest share of the way from c0 to it."""
    from weftsim.wear.extrapolate import advance_update, effective_clearance, joint_of, wearing_joints

    state = advance_update(update, scene) if advance else update
    values = []
    for joint in wearing_joints(scene):
        c0, part = joint_of(scene, joint).clearance, state.part(joint)
        c = effective_clearance(c0, part.bearing, part.journal)
        values.append(c if share is None else (c - c0) / (share - c0))
    return max(values)


def _cut_at(scene: Scene, update, limit: float):
    """``update`` with its N cut so that the effective clearance just reaches ``limit`` (bisection to 1e-18 of N)."""
    from dataclasses import replace

    inside, outside = 0.0, update.step_revolutions
    for _ in range(60):
        middle = 0.5 * (inside + outside)
        if _beyond(scene, replace(update, step_revolutions=middle), limit):
            outside = middle
        else:
            inside = middle
    return replace(update, step_revolutions=outside)


def _write_results(scene: Scene, updates: list, hours: float, limit: float | None, wall: float, outdir: Path,
                   what: dict, figures: bool, failure: str | None = None, engine: str = "reference",
                   reached_limit: bool = False) -> dict:
    """Write the tables, the summary and the figures of ``updates``; returns the summary with ``"files"``.

    ``failure``: why the prediction stopped at an update that failed (``wear.json`` keeps it); ``engine``:
    the engine the updates were simulated on (``wear.json``'s ``"engine"``).
    """
    from dataclasses import replace

    from weftsim.post.output import write_figure, write_files, write_json
    from weftsim.wear import store
    from weftsim.wear.extrapolate import advance_update, effective_clearance, ended_by_limit, joint_of, wearing_joints

    data = store.summary(scene, updates, hours, limit, wall)
    data["engine"] = engine
    ended = ended_by_limit(scene, updates)
    if ended is None and reached_limit and limit is not None:  # run until the limit: the last update reaches it
        ended = f"the effective clearance reaches the limit {limit * 1e3:g} mm (--limit-clearance-mm)"
    data["ended"] = ended
    data["failure"] = failure
    joints = wearing_joints(scene)
    if ended is not None:  # the last update extrapolates up to the limit: report the state there
        end = replace(advance_update(updates[-1], scene), step_revolutions=0.0)
        data.update(store.archard_check(scene, [*updates, end]))  # the volumes at the limit
        if limit is not None:
            data.pop("note", None)
            data.update(store.limit_summary(scene, [*updates, end], limit))
        data.update(hours_reached=end.hours,
                    wear_volume_mm3=data["wear_volume_mm3"] + 1e9 * updates[-1].total_volume_rate
                    * updates[-1].step_revolutions)
        for joint in joints:
            part, grown = end.part(joint), updates[-1].part(joint).volume_rate * updates[-1].step_revolutions
            data.update({
                f"final_effective_clearance_{joint}_mm": 1e3 * effective_clearance(joint_of(scene, joint).clearance,
                                                                                   part.bearing, part.journal),
                f"final_bearing_wear_max_{joint}_mm": 1e3 * float(part.bearing.max()),
                f"final_journal_wear_max_{joint}_mm": 1e3 * float(part.journal.max()),
                f"wear_volume_{joint}_mm3": data[f"wear_volume_{joint}_mm3"] + 1e9 * grown})
    if limit is not None:  # censored: not reaching the limit within the hours, or never (wears nothing)
        from weftsim.wear.censored import limit_note

        data.update(limit_note(scene, updates, limit, data.get("hours_to_limit")))
    data.update(duty_summary(scene, updates, data))
    columns = store.table(scene, updates)
    files: dict[str, tuple[str, Callable[[Path], Path]]] = {
        "state": (store.STATE, lambda p: p),
        "table": ("wear.csv", lambda p: store.write_table(p, scene, updates)),
        "summary": ("wear.json", lambda p: write_json(p, data)),
    }

    def profile(which: str, j: str) -> Callable[[Path], Path]:
        return lambda p: store.write_profiles(p, updates, which, j)

    for joint in joints:
        files[f"profile_{joint}"] = (f"wear_profile_{joint}.csv", profile("bearing", joint))
        files[f"journal_profile_{joint}"] = (f"wear_profile_journal_{joint}.csv", profile("journal", joint))
    if figures:
        from weftsim.wear.figures import conditions, growth_figure, profile_figure

        engine_tag = "" if engine == "reference" else f" ({engine} engine)"

        def profile_png(j: str, t: str) -> Callable[[Path], Path]:
            return lambda p: write_figure(p, profile_figure(scene, updates, t, j))

        for joint in joints:
            title = f"{scene.name}: wear at {joint.upper()}{engine_tag}\n{conditions(scene, (joint,))}"
            files[f"profile_figure_{joint}"] = (f"wear_profile_{joint}.png", profile_png(joint, title))
        name = "".join(joints)
        title = f"{scene.name}: wear at {' and '.join(j.upper() for j in joints)}{engine_tag}\n{conditions(scene, joints)}"
        limit_mm = None if limit is None else 1e3 * limit
        files["growth_figure"] = (f"wear_growth_{name}.png",
                                  lambda p: write_figure(p, growth_figure(columns, title, joints, limit_mm)))
    written = write_files(outdir, what, files, scene=scene)
    data["files"] = {k: str(v) for k, v in written.items()}
    return data


def wear(scene: Scene, hours: float, outdir: str | Path, *, engine: str = "reference", limit_mm: float | None = None,
         progress: Callable[[float], None] | None = None, force: bool = False, until_limit: bool = False) -> dict:
    """The wear of the scene's worn joint(s) over ``hours`` of operation (``weftsim wear``; ``weftsim.wear(...)``)
    into ``outdir``: Archard's law on the engine's contact, extrapolated over cycles, resumable from
    ``wear_state.npz``.

    Returns ``wear.json``'s content (:func:`predict_to_directory`); ``limit_mm`` is a clearance limit, mm,
    whose hours to reach are reported (and where the prediction ends with ``until_limit``).
    """
    limit = None if limit_mm is None else limit_mm * 1e-3
    return predict_to_directory(scene, hours, outdir, engine=engine, limit=limit, progress=progress, force=force,
                                until_limit=until_limit)


class _CallableModule(types.ModuleType):
    """``weftsim.wear(...)`` is :func:`wear`, whether ``weftsim.wear`` names the function (``import weftsim``)
    or this subpackage (once ``import weftsim.wear`` has run)."""

    def __call__(self, *args, **kwargs):
        return wear(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
