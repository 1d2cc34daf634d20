"""Speed study, like the paper's Fig. 13: c = 0.25 mm at 300, 500 and 800 rpm (reference engine).

Besides the overlaid curves of the last revolution, it gives

- amplitude ratios between speeds for the driving torque and the rapier acceleration,
  several ways (the paper does not say which it used): the ideal joint's peak (exactly
  (n2/n1)^2 by kinematics), the first-revolution peak, the 99th percentile of the
  magnitude and the RMS over revolutions 2..N, and the last revolution's peak;
- the amplitude spectrum of the rapier acceleration over revolutions 2..N
  (:func:`weftsim.studies.spectrum.acceleration_spectrum`: single-sided, A_k = 2|X_k|/N,
  the amplitude of each sinusoid), its largest line, the largest line in 0-10 Hz and the
  share of the fluctuation's mean square below 10 Hz.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from weftsim.studies import common
from weftsim.studies.spectrum import acceleration_spectrum

if TYPE_CHECKING:
    from weftsim.studies.spectrum import Spectrum

IDEAL_SCENE = "ideal.toml"
SCENES = {300.0: "paper/speed_300rpm_c0p25mm.toml", 500.0: "paper/speed_500rpm_c0p25mm.toml",
          800.0: "paper/speed_800rpm_c0p25mm.toml"}
REVOLUTIONS = 10.0  # 9 whole revolutions after the start-up one: spectrum lines every f_rev / 9
SETS = {"drive.speed_rpm": "it varies the crank speed: 300, 500, 800 rpm"}  # common.study_overrides
PAIRS = ((800.0, 500.0), (500.0, 300.0), (800.0, 300.0))
PAPER_BAND_HZ = 10.0  # paper: "the main frequency fluctuation is between 0 and 10 Hz"
COLOURS = {300.0: "tab:blue", 500.0: "tab:orange", 800.0: "tab:red"}
CHANNELS = {"torque": "driving_torque_Nm", "acceleration": "rapier_acceleration_m_s2"}


def amplitude_measures(metrics: dict, channel: str) -> dict[str, float | None]:
    """Ways to read "the amplitude" of a channel from one run's metrics."""
    stats = (metrics["statistics"] or {}).get(channel, {})
    return {
        "first_revolution_peak": common.magnitude(metrics["first_revolution"][channel]),
        "p99_abs": stats.get("p99_abs"),
        "rms": stats.get("rms"),
        "last_revolution_peak": common.magnitude(metrics["last_revolution"][channel]),
    }


def spectrum_summary(spectrum: Spectrum, speed_rpm: float) -> dict:
    f_rev = speed_rpm / 60.0
    peak_f, peak_a = spectrum.peak()
    band_f: float | None
    band_a: float | None
    try:
        band_f, band_a = spectrum.peak(0.0, PAPER_BAND_HZ)
    except ValueError:  # lines every f_rev / revolutions may all lie above 10 Hz
        band_f = band_a = None
    line = int(np.argmin(np.abs(spectrum.frequency_hz - f_rev)))
    return {
        "crank_frequency_hz": f_rev,
        "line_spacing_hz": float(spectrum.frequency_hz[1]),
        "revolutions": spectrum.revolutions,
        "max_amplitude_m_s2": peak_a,
        "max_amplitude_frequency_hz": peak_f,
        "max_amplitude_harmonic": peak_f / f_rev,
        "band_0_10hz_max_amplitude_m_s2": band_a,
        "band_0_10hz_max_frequency_hz": band_f,
        "fundamental_amplitude_m_s2": float(spectrum.amplitude[line]),
        "power_fraction_0_10hz": spectrum.power_fraction(0.0, PAPER_BAND_HZ),
        "power_fraction_first_5_harmonics": spectrum.power_fraction(0.0, 5.0 * f_rev + 1e-9),
    }


