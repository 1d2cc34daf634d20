"""Engine comparison, like the paper's Fig. 16: c = 0.50 mm at 400 rpm, both engines overlaid.

The paper compares its Lagrange model (MATLAB) with an ADAMS virtual prototype and
reports model / prototype peak ratios of 1.035 (rapier acceleration) and 1.099
(driving torque).  Here the closed-form Lagrange solver (``reference``) plays the
paper's model and the Exudyn multibody model (``exudyn``) the virtual prototype, so the
paper's ratios correspond to reference / exudyn; both directions are reported.

The agreement checks are those of ``weftsim compare`` (:func:`weftsim.post.compare.compare_results`):
first contact angle and first-revolution maxima, and with 10 or more revolutions the RMS
and 99th percentiles over revolutions 2..N.  Two figures: the first revolution (where
the engines must agree) and the last one (an illustration, as the paper's Fig. 16).
"""

from __future__ import annotations

from pathlib import Path

from weftsim.studies import common

SCENE = "paper/clearance_0p50mm_400rpm.toml"
REVOLUTIONS = 10.0  # compare.py checks statistics from 10 revolutions on
SETS: dict[str, str] = {}  # both engines run the same scene: any key may be overridden (common.study_overrides)
ENGINES = ("reference", "exudyn")
STYLES = {"reference": {"color": "tab:blue", "lw": 1.1}, "exudyn": {"color": "tab:red", "lw": 0.8, "ls": "--"}}
LABELS = {"reference": "reference (closed-form Lagrange; the paper's model)",
          "exudyn": "exudyn (multibody; the paper's ADAMS prototype)"}
PAPER_RATIOS = {"rapier_acceleration_m_s2": 1.035, "driving_torque_Nm": 1.099}


def peak_ratios(reference: dict, exudyn: dict) -> dict:
    """reference / exudyn ratios of the peak magnitudes, several ways (None where undefined)."""
    out = {}
    for channel in ("rapier_acceleration_m_s2", "driving_torque_Nm", "contact_force_N"):
        rs, es = (reference["statistics"] or {}).get(channel, {}), (exudyn["statistics"] or {}).get(channel, {})
        out[channel] = {
            "first_revolution_peak": common.ratio(common.magnitude(reference["first_revolution"][channel]),
                                                  common.magnitude(exudyn["first_revolution"][channel])),
            "p99_abs": common.ratio(rs.get("p99_abs"), es.get("p99_abs")),
            "rms": common.ratio(rs.get("rms"), es.get("rms")),
            "last_revolution_peak": common.ratio(common.magnitude(reference["last_revolution"][channel]),
                                                 common.magnitude(exudyn["last_revolution"][channel])),
        }
    return out


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the engine comparison into ``outdir``; returns what ``engines.json`` holds.

    ``overrides``: scene keys (file units) applied to the scene both engines run.
    ``scene``: the scene file or bundled name its cases run on (default: the paper's reference, ``models/``).
    """
    from weftsim.post.compare import compare_results
    from weftsim.post.output import write_figure, write_json
    from weftsim.studies.figures import channel_panels

    overrides = common.study_overrides("engines", SETS, revolutions, REVOLUTIONS, overrides)
    source, base = scene, common.base_scene(models, scene, overrides)
    outdir = common.open_directory(outdir, force, base)
    study_scene = common.load(models, SCENE, overrides, source)
    results = {engine: common.solve(study_scene, engine, progress=progress) for engine in ENGINES}
    metrics = {engine: common.run_metrics(r) for engine, r in results.items()}
    comparison = compare_results(results["exudyn"], results["reference"])
    written = {}
    n = min(m["revolutions"] for m in metrics.values())
    rpm = common.speed_rpm(study_scene)
    for which, revolution in (("first", 0), ("last", max(n - 1, 0))):
        curves = []
        for engine in ENGINES:
            data = common.revolution_steps(results[engine], revolution)
            written[f"{engine}-{which}"] = common.write_curves(outdir, f"engines-curves-{engine}-rev{revolution + 1}",
                                                               data)
            curves.append((LABELS[engine], data, STYLES[engine]))
        name = "study-engines.png" if which == "first" else "study-engines-last.png"
        note = "where the engines must agree" if which == "first" else "an illustration: impacts not reproducible"
        written[f"figure-{which}"] = write_figure(outdir / name, channel_panels(
            curves, f"c = {study_scene.joint.clearance * 1e3:g} mm, {rpm:g} rpm: revolution {revolution + 1} of {n} "
                    f"({note}; cf. paper Fig. 16)" + common.title_note(base, overrides)))
    ratios = peak_ratios(metrics["reference"], metrics["exudyn"])
    report = {
        "study": "engines",
        **common.record(base, overrides),
        "scene": study_scene.name,
        "clearance_mm": common.clearance_mm(study_scene),
        "speed_rpm": rpm,
        "revolutions": n,
        "runs": metrics,
        "ratios_reference_over_exudyn": ratios,
        "paper_ratios_model_over_prototype": PAPER_RATIOS,
        "compare": comparison,
        "files": sorted(p.name for p in written.values()) + ["engines.json"],
    }
    written["json"] = write_json(outdir / "engines.json", report)
    common.finish(outdir, written, "engines", base)
    return report


def format_report(report: dict) -> str:
    """The lines ``weftsim study engines`` prints."""
    from weftsim.post.compare import format_report as compare_table

    def f(value):
        return f"{value:.4f}" if value is not None else "-"

    lines = [f"engine comparison, c = {report['clearance_mm']:g} mm, {report['speed_rpm']:g} rpm, "
             f"{report['revolutions']} revolutions",
             "reference / exudyn peak ratios (paper, model / ADAMS: acceleration 1.035, torque 1.099):"]
    for channel, row in report["ratios_reference_over_exudyn"].items():
        lines.append(f"  {channel:26s} rev1 peak {f(row['first_revolution_peak'])}, p99|.| {f(row['p99_abs'])}, "
                     f"RMS {f(row['rms'])}, last-rev peak {f(row['last_revolution_peak'])}")
    for engine, m in report["runs"].items():
        lines.append(f"  {engine:9s} wall time {m['wall_time_s']:.1f} s")
    lines.append(compare_table(report["compare"]))
    return "\n".join(lines)
