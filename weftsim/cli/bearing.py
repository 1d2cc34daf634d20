"""The ``weftsim bearing`` subcommand: flags, the report and its files (the CLI module only wires it in)."""

from __future__ import annotations

import json
import math
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import argparse

    from weftsim.input.params import Scene


def add_flags(p: argparse.ArgumentParser) -> None:
    """``weftsim bearing SCENE [--joint e|f] [--json] [--load-kn F --journal-rpm N]`` beside the scene flags."""
    p.add_argument("--joint", choices=("e", "f"), default="e", help="the joint to check (default e)")
    p.add_argument("--json", action="store_true", help="print the report as JSON on stdout")
    p.add_argument("--load-kn", type=float, default=None,
                   help="another operating point: the bearing alone under this steady load, kN (default: the "
                        "ideal mechanism's mean; with neither flag, its mean and peak)")
    p.add_argument("--journal-rpm", type=float, default=None,
                   help="the journal speed of that point, rpm, bushing still (default: the mean sliding speed)")
    p.add_argument("--no-plot", action="store_true", help="skip the Stribeck figure")


def point_line(name: str, p: dict) -> str:
    """One operating point in one line."""
    rpm = p["journal_speed_rad_s"] * 60.0 / (2.0 * math.pi)
    temperature = "" if p["film_temperature_c"] is None else f", film {p['film_temperature_c']:.4g} C"
    return (f"{name}: W = {p['load_n'] / 1e3:.4g} kN at {rpm:.4g} rpm: S = {p['sommerfeld']:.4g}, "
            f"eps = {p['eccentricity_ratio']:.4g}, attitude {p['attitude_angle_deg']:.4g} deg, "
            f"h_min = {1e6 * p['min_film_m']:.4g} um (film ratio {p['film_ratio']:.4g}), "
            f"f = {p['friction_coefficient']:.4g}, power loss {p['power_loss_w']:.4g} W{temperature} "
            f"({1e3 * p['viscosity_pa_s']:.4g} mPa s), {p['regime']}")


def run(args: argparse.Namespace, scene: Scene, outdir) -> int:
    """Compute the check, write ``bearing.json`` and ``stribeck.png``, print the report (or its JSON)."""
    from weftsim.api import bearing
    from weftsim.post.output import prepare_directory, to_json, write_figure, write_json

    report = bearing(scene, args.joint, args.load_kn, args.journal_rpm)
    outdir = prepare_directory(outdir, args.force, scene)
    write_json(outdir / "bearing.json", report)
    if not args.no_plot:
        from weftsim.post.stribeck_plot import plot_stribeck

        write_figure(outdir / "stribeck.png", plot_stribeck(report))
    if args.json:
        print(to_json(report))
        return 0
    oil = (f"{report['oil']} at {report['ambient_temperature_c']:g} C ambient" if report["oil"] else
           f"{report['viscosity_mpa_s']:.4g} mPa s (isoviscous)")
    print(f"{report['scene']}, joint {report['joint']}: {report['journal_diameter_mm']:g} x "
          f"{report['bearing_length_mm']:g} mm pin, c = {report['clearance_mm']:g} mm, sigma = "
          f"{report['roughness_um']:g} um, {oil}")
    for name, point in report["points"].items():
        print("  " + point_line(name, point))
    for note in report.get("notes", []):
        print("  note: " + note)
    curve = report.get("stribeck")
    if curve:
        k = min(range(len(curve["friction_coefficient"])), key=curve["friction_coefficient"].__getitem__)
        print(f"  Stribeck curve at {curve['load_n'] / 1e3:.4g} kN: least friction f = "
              f"{curve['friction_coefficient'][k]:.4g} at {curve['journal_speed_rad_s'][k] * 30.0 / math.pi:.4g} rpm "
              f"({curve['regime'][k]}); files in {outdir}")
    sys.stdout.flush()
    return 0