def run(outdir: str | Path, models: str | Path = "models", revolutions: float | None = None,
        force: bool = False, progress: bool = True, overrides: dict | None = None,
        scene: str | Path | None = None) -> dict:
    """Run the speed study into ``outdir``; returns what ``speed.json`` holds.

    ``overrides``: scene keys (file units) applied to every run, except the speed (:data:`SETS`).
    ``scene``: the scene file or bundled name its cases run on (default: the paper's reference, ``models/``).
    """
    from weftsim.post.output import write_csv, write_figure, write_json
    from weftsim.studies.figures import channel_panels, spectrum_panels, trend_panels

    overrides = common.study_overrides("speed", SETS, revolutions, REVOLUTIONS, overrides)
    base = common.base_scene(models, scene, overrides)
    outdir = common.open_directory(outdir, force, base)
    note = common.title_note(base, overrides)
    results, ideals = {}, {}
    for rpm, name in SCENES.items():
        ideals[rpm] = common.solve(common.load(models, IDEAL_SCENE, {**overrides, "drive.speed_rpm": rpm,
                                                                    "name": f"ideal_{rpm:g}rpm"}, scene),
                                   progress=progress)
        results[rpm] = common.solve(common.load(models, name, overrides, scene), progress=progress)
    c = f"c = {common.clearance_mm(results[500.0].scene):g} mm"  # the paper's 0.25 mm, or the scene's
    metrics = {rpm: common.run_metrics(r) for rpm, r in results.items()}
    ideal_metrics = {rpm: common.run_metrics(r) for rpm, r in ideals.items()}
    written: dict[str, Any] = {}
    curves: list[tuple[str, Any, dict[str, Any]]] = []
    spectra: list[tuple[str, Any, dict[str, Any]]] = []
    spectrum_rows: dict[str, dict[str, Any]] = {}
    table: dict[str, dict[str, Any]] = {}
    for rpm, result in results.items():
        n = metrics[rpm]["revolutions"]
        data = common.revolution_steps(result, max(n - 1, 0))
        written[f"curves-{rpm:g}"] = common.write_curves(outdir, f"speed-curves-{rpm:g}rpm", data)
        curves.append((f"{rpm:g} rpm, {c}", data, {"color": COLOURS[rpm]}))
        ideal_data = common.revolution_steps(ideals[rpm], max(n - 1, 0))
        curves.append((f"{rpm:g} rpm, ideal joint", ideal_data, {"color": COLOURS[rpm], "ls": "--", "lw": 0.7}))
        table[f"{rpm:g}"] = {kind: {"clearance": amplitude_measures(metrics[rpm], channel),
                                    "ideal_peak": common.magnitude(ideal_metrics[rpm]["first_revolution"][channel])}
                             for kind, channel in CHANNELS.items()}
        if n >= 2:
            spectrum = acceleration_spectrum(result)
            ideal_spectrum = acceleration_spectrum(ideals[rpm])
            spectra.append((f"{rpm:g} rpm, {c}", spectrum, {"color": COLOURS[rpm]}))
            spectrum_rows[f"{rpm:g}"] = {"clearance": spectrum_summary(spectrum, rpm),
                                         "ideal": spectrum_summary(ideal_spectrum, rpm)}
            written[f"spectrum-{rpm:g}"] = write_csv(outdir / f"speed-spectrum-{rpm:g}rpm.csv", {
                "frequency_hz": spectrum.frequency_hz, "amplitude_m_s2": spectrum.amplitude,
                "ideal_amplitude_m_s2": ideal_spectrum.amplitude})
    ratios: dict[str, dict[str, Any]] = {}
    for high, low in PAIRS:
        key = f"{high:g}/{low:g}"
        ratios[key] = {"ideal_kinematics": (high / low) ** 2}
        for kind in CHANNELS:
            a, b = table[f"{high:g}"][kind], table[f"{low:g}"][kind]
            ratios[key][kind] = {"ideal_peak": common.ratio(a["ideal_peak"], b["ideal_peak"]),
                                 **{m: common.ratio(a["clearance"][m], b["clearance"][m]) for m in a["clearance"]}}
        if spectrum_rows:
            sa, sb = spectrum_rows[f"{high:g}"], spectrum_rows[f"{low:g}"]
            ratios[key]["spectrum_max_amplitude"] = common.ratio(sa["clearance"]["max_amplitude_m_s2"],
                                                                 sb["clearance"]["max_amplitude_m_s2"])
    n = metrics[500.0]["revolutions"]
    written["figure"] = write_figure(outdir / "study-speed.png", channel_panels(
        curves, f"speed study at {c}, reference engine, last of {n} revolutions (cf. paper Fig. 13)" + note))
    speeds = list(SCENES)
    panels = []
    for kind, unit in (("acceleration", "rapier acceleration [m/s²]"), ("torque", "driving torque [N·m]")):
        rows = [table[f"{rpm:g}"][kind] for rpm in speeds]
        panels.append((unit, [("ideal joint, peak", [r["ideal_peak"] for r in rows]),
                              (f"{c}, max revolution 1",
                               [r["clearance"]["first_revolution_peak"] for r in rows]),
                              (f"{c}, 99th pct |.|, rev. 2..N", [r["clearance"]["p99_abs"] for r in rows]),
                              (f"{c}, RMS, rev. 2..N", [r["clearance"]["rms"] for r in rows])]))
    written["trend"] = write_figure(outdir / "study-speed-trend.png", trend_panels(
        speeds, "crank speed [rpm]", panels, "amplitude against crank speed (reproducible quantities)" + note, speeds))
    if spectra:
        written["spectrum"] = write_figure(outdir / "study-speed-spectrum.png", spectrum_panels(
            spectra, f"rapier acceleration spectrum, {c}, revolutions 2..{n} "
                     "(single-sided amplitude 2|X|/N)" + note))
    report = {
        "study": "speed",
        **common.record(base, overrides),
        "clearance_mm": metrics[500.0]["clearance_mm"],
        "revolutions": n,
        "runs": {f"{rpm:g}": metrics[rpm] for rpm in speeds},
        "ideal_runs": {f"{rpm:g}": ideal_metrics[rpm] for rpm in speeds},
        "amplitudes": table,
        "ratios": ratios,
        "spectrum": spectrum_rows,
        "spectrum_convention": "single-sided amplitude: A_0 = |X_0|/N, A_k = 2|X_k|/N (k >= 1) of the bin means "
                               "over revolutions 2..N, box-filter gain divided out; a sine of amplitude A "
                               "gives A",
        "files": sorted(p.name for p in written.values()) + ["speed.json"],
    }
    written["json"] = write_json(outdir / "speed.json", report)
    common.finish(outdir, written, "speed", base)
    return report


