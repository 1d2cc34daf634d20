"""Wear ensembles: the hours to a clearance limit as a distribution over uncertain inputs (docs/wear.md section 7).

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

import itertools
import math
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.errors import WearError
from weftsim.wear.jobs import hours_at, run_job
from weftsim.wear.uncertain import Uncertain, latin_hypercube, parse_uncertain, quantile_interval, rank_shares

if TYPE_CHECKING:
    from collections.abc import Callable

    from weftsim.input.params import Scene

RESCALED = ("joint_e.wear.wear_coefficient", "joint_e.wear.bearing_hardness_mpa", "joint_e.wear.journal_hardness_mpa")
DESIGN_QUANTILES = (0.05, 0.5, 0.95)
CHAOS_RUNS = 6  # the centre run and five whose k differs in the last bits (docs/wear.md section 6 used six)
LEVELS = 40  # clearance levels of the band between the largest starting clearance and the limit
QUANTILES = (0.1, 0.5, 0.9)
CONFIDENCE = 0.9


def _last_bits(scene: Scene, j: int) -> Scene:
    """``scene`` with its wear coefficient j units in the last place larger (the same physics to 1e-15)."""
    k = scene.joint.wear.wear_coefficient
    for _ in range(j):
        k = math.nextafter(k, math.inf)
    return replace(scene, joint=replace(scene.joint, wear=replace(scene.joint.wear, wear_coefficient=k)))


def _lagrange(nodes: np.ndarray, x: np.ndarray) -> np.ndarray:
    """(n, len(nodes)) weights of quadratic Lagrange interpolation at ``x`` (clamped to the nodes' range)."""
    x = np.clip(x, nodes.min(), nodes.max())
    w = np.ones((x.size, nodes.size))
    for i, xi in enumerate(nodes):
        for m, xm in enumerate(nodes):
            if m != i:
                w[:, i] *= (x - xm) / (xi - xm)
    return w


def plan(scene: Scene, uncertain: list[Uncertain], chaos_runs: int = CHAOS_RUNS
         ) -> tuple[list[tuple[str, Scene]], list[Uncertain], np.ndarray]:
    """(jobs as (name, scene), the dynamic inputs, their design values (nodes, dims)); checks every design scene."""
    from weftsim.input.scene import SceneError, apply_overrides, to_file_keys

    keys = to_file_keys(scene)
    seen = set()
    for u in uncertain:
        if u.key in seen:
            raise WearError(f"--uncertain {u.key} is given twice")
        seen.add(u.key)
        if u.key not in keys or u.key == "name":
            raise WearError(f"--uncertain {u.key}: not a scene key (weftsim list shows them)")
        if u.key in RESCALED and not np.all(u.ppf(np.array([1e-6, 0.5, 1 - 1e-6])) > 0.0):
            raise WearError(f"--uncertain {u.text}: {u.key} must stay > 0; a lognormal keeps it positive")
    dynamic = [u for u in uncertain if u.key not in RESCALED]
    design = np.array([[float(u.ppf(np.array([q]))[0]) for u in dynamic] for q in DESIGN_QUANTILES])
    nodes = np.array(list(itertools.product(*[design[:, d] for d in range(len(dynamic))]))) if dynamic \
        else np.zeros((1, 0))
    jobs = []
    centre = tuple(1 for _ in dynamic)
    for index in itertools.product(range(len(DESIGN_QUANTILES)), repeat=len(dynamic)):
        values = {u.key: float(design[i, d]) for d, (u, i) in enumerate(zip(dynamic, index))}
        try:
            node_scene = apply_overrides(scene, values, "--uncertain", refuse_ideal_keys=False) if values else scene
        except SceneError as exc:
            raise WearError(f"--uncertain: the design point {values} is not a valid scene: {exc}") from None
        name = "node_" + "_".join(str(i) for i in index) if dynamic else "centre"
        jobs.append((name, node_scene))
        if index == centre:
            jobs.extend((f"chaos_{j}", _last_bits(node_scene, j)) for j in range(1, chaos_runs))
    return jobs, dynamic, nodes


def _run_jobs(jobs: list[tuple[str, Scene]], limit: float, outdir: Path, jobs_n: int | None, scheduler: str | None,
              announce: Callable[[str], None] | None) -> dict[str, dict]:
    import concurrent.futures as cf

    from weftsim.sweep.pool import executor

    pool, _, stop = executor(jobs_n, scheduler, len(jobs), "reference")
    results: dict[str, dict] = {}
    try:
        futures = {pool.submit(run_job, s, limit, str(outdir / "jobs" / name)): name for name, s in jobs}
        for future in cf.as_completed(futures):
            name = futures[future]
            try:
                results[name] = future.result()
            except Exception as exc:  # noqa: BLE001 - a worker that died: recorded as that job's failure
                results[name] = {"error": f"{type(exc).__name__}: {exc}", "wall_s": math.nan}
            if announce:
                r = results[name]
                announce(f"ensemble: job {name} {'failed: ' + r['error'] if r['error'] else 'done'} "
                         f"({len(results)}/{len(jobs)}, {r.get('wall_s', math.nan):.1f} s)")
    except KeyboardInterrupt:
        stop(True)
        raise
    stop(False)
    return results


def combine(scene: Scene, uncertain: list[Uncertain], dynamic: list[Uncertain], nodes: np.ndarray,
            results: dict[str, dict], samples: int, limit: float, seed: int, levels_extra=()) -> dict:
    """The ensemble from the jobs' curves: per-sample hours at every clearance level (module docstring)."""
    from weftsim.input.scene import to_file_keys

    node_names = [n for n in results if n.startswith("node_")] or ["centre"]
    node_names.sort()
    centre = "node_" + "_".join("1" for _ in dynamic) if dynamic else "centre"
    failed = {n: r["error"] for n, r in results.items() if r.get("error")}
    bad_nodes = [n for n in node_names if n in failed]
    if bad_nodes:
        raise WearError(f"the ensemble's design run {bad_nodes[0]} failed: {failed[bad_nodes[0]]}")
    start = min(results[n]["clearance_m"][0] for n in node_names)
    levels = np.unique(np.concatenate([np.linspace(start, limit, LEVELS + 1)[1:],
                                       [v for v in levels_extra if start < v <= limit]]))
    node_hours = np.array([hours_at(results[n], levels) for n in node_names])  # (nodes, levels)
    chaos_names = [centre] + sorted(n for n in results if n.startswith("chaos_") and n not in failed)
    chaos = np.array([hours_at(results[n], levels) for n in chaos_names])
    with np.errstate(invalid="ignore", divide="ignore"):
        chaos_factor = np.where(chaos.mean(axis=0) > 0.0, chaos / chaos.mean(axis=0), 1.0)  # (runs, levels)
    # The design runs are one chaotic draw each; shift the design to pass through the chaos runs' mean at
    # the centre (the centre run is chaos run 0), so that the chaos factor is not counted twice there.
    node_hours = node_hours / chaos_factor[0]
    # Log-hours are interpolated where every design point has started wearing; a level below some design
    # point's starting clearance (hours 0 there: a clearance key is uncertain) is interpolated in hours.
    positive = np.all(node_hours > 0.0, axis=0)
    with np.errstate(divide="ignore"):
        log_nodes = np.where(positive, np.log(node_hours), node_hours)

    rng = np.random.default_rng(seed)
    u = latin_hypercube(samples, len(uncertain) + 1, rng)
    values = {v.key: v.ppf(u[:, i]) for i, v in enumerate(uncertain)}
    weights = np.ones((samples, 1))
    for d, v in enumerate(dynamic):
        w = _lagrange(np.array(sorted(set(nodes[:, d]))), values[v.key])
        index = [sorted(set(nodes[:, d])).index(x) for x in nodes[:, d]]
        weights = weights * w[:, index]
    mixed = weights @ log_nodes if dynamic else np.repeat(log_nodes, samples, axis=0)
    base = to_file_keys(scene)
    share_b = results[centre]["bearing_share"]
    scale = np.ones(samples)
    if "joint_e.wear.wear_coefficient" in values:
        scale *= base["joint_e.wear.wear_coefficient"] / values["joint_e.wear.wear_coefficient"]
    hb = values.get("joint_e.wear.bearing_hardness_mpa", base["joint_e.wear.bearing_hardness_mpa"])
    hj = values.get("joint_e.wear.journal_hardness_mpa", base["joint_e.wear.journal_hardness_mpa"])
    scale /= share_b * base["joint_e.wear.bearing_hardness_mpa"] / hb \
        + (1.0 - share_b) * base["joint_e.wear.journal_hardness_mpa"] / hj
    draw = np.minimum((u[:, -1] * len(chaos_names)).astype(int), len(chaos_names) - 1)
    base_hours = np.where(positive, np.exp(mixed), np.maximum(mixed, 0.0))
    hours = base_hours * scale[:, None] * chaos_factor[draw]  # (samples, levels)
    at_limit = hours[:, -1]
    inputs = {**values, "chaotic scatter": chaos_factor[draw, -1]}
    shares = rank_shares(inputs, np.log(at_limit))
    return {"levels": levels, "hours": hours, "values": values, "chaos_draw": draw, "inputs": inputs,
            "shares": shares, "chaos_hours_at_limit": chaos[:, -1], "failed": failed}


def quantile_table(hours: np.ndarray) -> dict:
    """{"p10": {"hours", "low", "high"}, ...} with CONFIDENCE order-statistic intervals."""
    out = {}
    for p in QUANTILES:
        est, low, high = quantile_interval(hours, p, CONFIDENCE)
        out[f"p{round(100 * p)}"] = {"hours": est, "low": low, "high": high}
    return out


def wear_ensemble(scene: Scene, uncertain: dict[str, str] | list[str], samples: int, limit: float,
                  outdir: str | Path, jobs: int | None = None, scheduler: str | None = None, seed: int = 0,
                  figures: bool = True, force: bool = False, levels: tuple[float, ...] = (),
                  chaos_runs: int = CHAOS_RUNS, announce: Callable[[str], None] | None = None) -> dict:
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
    """
    from weftsim.post.output import begin_directory, prepare_directory, write_csv, write_figure, write_files, write_json
    from weftsim.wear import check_request

    texts = [f"{k}={v}" for k, v in uncertain.items()] if isinstance(uncertain, dict) else list(uncertain)
    parsed = [parse_uncertain(t) for t in texts]
    if not parsed:
        raise WearError("an ensemble needs at least one --uncertain KEY=DISTRIBUTION")
    if not (isinstance(samples, int) and 10 <= samples <= 10**6):
        raise WearError(f"--samples must be a whole number from 10 to 1000000, got {samples!r}")
    if not (isinstance(chaos_runs, int) and 1 <= chaos_runs <= 50):
        raise WearError(f"--chaos-runs must be a whole number from 1 to 50, got {chaos_runs!r}")
    check_request(scene, 1.0, "reference", limit)
    if not scene.joint_f.is_ideal:  # its H/k rescaling and its clearance curve are joint E's
        raise WearError("an ensemble predicts the wear at E with F ideal so far; `weftsim wear SCENE --hours H` "
                        "predicts F and E with F (docs/wear.md); set joint_f.clearance_mm = 0 for the ensemble")
    job_list, dynamic, nodes = plan(scene, parsed, chaos_runs)
    for name, s in job_list:
        if not limit > s.joint.clearance:
            raise WearError(f"the design point {name} starts at a clearance of {1e3 * s.joint.clearance:g} mm, not "
                            f"below the limit {1e3 * limit:g} mm: narrow the clearance's distribution or raise "
                            "the limit")
    if announce is not None:
        from weftsim.wear.extrapolate import update_time

        announce(f"ensemble: {len(job_list)} simulated predictions to {1e3 * limit:g} mm ("
                 f"{3 ** len(dynamic) if dynamic else 1} design point(s) of {len(dynamic)} simulated key(s), "
                 f"{chaos_runs - 1} more chaos run(s)); one update of the nominal scene ~{update_time(scene):.2g} s, "
                 f"~{math.log(limit / scene.joint.clearance) / math.log1p(scene.joint.wear.max_clearance_change):.0f} "
                 "updates a prediction; the samples cost no simulation")
    outdir = prepare_directory(outdir, force)
    what = {"kind": "wear ensemble", "scene": scene.name}
    begin_directory(outdir, what)
    wall0 = time.perf_counter()
    results = _run_jobs(job_list, limit, outdir, jobs, scheduler, announce)
    sim_wall = time.perf_counter() - wall0
    ens = combine(scene, parsed, dynamic, nodes, results, samples, limit, seed, levels)
    hours, lv = ens["hours"], ens["levels"]
    band = {"clearance_e_mm": 1e3 * lv}  # the joint in the name, as in wear.csv
    for p in QUANTILES:
        band[f"hours_p{round(100 * p)}"] = np.quantile(hours, p, axis=0)
    by_level = {f"{1e3 * lv[i]:.6g}": quantile_table(hours[:, i]) for i in range(lv.size)
                if i == lv.size - 1 or any(abs(lv[i] - v) < 1e-12 for v in levels)}
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
                   "chaos_runs": len(ens["chaos_hours_at_limit"]),
                   "chaos_hours_at_limit": [float(v) for v in ens["chaos_hours_at_limit"]],
                   "chaos_relative_sd": float(np.std(ens["chaos_hours_at_limit"], ddof=1)
                                              / np.mean(ens["chaos_hours_at_limit"]))
                   if len(ens["chaos_hours_at_limit"]) > 1 else None,
                   "quantile_confidence": CONFIDENCE},
        "hours_to_limit": quantile_table(hours[:, -1]),
        "hours_by_clearance_mm": by_level,
        "shares": {k: {"rank_correlation": r, "share": s} for k, (r, s) in ens["shares"].items()},
        "jobs": {n: {"wall_s": r.get("wall_s"), "updates": r.get("updates"), "error": r.get("error"),
                     "reused": bool(r.get("reused"))} for n, r in sorted(results.items())},
        "simulation_wall_time_s": sim_wall,
        "wall_time_s": time.perf_counter() - wall0,
    }
    table = {f"{k}": np.asarray(v, dtype=float) for k, v in ens["values"].items()}
    table["chaos_run"] = ens["chaos_draw"].astype(float)
    table["hours_to_limit_e"] = hours[:, -1]
    files = {
        "samples": ("ensemble.csv", lambda p: write_csv(p, table)),
        "band": ("ensemble_band.csv", lambda p: write_csv(p, band)),
        "summary": ("ensemble.json", lambda p: write_json(p, data)),
    }
    if figures:
        from weftsim.wear.ensemble_figures import band_figure, cdf_figure, shares_figure

        title = f"{scene.name}: wear at E, {samples} samples"
        files["cdf_figure"] = ("ensemble_cdf.png", lambda p: write_figure(p, cdf_figure(hours[:, -1], data, title)))
        files["band_figure"] = ("ensemble_band.png", lambda p: write_figure(p, band_figure(band, title)))
        files["shares_figure"] = ("ensemble_shares.png", lambda p: write_figure(p, shares_figure(data, title)))
    written = write_files(outdir, what, files)
    data["files"] = {k: str(v) for k, v in written.items()}
    return data

