"""docs/paper-comparison.md from the four study reports (every number comes from them).

:func:`render` takes the JSON content of the ``contact-law``, ``clearance``, ``speed``
and ``engines`` studies and returns Markdown: one table row per quantitative statement
of docs/physics.md section 5 (the paper's number, ours, one line on why they agree or differ),
then one section per study with its figures.  Verdicts that depend on the numbers
(monotonic trends, ranges) are computed here, not written in advance.
"""

from __future__ import annotations

import math

PAPER_SPEED_RATIO = {"torque": 2.0, "acceleration": 1.9}
PAPER_SPECTRUM = {"300": 80.0, "500": 255.0, "800": 977.5}
PAPER_ENGINE_RATIO = {"rapier_acceleration_m_s2": 1.035, "driving_torque_Nm": 1.099}
HERTZ_IMPACT_EXPONENT = 1.2  # peak Hertz force of an impact ~ v_imp^(6/5), v_imp ~ crank speed


def _g(value, digits: int = 4) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}g}"


def _f(value, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def _pct(value) -> str:
    return "-" if value is None else f"{100 * value:+.2f}%"


def _increasing(values) -> bool | None:
    if any(v is None for v in values):
        return None
    return all(b > a for a, b in zip(values, values[1:]))


def _verdict(flag: bool | None, yes: str, no: str) -> str:
    return "(not enough revolutions to tell)" if flag is None else (yes if flag else no)


def _row(statement: str, paper: str, ours: str, why: str) -> str:
    return f"| {statement} | {paper} | {ours} | {why} |"


def _offsets_after(angles, extremes) -> list[float]:
    """For each angle, how far (deg, 0..360) it lies after the nearest preceding extreme."""
    return [min((a - e) % 360.0 for e in extremes) for a in angles]


def summary_rows(reports: dict) -> list[str]:
    """The comparison table: one row per statement of docs/physics.md section 5, verdicts computed from the numbers."""
    cl, sp, en, law = reports["clearance"], reports["speed"], reports["engines"], reports["contact-law"]
    rows = ["| paper (docs/physics.md section 5) | paper's number | ours | agree? why |", "|---|---|---|---|"]
    trend = cl["trend"]
    cs = ", ".join(f"{r['clearance_mm']:g}" for r in trend)
    changes = [abs(r[f"{q}_max_change_vs_ideal"]) for r in trend for q in ("displacement", "velocity")
               if r[f"{q}_max_change_vs_ideal"] is not None]
    largest = max(changes) if changes else None
    rows.append(_row(
        "clearance barely changes peak rapier displacement and velocity", "(curves, Fig. 12 a-b)",
        f"largest change of the peak displacement or velocity vs the ideal joint, revolutions 2..N, c = {cs} mm: "
        f"{_pct(largest)}",
        _verdict(None if largest is None else largest < 0.02,
                 "agrees: the rapier follows the kinematics within the clearance; s and v integrate the impacts away",
                 "differs: the peaks move by 2% or more")))
    keys = (("acceleration_rms_m_s2", "RMS a"), ("torque_rms_Nm", "RMS T"), ("contact_force_p99_N", "p99 F"),
            ("first_revolution_contact_force_max_N", "rev. 1 max F"))
    ours = "; ".join(f"{label} " + " → ".join(_g(r[key], 3) for r in trend) for key, label in keys)
    flags = [_increasing([r[key] for r in trend]) for key, _ in keys]
    flag = None if None in flags else all(flags)
    rows.append(_row(
        f"acceleration, torque and contact force fluctuate more with larger clearance ({cs} mm, "
        f"{cl['speed_rpm']:g} rpm)", "(curves, Fig. 12 c-f)", ours + " (units m/s², N·m, N)",
        _verdict(flag, "agrees: every one of these reproducible measures grows with c (longer free flight, "
                       "faster impacts)",
                 "differs in part: not every measure grows with c (see the clearance section)")))
    speeds = list(sp["amplitudes"])
    sp_keys = (("acceleration", "p99_abs", "p99 abs(a)"), ("torque", "p99_abs", "p99 abs(T)"),
               ("acceleration", "first_revolution_peak", "rev. 1 max abs(a)"))
    ours = "; ".join(f"{label} " + " → ".join(_g(sp["amplitudes"][s][kind]["clearance"][m], 3) for s in speeds)
                     for kind, m, label in sp_keys)
    flags = [_increasing([sp["amplitudes"][s][kind]["clearance"][m] for s in speeds]) for kind, m, _ in sp_keys]
    flag = None if None in flags else all(flags)
    rows.append(_row(f"... and with higher speed ({', '.join(speeds)} rpm, c = {sp['clearance_mm']:g} mm)",
                     "(curves, Fig. 13)", ours + " (units m/s², N·m)",
                     _verdict(flag, "agrees: all grow with speed (inertial loads as ω², impact velocities as ω)",
                              "differs in part (see the speed section)")))
    features = cl["ideal_features_deg"]
    near, offsets = [], []
    for c, row in cl["acceleration_deviation"].items():
        if row["largest_bins_deg"]:
            near.append(f"c = {c} mm: {', '.join(f'{a:g}°' for a in row['largest_bins_deg'])}")
            offsets += _offsets_after(row["largest_bins_deg"], features["velocity_extremes_deg"])
    if offsets:
        why = (f"agrees in part: our largest departures lie {min(offsets):.0f}-{max(offsets):.0f}° after the velocity "
               "extremes, where a changes sign, the load through E reverses and the journal crosses the clearance "
               "(bins 10° wide); the a extremes (v = 0) are calmer" if max(offsets) <= 60.0 else
               f"differs in part: some of our largest departures lie more than 60° after a velocity extreme "
               f"({', '.join(f'{o:.0f}°' for o in offsets)})")
    else:
        why = "(not enough revolutions to tell)"
    rows.append(_row(
        "high-frequency oscillation near the acceleration extremes and where the velocity peaks or crosses zero",
        "(Fig. 12 c)",
        f"10° bins of largest RMS(a − a_ideal), revolutions 2..N: {'; '.join(near) or '-'}. Ideal: a extremes at "
        f"{_f(features['acceleration_max_deg'][0], '.0f')}° and {_f(features['acceleration_min_deg'][0], '.0f')}°, "
        f"v extremes (a = 0) at {', '.join(f'{a:.1f}°' for a in features['velocity_extremes_deg'])}, v = 0 at "
        f"{', '.join(f'{a:.0f}°' for a in features['velocity_zeros_deg'])}", why))
    ratio = sp["ratios"].get("800/500")
    if ratio:
        impact = 1.6 ** HERTZ_IMPACT_EXPONENT
        for kind in ("torque", "acceleration"):
            r = ratio[kind]
            first = r["first_revolution_peak"]
            inside = first is not None and impact <= first <= ratio["ideal_kinematics"]
            rows.append(_row(
                f"800 vs 500 rpm: {kind} amplitude ratio", f"{PAPER_SPEED_RATIO[kind]:.1f}× (ideal kinematics "
                f"{ratio['ideal_kinematics']:.2f}×)",
                f"rev. 1 peak {_f(first, '.3f')}×, last-rev. peak {_f(r['last_revolution_peak'], '.3f')}×, p99 "
                f"{_f(r['p99_abs'], '.3f')}×, RMS {_f(r['rms'], '.3f')}×; ideal {_f(r['ideal_peak'], '.3f')}×",
                ("agrees" if inside else "differs") + f": the start-up impact peak (reproducible) scales "
                f"{_f(first, '.2f')}×, {'inside' if inside else 'outside'} the range from a Hertz impact peak "
                f"(∝ v_imp^1.2, {impact:.2f}×) to a pure inertial load (2.56×), where the paper's "
                f"{PAPER_SPEED_RATIO[kind]:.1f}× also lies; statistics scale closer to 2.56× (kinematic part); "
                "last-revolution peaks are not reproducible"))
    spectrum = sp["spectrum"]
    if spectrum:
        lines = "; ".join(f"{s} rpm: largest line {row['clearance']['max_amplitude_frequency_hz']:.2f} Hz "
                          f"(harmonic {row['clearance']['max_amplitude_harmonic']:.0f}), "
                          f"{100 * row['clearance']['power_fraction_0_10hz']:.0f}% of the mean square in 0-10 Hz"
                          for s, row in spectrum.items())
        below = [s for s, row in spectrum.items() if row["clearance"]["max_amplitude_frequency_hz"] <= 10.0]
        above = [s for s in spectrum if s not in below]
        why = (f"agrees at {', '.join(below) or 'no speed'} rpm, where the largest line (the crank frequency) is "
               "below 10 Hz" + (f"; at {', '.join(above)} rpm the crank frequency itself is above 10 Hz, so the "
                                "main line cannot lie in 0-10 Hz in any model" if above else ""))
        rows.append(_row("acceleration spectrum: main content 0-10 Hz", "0-10 Hz", lines, why))
        amps = [spectrum[s]["clearance"]["max_amplitude_m_s2"] for s in spectrum]
        ours_ratios = [b / a for a, b in zip(amps, amps[1:])]
        squares = [(float(b) / float(a)) ** 2 for a, b in zip(spectrum, list(spectrum)[1:])]
        paper_amps = [PAPER_SPECTRUM.get(s) for s in spectrum]
        paper_ratios = [b / a for a, b in zip(paper_amps, paper_amps[1:]) if a and b]
        as_square = all(abs(r / q - 1) < 0.02 for r, q in zip(ours_ratios, squares))
        rows.append(_row(
            "spectrum maximum amplitudes at " + ", ".join(spectrum) + " rpm",
            ", ".join(f"{PAPER_SPECTRUM[s]:g}" for s in spectrum if s in PAPER_SPECTRUM) + " m/s² (ratios "
            + ", ".join(f"{r:.2f}" for r in paper_ratios) + ")",
            ", ".join(f"{a:.1f}" for a in amps) + " m/s² (ratios " + ", ".join(f"{r:.2f}" for r in ours_ratios)
            + "; ideal joint " + ", ".join(f"{spectrum[s]['ideal']['max_amplitude_m_s2']:.1f}" for s in spectrum)
            + ")",
            "differs: ours is the crank-frequency line of the kinematics (about half the stroke × ω²; our stroke "
            "is 1.05 m)" + (", within 2% of the ω² ratios " + ", ".join(f"{q:.2f}" for q in squares)
                             if as_square else "")
            + "; the paper's grow faster than ω² and its amplitude convention and Table 1 are unknown, so only "
            "the growth with speed agrees"))
    ours_r = en["ratios_reference_over_exudyn"]
    for channel, label in (("rapier_acceleration_m_s2", "acceleration"), ("driving_torque_Nm", "torque")):
        r = ours_r[channel]
        first = r["first_revolution_peak"]
        later = [v for k, v in r.items() if k != "first_revolution_peak" and v is not None]
        paper = PAPER_ENGINE_RATIO[channel]
        why = ("closer than the paper" if first is not None and abs(first - 1) < abs(paper - 1) else
               "not closer than the paper") + " on the reproducible first revolution (same equations and contact " \
            "law, only the integrators differ)"
        if later:
            why += (f"; over later revolutions the ratios scatter by up to {100 * max(abs(v - 1) for v in later):.1f}% "
                    "because the impact sequence is not reproducible (docs/physics.md section 6)")
        rows.append(_row(
            f"model vs virtual prototype (c = {en['clearance_mm']:g} mm, {en['speed_rpm']:g} rpm): peak {label}",
            f"{paper:.3f}× (Lagrange model / ADAMS)",
            f"reference / exudyn: rev. 1 peak {_f(first, '.4f')}×, last-rev. peak "
            f"{_f(r['last_revolution_peak'], '.4f')}×, p99 {_f(r['p99_abs'], '.4f')}×, RMS {_f(r['rms'], '.4f')}×",
            why))
    c = law["curve"]
    slopes = c["stiffness_log_slope"]
    rows.append(_row(
        f"Fig. 7: K(δ) rises steeply and flattens after δ ≈ 0.005 mm (c = {law['clearance_mm']:g} mm)", "0.005 mm",
        f"K(0.005 mm) = {c['stiffness_at_0p005mm']:.3g} N/m^1.5 = {100 * c['stiffness_at_0p005mm_over_plateau']:.0f}% "
        f"of the plateau {c['stiffness_plateau']:.3g}; d ln K/d ln δ = "
        + ", ".join(f"{v:.2f} at {k} mm" for k, v in slopes.items()),
        _verdict(c["stiffness_at_0p005mm_over_plateau"] > 0.5,
                 "agrees: K ∝ √δ for δ ≪ c (slope 0.5), flat for δ ≫ c; at 0.005 mm K has most of "
                 "its plateau",
                 "differs: at 0.005 mm K has less than half its plateau")))
    rev = law["revolution"]
    if rev:
        stable = rev["time_fraction_in_contact"] > 0.9 and rev["stiffness_median"] > 0.9 * c["stiffness_plateau"]
        rows.append(_row(
            f"Fig. 8: at small clearance K stays in a stable range for a long time ({law['speed_rpm']:g} rpm)",
            "(curve)", f"revolution {law['plotted_revolution']}: in contact "
            f"{100 * rev['time_fraction_in_contact']:.1f}% of the time, median K {rev['stiffness_median']:.3g} "
            f"N/m^1.5 (plateau {c['stiffness_plateau']:.3g}), "
            f"δ up to {rev['penetration_max_mm']:.3g} mm",
            _verdict(stable, f"agrees: at c = {law['clearance_mm']:g} mm the journal stays in contact most of the "
                             "revolution with δ ≫ c, on the plateau of K",
                     "differs: contact is intermittent or K is off its plateau")))
    d = c["damping_log_slope"]
    linear = min(d.values()) < 1.2
    rows.append(_row(
        "Fig. 9: D(δ) nonlinear up to δ ≈ 0.015 mm, then closer to linear", "0.015 mm",
        "d ln D/d ln δ at fixed v_imp = " + ", ".join(f"{v:.2f} at {k} mm" for k, v in d.items()),
        "agrees: D becomes close to linear" if linear else
        f"differs in part: D = ξ K(δ) δ^1.5 / v_imp bends from ∝ δ² to ∝ δ^1.5 around δ ~ c (slope "
        f"{min(d.values()):.2f} at {max(d, key=lambda k: float(k))} mm), never linear; the paper's Eq. 23 is lost, "
        "its D may differ, or its plot mixes impact velocities"))
    return rows


def _figure(name: str, alt: str) -> str:
    return f"![{alt}](img/{name})"


def clearance_section(cl: dict) -> list[str]:
    clearances = ", ".join(f"{r['clearance_mm']:g}" for r in cl["trend"])
    out = ["## Clearance study (paper Fig. 12)", "",
           f"c = {clearances} mm at {cl['speed_rpm']:g} rpm, "
           f"{cl['revolutions']} revolutions each, reference engine; the curves show the last revolution "
           "(an illustration), the trend figure the reproducible numbers.", "",
           _figure("study-clearance.png", "clearance study: six channels over the last revolution"), "",
           _figure("study-clearance-trend.png", "clearance trend of reproducible quantities"), "",
           "| c [mm] | first contact [deg] | rev. 1 max F [N] | rev. 1 max abs(a) [m/s²] | rev. 1 max abs(T) [N·m] "
           "| RMS a [m/s²] | p99 abs(a) [m/s²] | RMS T [N·m] | p99 abs(T) [N·m] | mean F [N] | p99 F [N] |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    ideal = cl["ideal"]
    ist = ideal["statistics"] or {}
    out.append(f"| ideal | - | 0 | {_g(ideal['first_revolution']['rapier_acceleration_m_s2']['max'], 5)} | "
               f"{_g(max(abs(v) for v in ideal['first_revolution']['driving_torque_Nm'].values()), 5)} | "
               f"{_g(ist.get('rapier_acceleration_m_s2', {}).get('rms'), 4)} | "
               f"{_g(ist.get('rapier_acceleration_m_s2', {}).get('p99_abs'), 4)} | "
               f"{_g(ist.get('driving_torque_Nm', {}).get('rms'), 4)} | "
               f"{_g(ist.get('driving_torque_Nm', {}).get('p99_abs'), 4)} | 0 | 0 |")
    for r in cl["trend"]:
        out.append(f"| {r['clearance_mm']:g} | {_f(r['first_contact_crank_angle_deg'], '.3f')} | "
                   f"{_g(r['first_revolution_contact_force_max_N'], 5)} | "
                   f"{_g(r['first_revolution_acceleration_peak_m_s2'], 5)} | "
                   f"{_g(r['first_revolution_torque_peak_Nm'], 5)} | {_g(r['acceleration_rms_m_s2'])} | "
                   f"{_g(r['acceleration_p99_abs_m_s2'])} | {_g(r['torque_rms_Nm'])} | "
                   f"{_g(r['torque_p99_abs_Nm'])} | {_g(r['contact_force_mean_N'])} | {_g(r['contact_force_p99_N'])} |")
    out += ["", "Where the acceleration departs from the ideal one (RMS of a − a_ideal in 10° bins over revolutions "
            "2..N), against the ideal motion's features:", "",
            _figure("study-clearance-deviation.png", "acceleration deviation from the ideal per crank-angle bin"), ""]
    return out


def speed_section(sp: dict) -> list[str]:
    out = ["## Speed study (paper Fig. 13)", "",
           f"{', '.join(sp['amplitudes'])} rpm at c = {sp['clearance_mm']:g} mm, {sp['revolutions']} revolutions each, "
           "reference engine, with the ideal joint at the same speeds (dashed).", "",
           _figure("study-speed.png", "speed study: six channels over the last revolution"), "",
           _figure("study-speed-trend.png", "amplitudes against crank speed"), "",
           "| rpm | channel | ideal peak | rev. 1 peak | p99 abs | RMS | last-rev. peak |",
           "|---|---|---|---|---|---|---|"]
    for rpm, row in sp["amplitudes"].items():
        for kind, values in row.items():
            c = values["clearance"]
            out.append(f"| {rpm} | {kind} | {_g(values['ideal_peak'], 5)} | {_g(c['first_revolution_peak'], 5)} | "
                       f"{_g(c['p99_abs'], 5)} | {_g(c['rms'], 5)} | {_g(c['last_revolution_peak'], 5)} |")
    out += ["", "Amplitude ratios between speeds (ideal kinematics: (n₂/n₁)²):", "",
            "| speeds | channel | ideal | rev. 1 peak | p99 abs | RMS | last-rev. peak |",
            "|---|---|---|---|---|---|---|"]
    for pair, row in sp["ratios"].items():
        for kind in ("torque", "acceleration"):
            r = row[kind]
            out.append(f"| {pair} | {kind} | {_f(r['ideal_peak'], '.3f')} | {_f(r['first_revolution_peak'], '.3f')} | "
                       f"{_f(r['p99_abs'], '.3f')} | {_f(r['rms'], '.3f')} | {_f(r['last_revolution_peak'], '.3f')} |")
    if sp["spectrum"]:
        out += ["", "### Rapier acceleration spectrum", "",
                f"Convention: {sp['spectrum_convention']}. The window holds whole revolutions, so the crank "
                "harmonics fall on lines (spacing f_rev / revolutions) and need no window function; the per-step "
                "signal is averaged over uniform bins before the FFT, so the impacts do not alias "
                "(`weftsim.studies.spectrum`).", "",
                _figure("study-speed-spectrum.png", "rapier acceleration amplitude spectrum"), "",
                "| rpm | f_rev [Hz] | largest line [Hz] | its amplitude [m/s²] | ideal joint [m/s²] | "
                "largest in 0-10 Hz [m/s²] | mean-square share 0-10 Hz | share in first 5 harmonics | paper [m/s²] |",
                "|---|---|---|---|---|---|---|---|---|"]
        for rpm, row in sp["spectrum"].items():
            s, i = row["clearance"], row["ideal"]
            out.append(f"| {rpm} | {s['crank_frequency_hz']:.3g} | {s['max_amplitude_frequency_hz']:.4g} | "
                       f"{s['max_amplitude_m_s2']:.1f} | {i['max_amplitude_m_s2']:.1f} | "
                       f"{_f(s['band_0_10hz_max_amplitude_m_s2'], '.1f')} | {100 * s['power_fraction_0_10hz']:.1f}% | "
                       f"{100 * s['power_fraction_first_5_harmonics']:.1f}% | {_f(PAPER_SPECTRUM.get(rpm), 'g')} |")
    out.append("")
    return out


def engines_section(en: dict) -> list[str]:
    cmp = en["compare"]
    out = ["## Engine comparison (paper Fig. 16)", "",
           f"c = {en['clearance_mm']:g} mm at {en['speed_rpm']:g} rpm, {en['revolutions']} revolutions. The "
           "closed-form Lagrange solver (`reference`) plays the paper's model, the Exudyn multibody model "
           "(`exudyn`) its ADAMS prototype; the paper's 1.035 and 1.099 are model / prototype, i.e. "
           "reference / exudyn here. First revolution (where the engines must agree) and last revolution "
           "(an illustration):", "",
           _figure("study-engines.png", "both engines over the first revolution"), "",
           _figure("study-engines-last.png", "both engines over the last revolution"), "",
           "| channel | rev. 1 peak | p99 abs | RMS | last-rev. peak |", "|---|---|---|---|---|"]
    for channel, r in en["ratios_reference_over_exudyn"].items():
        out.append(f"| {channel} | {_f(r['first_revolution_peak'], '.4f')} | {_f(r['p99_abs'], '.4f')} | "
                   f"{_f(r['rms'], '.4f')} | {_f(r['last_revolution_peak'], '.4f')} |")
    out += ["", "Agreement checks of `weftsim compare` (the scene's `[compare]` tolerances):", "",
            "| check | exudyn | reference | difference | tolerance | passed |", "|---|---|---|---|---|---|"]
    for check in cmp["checks"]:
        out.append(f"| {check['name']} | {_g(check['exudyn'], 7)} | {_g(check['reference'], 7)} | "
                   f"{_g(check['difference'], 3)} | {check['tolerance']:g} | {'yes' if check['passed'] else 'NO'} |")
    for item in cmp.get("not_compared", []):
        out.append(f"Not compared: {item['what']} ({item['why']}).")
    verdicts = {"agree": "Engines agree", "disagree": "Engines DISAGREE", "failed": "Engines not compared (a run failed)",
                "partial": "Comparison partial (only the first-contact angle compared; no verdict on the peaks)"}
    out += ["", f"{verdicts.get(cmp.get('status'), 'Engines agree' if cmp['agree'] else 'Engines DISAGREE')}; wall time: "
            + ", ".join(f"{e} {m['wall_time_s']:.1f} s" for e, m in en["runs"].items()) + ".", ""]
    return out


def contact_law_section(law: dict) -> list[str]:
    rev = law["revolution"]
    out = ["## Contact law (paper Fig. 7-9)", "",
           f"Law `{law['law']}` (K(δ) of Bai-Zhao, ξ = {law['hysteresis']:.4g}, n = {law['exponent']:g}) at "
           f"c = {law['clearance_mm']:g} mm. (a) K(δ) from the contact-law library; (b) K(δ) at every solver step in "
           f"contact along revolution {law['plotted_revolution']} at {law['speed_rpm']:g} rpm (reference engine); "
           "(c) D = ξ K(δ) δ^n / v_imp at the same steps, coloured by the held impact velocity, with D(δ) of the "
           "law at two fixed impact velocities. The constant Lankarani-Nikravesh stiffness "
           f"({law['stiffness_lankarani_nikravesh']:.3g} N/m^1.5) is drawn for reference.", "",
           _figure("study-contact-law.png", "contact stiffness and damping"), ""]
    if rev:
        out += [f"Along revolution {law['plotted_revolution']}: in contact "
                f"{100 * rev['time_fraction_in_contact']:.1f}% of the time, K {rev['stiffness_min']:.3g} .. "
                f"{rev['stiffness_max']:.3g} N/m^1.5, δ up to "
                f"{rev['penetration_max_mm']:.3g} mm, impact velocity {rev['impact_velocity_min_m_s']:.3g} .. "
                f"{rev['impact_velocity_max_m_s']:.3g} m/s, D {rev['damping_min']:.3g} .. {rev['damping_max']:.3g} "
                "N·s/m.", ""]
    return out


def render(reports: dict, timings: dict, commands: dict, environment: dict) -> str:
    """The whole of docs/paper-comparison.md.

    Parameters
    ----------
    reports : dict
        Study name -> the study's JSON content.
    timings : dict
        Study name -> wall time of the study's last run, s (None when unknown).
    commands : dict
        Study name -> the command that produces it; ``"report"`` -> this report's command.
    environment : dict
        Versions (printed at the end).
    """
    out = ["# weftsim against the paper", "",
           f"Generated by `{commands['report']}` from the four studies below; every number here is printed by "
           "those commands (and stored in their JSON files). Do not edit by hand.", "",
           "Our mechanism is the reference mechanism of docs/physics.md section 1, not the paper's lost Table 1: its short sector "
           "arm (L_FG = 50 mm) and large reflected gear and rapier inertia put about 30 kN through joint E in "
           "normal running, so absolute peaks are much larger than the paper's. What can be compared are trends "
           "and ratios. After the first impacts the impact sequence depends on round-off and tolerances "
           "(docs/physics.md section 6), so the reproducible numbers are the first revolution's peaks (the start-up "
           "impact from the centred journal) and statistics over revolutions 2..N (RMS, 99th percentiles 'p99' "
           "of the magnitude); single-cycle peaks after the first revolution are illustrations.", "",
           "## Summary", ""]
    out += summary_rows(reports)
    out.append("")
    out += contact_law_section(reports["contact-law"])
    out += clearance_section(reports["clearance"])
    out += speed_section(reports["speed"])
    out += engines_section(reports["engines"])
    out += ["## Reproduce", "", "| study | command | wall time [s] |", "|---|---|---|"]
    for name in reports:
        t = timings.get(name)
        out.append(f"| {name} | `{commands[name]}` | {_f(t, '.0f') if t is not None else '(not timed)'} |")
    out += ["", "All four and this report: `python scripts/make_paper_comparison.py` (`--reuse` rebuilds the report "
            "from the studies' JSON without running them). Wall times are from a shared 2-core machine and vary "
            "with its load. Versions: "
            + ", ".join(f"{k} {v}" for k, v in environment.items() if v) + ".", ""]
    return "\n".join(out)