def format_report(report: dict) -> str:
    """The tables ``weftsim study speed`` prints."""
    def f(value, spec):
        return format(value, spec) if value is not None else "-"

    lines = [f"speed study at c = {report['clearance_mm']:g} mm, {report['revolutions']} revolutions "
             "(reference engine)",
             f"{'rpm':>5s} {'channel':>12s} {'ideal pk':>9s} {'rev1 pk':>9s} {'p99|.|':>9s} {'RMS':>9s} "
             f"{'last pk':>9s}"]
    for rpm, row in report["amplitudes"].items():
        for kind, values in row.items():
            c = values["clearance"]
            lines.append(f"{rpm:>5s} {kind:>12s} {values['ideal_peak']:9.1f} {f(c['first_revolution_peak'], '9.1f')} "
                         f"{f(c['p99_abs'], '9.1f')} {f(c['rms'], '9.1f')} {f(c['last_revolution_peak'], '9.1f')}")
    lines.append("amplitude ratios (ideal kinematics: (n2/n1)^2)")
    for pair, row in report["ratios"].items():
        for kind in CHANNELS:
            r = row[kind]
            lines.append(f"  {pair:>7s} {kind:>12s}: ideal {f(r['ideal_peak'], '.3f')}, rev1 peak "
                         f"{f(r['first_revolution_peak'], '.3f')}, p99|.| {f(r['p99_abs'], '.3f')}, RMS "
                         f"{f(r['rms'], '.3f')}, last-rev peak {f(r['last_revolution_peak'], '.3f')}")
        if "spectrum_max_amplitude" in row:
            lines.append(f"  {pair:>7s} spectrum max amplitude: {f(row['spectrum_max_amplitude'], '.3f')}")
    lines.append("acceleration spectrum over revolutions 2..N (single-sided amplitude 2|X|/N)")
    for rpm, row in report["spectrum"].items():
        s, i = row["clearance"], row["ideal"]
        lines.append(f"  {rpm:>4s} rpm: max {s['max_amplitude_m_s2']:.1f} m/s^2 at "
                     f"{s['max_amplitude_frequency_hz']:.2f} Hz "
                     f"(harmonic {s['max_amplitude_harmonic']:.2f}; ideal {i['max_amplitude_m_s2']:.1f}), "
                     f"max in 0-10 Hz {f(s['band_0_10hz_max_amplitude_m_s2'], '.1f')} at "
                     f"{f(s['band_0_10hz_max_frequency_hz'], '.2f')} Hz, mean-square share 0-10 Hz "
                     f"{100 * s['power_fraction_0_10hz']:.1f}%, first 5 harmonics "
                     f"{100 * s['power_fraction_first_5_harmonics']:.1f}%")
    return "\n".join(lines)
