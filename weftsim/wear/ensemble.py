"""Wear ensembles: the hours to a clearance limit as a distribution over uncertain inputs (docs/wear.md section 9).

Public entry::

    wear_ensemble(scene, {"joint_e.wear.wear_coefficient": "lognormal(1e-7,0.7)", ...}, samples=1000,
                  limit=0.1e-3, outdir="out/ens") -> dict   (the summary written to ensemble.json)

What the physics allows instead of one simulation per sample:

- **Rescaled keys** (``RESCALED``): Archard's k and the hardnesses never enter the dynamics, so the
  hours to any clearance scale exactly as H / k (docs/wear.md section 5).  k is rescaled exactly; a
  hardness is rescaled by the bearing's and the journal's shares of the worn clearance in the
  centre run (exact when both hardnesses change by the same factor, first order otherwise).
- **Chaotic scatter**: ``chaos_runs`` predictions of the centre geometry whose k differs in the
  last bits give the scatter of the chaotic impact sequence; each sample draws one of them and
  takes its hours relative to their mean, at every clearance level.
- **Dynamic keys** (all others: clearance, speed, viscosity, ...): simulated on a tensor design of
  three points per key, at the 5, 50 and 95 % quantiles of its distribution; each sample's log-hours
  are interpolated quadratically between them (values beyond the outer points are clamped there).

The simulations run as jobs (:func:`weftsim.wear.jobs.run_job`) on the sweep machinery's pool: local
processes or a Dask cluster, each job resumable.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import WearError
from weftsim.wear.censored import censored_quantile, fraction_interval, interval_bounds, json_hours
from weftsim.wear.ensemble_design import (DESIGN_QUANTILES, RESCALED, k_scale, _lagrange, centre_name,  # noqa: F401
                                          interpolate, plan)
from weftsim.wear.jobs import hours_at, run_job
from weftsim.wear.life import duty_text, horizon_days, life_figure, sample_days, shift_days, stop_share_summary
from weftsim.wear.uncertain import Uncertain, latin_hypercube, parse_uncertain, rank_shares

if TYPE_CHECKING:
    from collections.abc import Callable

    from weftsim.input.params import Scene

CHAOS_RUNS = 6  # the centre run and five whose k differs in the last bits (docs/wear.md section 6 used six)
LEVELS = 40  # clearance levels of the band between the largest starting clearance and the limit
QUANTILES = (0.1, 0.5, 0.9)
CONFIDENCE = 0.9
# Horizon of an ensemble (--hours with --uncertain): a sample that does not reach the limit within it is
# censored ("> H h").  1e5 h is the life of a loom (11 years of continuous running); the design's jobs run
# to MAX_HOURS = 10 H, so a sample rescaled by k0 / k >= 0.1 is still resolved (others are counted).
HORIZON_HOURS = 1e5


def _run_jobs(jobs: list[tuple[str, Scene]], limit: float, outdir: Path, jobs_n: int | None, scheduler: str | None,
              announce: Callable[[str], None] | None, horizon: float | None = None) -> dict[str, dict]:
    import concurrent.futures as cf

    from weftsim.sweep.pool import executor

    pool, workers, stop = executor(jobs_n, scheduler, len(jobs), "reference")
    results: dict[str, dict] = {}
    start = time.perf_counter()
    if announce:
        announce(f"ensemble: {len(jobs)} jobs on {workers} worker(s); a line as each ends")
    try:
        futures = {pool.submit(run_job, s, limit, str(outdir / "jobs" / name), horizon): name for name, s in jobs}
        for future in cf.as_completed(futures):
            name = futures[future]
            try:
                results[name] = future.result()
            except Exception as exc:  # noqa: BLE001 - a worker that died: recorded as that job's failure
                results[name] = {"error": f"{type(exc).__name__}: {exc}", "wall_s": math.nan}
            if announce:
                r = results[name]
                state = "failed: " + r["error"] if r["error"] else \
                    ("does not reach the limit" + (f": {r['never']}" if r.get("never") else
                                                   f" within {r['horizon_h']:g} h") if r.get("censored") else "done")
                announce(f"ensemble: job {name} {state} ({len(results)}/{len(jobs)}, {r.get('wall_s', math.nan):.1f} s)"
                         + _time_left(time.perf_counter() - start, len(results), len(jobs)))
    except KeyboardInterrupt:
        stop(True)
        raise
    stop(False)
    return results


def _time_left(elapsed: float, done: int, total: int) -> str:
    """``; ~3 min left`` at the pace of the jobs so far (jobs of one ensemble cost about the same), or ''."""
    from weftsim.checks.progress import format_duration

    if done >= total or done <= 0:
        return ""
    return f"; ~{format_duration(elapsed / done * (total - done))} left"


def combine(scene: Scene, uncertain: list[Uncertain], dynamic: list[Uncertain], nodes: np.ndarray,
            results: dict[str, dict], samples: int, limit: float, seed: int, levels_extra=(),
            horizon: float = HORIZON_HOURS) -> dict:
    """The ensemble from the jobs' curves: per-sample hours at every clearance level (module docstring).

    Hours are ``inf`` where a sample does not reach a level within ``horizon`` (censored).
    """
    from weftsim.input.scene import to_file_keys
    from weftsim.wear.extrapolate import MAX_HOURS

    node_names = [n for n in results if n.startswith("node_")] or ["centre"]
    node_names.sort()
    centre = centre_name(nodes, dynamic)
    failed = {n: r["error"] for n, r in results.items() if r.get("error")}
    bad_nodes = [n for n in node_names if n in failed]
    if bad_nodes:
        raise WearError(f"the ensemble's design run {bad_nodes[0]} failed: {failed[bad_nodes[0]]}")
    start = min(results[n]["clearance_m"][0] for n in node_names)
    levels = np.unique(np.concatenate([np.linspace(start, limit, LEVELS + 1)[1:],
                                       [v for v in levels_extra if start < v <= limit]]))
    node_hours = np.array([hours_at(results[n], levels) for n in node_names])  # (nodes, levels); inf: censored
    chaos_names = [centre] + sorted(n for n in results if n.startswith("chaos_") and n not in failed)
    chaos = np.array([hours_at(results[n], levels) for n in chaos_names])
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = chaos.mean(axis=0)
        # a level some chaos run does not reach carries no chaotic factor (nothing wears there to scatter)
        chaos_factor = np.where((mean > 0.0) & np.isfinite(mean), chaos / mean, 1.0)  # (runs, levels)
    # The design runs are one chaotic draw each; shift the design to pass through the chaos runs' mean at
    # the centre (the centre run is chaos run 0), so that the chaos factor is not counted twice there.
    node_hours = node_hours / chaos_factor[0]

    rng = np.random.default_rng(seed)
    u = latin_hypercube(samples, len(uncertain) + 1, rng)
    values = {v.key: v.ppf(u[:, i]) for i, v in enumerate(uncertain)}
    base = to_file_keys(scene)
    share_b = results[centre]["bearing_share"]
    scale = k_scale(scene, values, samples)
    hb = values.get("joint_e.wear.bearing_hardness_mpa", base["joint_e.wear.bearing_hardness_mpa"])
    hj = values.get("joint_e.wear.journal_hardness_mpa", base["joint_e.wear.journal_hardness_mpa"])
    scale /= share_b * base["joint_e.wear.bearing_hardness_mpa"] / hb \
        + (1.0 - share_b) * base["joint_e.wear.journal_hardness_mpa"] / hj
    draw = np.minimum((u[:, -1] * len(chaos_names)).astype(int), len(chaos_names) - 1)
    base_hours = interpolate(node_hours, nodes, dynamic, values, samples)
    if "joint_e.clearance_mm" in values:  # a sample that starts above a level is there at 0 h, whatever the rule
        base_hours[1e-3 * values["joint_e.clearance_mm"][:, None] >= levels[None, :]] = 0.0
    hours = base_hours * scale[:, None] * chaos_factor[draw]  # (samples, levels)
    never = ~np.isfinite(hours)
    hours = np.where(hours <= horizon, hours, math.inf)  # censored at the horizon
    # a sample whose design points stopped at the jobs' horizon but which k / H rescales below the ensemble's
    # horizon is not resolved: counted (the jobs' horizon is 10 H, so only k > 10 k0 can do it)
    job_horizon = min((results[n].get("horizon_h") or MAX_HOURS) for n in node_names)
    unresolved = int(np.sum(never[:, -1] & (job_horizon * scale < horizon)))
    at_limit = hours[:, -1]
    inputs = {**values, "chaotic scatter": chaos_factor[draw, -1]}
    with np.errstate(divide="ignore"):
        shares = rank_shares(inputs, np.log(at_limit)) if np.any(np.isfinite(at_limit)) else \
            {k: (0.0, 0.0) for k in inputs}
    never_nodes = {n: results[n].get("never") for n in node_names if results[n].get("never")}
    return {"levels": levels, "hours": hours, "values": values, "chaos_draw": draw, "inputs": inputs,
            "shares": shares, "chaos_hours_at_limit": chaos[:, -1], "failed": failed, "unresolved": unresolved,
            "never_nodes": never_nodes, "censored_nodes": [n for n in node_names if results[n].get("censored")]}


def quantile_table(hours: np.ndarray, horizon: float = HORIZON_HOURS) -> dict:
    """{"p10": {"hours", "low", "high", "censored", "beyond_hours"}, ...} with CONFIDENCE order-statistic
    intervals; a quantile among the censored samples (``inf``) has ``hours`` None and ``censored`` True
    (it lies beyond ``horizon``); an interval bound is None either among them (``low_beyond_hours`` /
    ``high_beyond_hours`` = ``horizon``) or where too few samples give none (``*_beyond_hours`` None:
    :func:`weftsim.wear.censored.interval_bounds`)."""
    out = {}
    for p in QUANTILES:
        est, low, high = censored_quantile(hours, p, CONFIDENCE)
        out[f"p{round(100 * p)}"] = {**json_hours(est, horizon), **interval_bounds(low, high, horizon)}
    return out


def reaching(hours: np.ndarray, horizon: float) -> dict:
    """The fraction of samples reaching a level within ``horizon`` h, with its CONFIDENCE interval."""
    n_reached = int(np.sum(np.isfinite(hours)))
    frac, low, high = fraction_interval(n_reached, hours.size, CONFIDENCE)
    return {"fraction": frac, "low": low, "high": high, "samples_reaching": n_reached, "within_hours": horizon}


def wear_ensemble(scene: Scene, uncertain: dict[str, str] | list[str], samples: int, limit: float,
                  outdir: str | Path, jobs: int | None = None, scheduler: str | None = None, seed: int = 0,
                  figures: bool = True, force: bool = False, levels: tuple[float, ...] = (),
                  chaos_runs: int = CHAOS_RUNS, announce: Callable[[str], None] | None = None,
                  horizon: float = HORIZON_HOURS, design_points: dict[str, int] | None = None) -> dict:
    """Run a wear ensemble into ``outdir``; returns the summary (``ensemble.json``) with ``"files"``.

    Parameters
    ----------
    scene : Scene
        The nominal scene (joint E with a clearance).
    uncertain : dict or list
        ``{key: "lognormal(1e-7,0.7)"}`` or ``["key=lognormal(1e-7,0.7)", ...]`` (file units).
    samples : int
        Monte Carlo samples (Latin hypercube), 10 to 10**6; samples cost no simulation.
    limit : float
        Clearance limit, m.
    outdir : str or path-like
        Output directory; ``jobs/`` in it holds the simulated predictions (resumed on a rerun).
    jobs, scheduler :
        Local worker processes, or the address of a Dask scheduler (as ``weftsim sweep``).
    levels : tuple of float
        Extra clearance levels (m) to report quantiles at (besides the limit).
    chaos_runs : int
        Predictions of the centre design point differing in the last bits of k (1 to 50; 1 = no scatter).
    horizon : float
        Hours: a sample that does not reach a level within them is censored (reported as "> horizon h", or
        "never" when its design points wear nothing); the design's predictions run to 10 x horizon (at
        most 1e6 h).
    design_points : dict, optional
        ``{key: n}``: n design points (2 to 9) for a simulated key instead of 3 (docs/wear.md section 9).
    """
    from weftsim.post.output import begin_directory, prepare_directory, write_csv, write_figure, write_files, write_json
    from weftsim.post.record import provenance
    from weftsim.wear import check_request

    texts = [f"{k}={v}" for k, v in uncertain.items()] if isinstance(uncertain, dict) else list(uncertain)
    parsed = [parse_uncertain(t) for t in texts]
    if not parsed:
        raise WearError("an ensemble needs at least one --uncertain KEY=DISTRIBUTION")
    if not (isinstance(samples, int) and 10 <= samples <= 10**6):
        raise WearError(f"--samples must be a whole number from 10 to 1000000, got {samples!r}")
    if isinstance(seed, bool) or not (isinstance(seed, int) and seed >= 0):  # before any simulation runs
        raise WearError(f"--seed must be a whole number >= 0, got {seed!r}")
    if not (isinstance(chaos_runs, int) and 1 <= chaos_runs <= 50):
        raise WearError(f"--chaos-runs must be a whole number from 1 to 50, got {chaos_runs!r}")
    from weftsim.wear.extrapolate import MAX_HOURS

    if not (isinstance(horizon, (int, float)) and 1.0 <= horizon <= MAX_HOURS):
        raise WearError(f"--hours (the ensemble's horizon) must be from 1 to {MAX_HOURS:g} h, got {horizon!r}")
    check_request(scene, 1.0, "reference", limit)
    if not scene.joint_f.is_ideal:  # its H/k rescaling and its clearance curve are joint E's
        raise WearError("an ensemble predicts the wear at E with F ideal so far; `weftsim wear SCENE --hours H` "
                        "predicts F and E with F (docs/wear.md); set joint_f.clearance_mm = 0 for the ensemble")
    from dataclasses import replace

    from weftsim.wear.uncertain_keys import check_uncertain_key

    names = tuple(u.key for u in parsed)
    parsed = [replace(u, key=check_uncertain_key(u.key, scene, names)) for u in parsed]  # dotted keys from here on
    job_list, dynamic, nodes = plan(scene, parsed, chaos_runs, design_points)
    job_horizon = min(10.0 * horizon, MAX_HOURS)
    for name, s in job_list:
        if not limit > s.joint.clearance:
            raise WearError(f"the design point {name} starts at a clearance of {1e3 * s.joint.clearance:g} mm, not "
                            f"below the limit {1e3 * limit:g} mm: narrow the clearance's distribution or raise "
                            "the limit")
    start = min(s.joint.clearance for _, s in job_list)  # the band's lowest clearance (combine's ``start``)
    for level in levels:
        if not (isinstance(level, (int, float)) and start < level < limit):
            raise WearError(f"--level-mm {1e3 * level:g}: a level must lie between the starting clearance "
                            f"{1e3 * start:g} mm and the limit {1e3 * limit:g} mm (the limit itself is always "
                            "reported)")
    if announce is not None:
        from weftsim.wear.extrapolate import update_time

        announce(f"ensemble: {len(job_list)} simulated predictions to {1e3 * limit:g} mm ("
                 f"{len(nodes)} design point(s) of {len(dynamic)} simulated key(s), "
                 f"{chaos_runs - 1} more chaos run(s)); one update of the nominal scene ~{update_time(scene):.2g} s, "
                 f"~{math.log(limit / scene.joint.clearance) / math.log1p(scene.joint.wear.max_clearance_change):.0f} "
                 "updates a prediction; the samples cost no simulation")
    outdir = prepare_directory(outdir, force, scene, kind="wear ensemble")
    what = {"kind": "wear ensemble", "scene": scene.name, **provenance(scene)}  # the command and resolved scene
    begin_directory(outdir, what)
    wall0 = time.perf_counter()
    results = _run_jobs(job_list, limit, outdir, jobs, scheduler, announce, job_horizon)
    sim_wall = time.perf_counter() - wall0
    ens = combine(scene, parsed, dynamic, nodes, results, samples, limit, seed, levels, horizon)
    hours, lv = ens["hours"], ens["levels"]
    band = {"clearance_e_mm": 1e3 * lv}  # the joint in the name, as in wear.csv
    for p in QUANTILES:  # inf where the quantile falls among the censored samples
        band[f"hours_p{round(100 * p)}"] = np.array([censored_quantile(hours[:, i], p)[0] for i in range(lv.size)])
    band["fraction_reaching"] = np.mean(np.isfinite(hours), axis=0)
    level_index = {f"{1e3 * lv[i]:.6g}": i for i in range(lv.size)
                   if i == lv.size - 1 or any(abs(lv[i] - v) < 1e-12 for v in levels)}
    by_level = {key: {**quantile_table(hours[:, i], horizon), "reaching": reaching(hours[:, i], horizon)}
                for key, i in level_index.items()}
    days = sample_days(scene, ens["values"], hours)
    shifts = shift_days(scene, ens["values"], hours)
    beyond = horizon_days(scene, ens["values"], horizon)  # a censored sample's days lie beyond this
    shift_beyond = {h: horizon_days(scene, ens["values"], horizon, h) for h in shifts or ()}
    data = {
        "scene": scene.name,
        "joint": "E",  # wear at joint E (the wear prediction's joint so far)
        "limit_clearance_mm": 1e3 * limit,
        "samples": samples,
        "seed": seed,
        "uncertain": [u.text for u in parsed],
        "method": {"rescaled": [u.key for u in parsed if u.key in RESCALED],
                   "simulated": [u.key for u in dynamic],
                   "design_quantiles": list(DESIGN_QUANTILES) if dynamic else [],
                   "design_points": {u.key: len(set(nodes[:, d])) for d, u in enumerate(dynamic)},
                   "design_rule": "log-hours between design points that reach a level; inverse hours, piecewise "
                                  "linear, where one does not (docs/wear.md section 9)",
                   "chaos_runs": len(ens["chaos_hours_at_limit"]),
                   "chaos_hours_at_limit": [float(v) for v in ens["chaos_hours_at_limit"]],
                   "chaos_relative_sd": float(np.std(ens["chaos_hours_at_limit"], ddof=1)
                                              / np.mean(ens["chaos_hours_at_limit"]))
                   if len(ens["chaos_hours_at_limit"]) > 1 else None,
                   "quantile_confidence": CONFIDENCE},
        "horizon_hours": horizon,
        "hours_to_limit": quantile_table(hours[:, -1], horizon),
        "reaching_limit": reaching(hours[:, -1], horizon),
        # the hours of the samples that reach the limit within the horizon (the conditional distribution)
        "hours_of_those_reaching": quantile_table(hours[np.isfinite(hours[:, -1]), -1], horizon)
        if np.sum(np.isfinite(hours[:, -1])) >= 2 else None,
        # design points that wear nothing at all (a full film): why, in one clause each
        "never": ens["never_nodes"],
        "censored_design_points": ens["censored_nodes"],
        "unresolved_samples": ens["unresolved"],
        "hours_by_clearance_mm": by_level,
        # calendar time (each sample's own duty, weftsim.wear.life) and the stop-starts' share of the wear
        "duty_text": duty_text(scene, ens["values"]),
        "horizon_calendar_days": beyond,
        "calendar_days_to_limit": quantile_table(days[:, -1], beyond),
        "calendar_days_by_clearance_mm": {key: quantile_table(days[:, i], beyond) for key, i in level_index.items()},
        # the same at one, two and three shifts (8, 16, 24 h a day; None where the hours a day are drawn)
        "calendar_days_by_shift": None if shifts is None else {
            f"{h:g}": {key: quantile_table(d[:, i], shift_beyond[h]) for key, i in level_index.items()}
            for h, d in shifts.items()},
        "horizon_calendar_days_by_shift": None if shifts is None else {f"{h:g}": b for h, b in shift_beyond.items()},
        "stop_start_share": stop_share_summary(results, centre_name(nodes, dynamic)),
        "shares": {k: {"rank_correlation": r, "share": s} for k, (r, s) in ens["shares"].items()},
        "jobs": {n: {"wall_s": r.get("wall_s"), "cpu_s": r.get("cpu_s"), "updates": r.get("updates"),
                     "error": r.get("error"),
                     "censored": bool(r.get("censored")), "reused": bool(r.get("reused"))}
                 for n, r in sorted(results.items())},
        "simulation_wall_time_s": sim_wall,
        "simulation_cpu_time_s": float(sum(r.get("cpu_s") or 0.0 for r in results.values())),
        "wall_time_s": time.perf_counter() - wall0,
    }
    table = {f"{k}": np.asarray(v, dtype=float) for k, v in ens["values"].items()}
    table["chaos_run"] = ens["chaos_draw"].astype(float)
    table["hours_to_limit_e"] = hours[:, -1]  # inf: does not reach the limit within the horizon
    table["reaches_limit_e"] = np.isfinite(hours[:, -1]).astype(float)
    table["calendar_days_to_limit_e"] = days[:, -1]
    files = {
        "samples": ("ensemble.csv", lambda p: write_csv(p, table)),
        "band": ("ensemble_band.csv", lambda p: write_csv(p, band)),
        "summary": ("ensemble.json", lambda p: write_json(p, data)),
    }
    if figures:
        from weftsim.wear.ensemble_figures import band_figure, cdf_figure, shares_figure

        from weftsim.wear.figures import conditions

        title = f"{scene.name}: wear at E, nominal {conditions(scene)}\n{samples} samples; uncertain: " + \
            ", ".join(u.key.rpartition(".")[2] for u in parsed)
        files["cdf_figure"] = ("ensemble_cdf.png", lambda p: write_figure(p, cdf_figure(hours[:, -1], data, title)))
        files["band_figure"] = ("ensemble_band.png",
                                lambda p: write_figure(p, band_figure(band, title, 1e3 * limit)))
        files["shares_figure"] = ("ensemble_shares.png", lambda p: write_figure(p, shares_figure(data, title)))
        shown = list(level_index.values())
        files["life_figure"] = ("ensemble_life.png", lambda p: write_figure(p, life_figure(
            days[:, shown], [1e3 * lv[i] for i in shown], data, title)))
    written = write_files(outdir, what, files, scene=scene)  # scene.toml: the nominal scene
    data["files"] = {k: str(v) for k, v in written.items()}
    return data

