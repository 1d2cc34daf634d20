"""Sander et al.'s Stribeck test against ``weftsim bearing``: docs/img/stribeck_sander.png and the tables of
docs/lubricated-joint.md ("Stribeck data").

``PYTHONPATH=. python scripts/stribeck_sander.py``: the rig of tests/data/stribeck_sander2016.toml
(weftsim.studies.stribeck_rig) at its measured speeds and on a fine speed grid, at the default film floor
(sigma) and at the least (sigma / 4), and with the elastic film (the rig's [elastic] keys, weftsim.joint.ehl); the
checks of the causes of the disagreement (the asperity load the
published torque implies, the assumed clearance, an elastic estimate from the film's own pressure).  Rerun it
whenever the film or asperity kernel changes: it prints every number the docs quote.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from weftsim.studies.stribeck_rig import comparison, load_rig, rig_point, with_elastic, with_floor

ROOT = Path(__file__).resolve().parents[1]
RIG = ROOT / "tests" / "data" / "stribeck_sander2016.toml"
FLOORS = (1.0, 0.25)  # the default film floor and the least allowed (film_floor_ratio)
RELATIVE_CLEARANCES = (0.5e-3, 0.75e-3, 1e-3, 1.5e-3, 2e-3)  # around the source's assumed Psi = 1e-3
CURVE_RPM = np.geomspace(100.0, 4000.0, 41)
# The real parts' Hertz modulus for the elastic estimate: steel shaft 210 GPa, aluminium conrod 70 GPa, nu 0.3.
REAL_MODULUS = 1.0 / ((1.0 - 0.3**2) / 210e9 + (1.0 - 0.3**2) / 70e9)


def comparison_table(rig, rows: list[dict], floored: list[dict]) -> str:
    """Per point: published and weftsim's torque, their ratio, the big end's film and asperity load, and the
    asperity load that would close the gap as the big end's boundary friction mu_b F_a R_j."""
    big_end = rig.bearings[0].joint
    mu, radius = big_end.lubrication.boundary_friction_coefficient, big_end.journal_radius
    lines = ["| load | rpm | published | weftsim | ratio | (floor sigma/4) | big end h_min (film ratio) | "
             "asperity load | asperity load that would close the gap | supports' share | supports' film ratio |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, low in zip(rows, floored):
        for k, rpm in enumerate(case["rpm"]):
            big = case["points"][k]["bearings"]["big_end"]
            support = case["points"][k]["bearings"]["support"]
            share = sum(b.count * case["points"][k]["bearings"][b.name]["friction_torque_nm"]
                        for b in rig.bearings if b.name != "big_end") / case["weftsim_nm"][k]
            gap = case["torque_nm"][k] - case["weftsim_nm"][k]
            implied = f"{big['asperity_load_n'] + gap / (mu * radius):.0f} N" if gap > 0.0 else "-"
            lines.append(f"| {case['load_n'] / 1e3:g} kN | {rpm:g} | {case['torque_nm'][k]:.3f} | "
                         f"{case['weftsim_nm'][k]:.3f} | {case['ratio'][k]:.2f} | {low['ratio'][k]:.2f} | "
                         f"{1e6 * big['min_film_m']:.3f} um ({big['film_ratio']:.2f}) | "
                         f"{big['asperity_load_n']:.0f} N | {implied} | {100 * share:.0f} % | "
                         f"{support['film_ratio']:.2f} |")
        lines.append(f"| {case['load_n'] / 1e3:g} kN | least torque at | {case['minimum_rpm']:g} rpm | "
                     f"{case['weftsim_minimum_rpm']:g} rpm | | {low['weftsim_minimum_rpm']:g} rpm | | | | | |")
    return "\n".join(lines)


def elastic_table(rows: list[dict], isotropic: list[dict], elastic: list[dict]) -> str:
    """Per point: published torque, the rigid film's and the elastic film's of isotropic alike surfaces ratio to it,
    the elastic film's (the source's surfaces) torque and ratio, the big end's minimum film, asperity load, peak
    pressure and greatest opening of the gap, and its Newton iterations."""
    lines = ["| load | rpm | published | rigid film | elastic, isotropic | elastic film | ratio | big end h_min (film "
             "ratio) | asperity load | peak pressure | gap opened by | Newton iterations (big end, support) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, iso, el in zip(rows, isotropic, elastic):
        for k, rpm in enumerate(case["rpm"]):
            big, sup = (el["points"][k]["bearings"][name] for name in ("big_end", "support"))
            lines.append(f"| {case['load_n'] / 1e3:g} kN | {rpm:g} | {case['torque_nm'][k]:.3f} | "
                         f"{case['ratio'][k]:.2f} | {iso['ratio'][k]:.2f} | {el['weftsim_nm'][k]:.3f} | "
                         f"{el['ratio'][k]:.2f} | "
                         f"{1e6 * big['min_film_m']:.3f} um ({big['film_ratio']:.2f}) | {big['asperity_load_n']:.0f} N | "
                         f"{big['elastic']['peak_pressure_pa'] / 1e6:.0f} MPa | "
                         f"{1e6 * big['elastic']['max_opening_m']:.2f} um | "
                         f"{big['elastic']['iterations']}, {sup['elastic']['iterations']} |")
        lines.append(f"| {case['load_n'] / 1e3:g} kN | least torque at | {case['minimum_rpm']:g} rpm | "
                     f"{case['weftsim_minimum_rpm']:g} rpm | {iso['weftsim_minimum_rpm']:g} rpm | "
                     f"{el['weftsim_minimum_rpm']:g} rpm | | | | | | |")
    return "\n".join(lines)


def with_surfaces(rig, roughness, peklenik):
    """The rig with every bearing's ``surface_roughness`` and ``peklenik_numbers`` replaced (None: unset)."""
    bearings = []
    for b in rig.bearings:
        lub = replace(b.joint.lubrication, surface_roughness=roughness, peklenik_numbers=peklenik)
        bearings.append(replace(b, joint=replace(b.joint, lubrication=lub)))
    return replace(rig, bearings=tuple(bearings))


def surface_table(elastic) -> str:
    """The elastic film's ratio to the published torque at the mixed points with the surfaces' assumptions
    changed one at a time."""
    lub = elastic.bearings[0].joint.lubrication
    rq, gamma = lub.surface_roughness, lub.peklenik_numbers
    composite = math.hypot(*rq) / math.sqrt(2.0)
    variants = (("isotropic, alike, on roughness_um (before)", None, None),
                ("isotropic, alike, on the composite Rq", (composite, composite), None),
                ("the source's surfaces (journal = 1)", rq, gamma),
                ("surfaces swapped (journal = 2)", rq[::-1], gamma[::-1]),
                ("the source's Rq, both gamma 1 (shear flow only)", rq, (1.0, 1.0)),
                ("the source's gamma, alike Rq (no shear flow of unlike Rq)", (composite, composite), gamma),
                ("the bearing's gamma 6 instead of 12 (a sensitivity)", rq, (gamma[0], 6.0)))
    points = [(8000.0, rpm) for rpm in (500.0, 400.0, 300.0, 250.0, 200.0, 150.0)] + [(4000.0, 250.0), (4000.0, 150.0)]
    published = {(c["load_n"], n): m for c in elastic.loads for n, m in zip(c["rpm"], c["torque_nm"])}
    lines = ["| surfaces | " + " | ".join(f"{load / 1e3:g} kN {rpm:g}" for load, rpm in points) + " |",
             "|---|" + "---|" * len(points)]
    def row(name, rig):
        return f"| {name} | " + " | ".join(f"{rig_point(rig, load, rpm)['torque_nm'] / published[load, rpm]:.2f}"
                                         for load, rpm in points) + " |"

    for name, r, g in variants:
        lines.append(row(name, with_surfaces(elastic, r, g)))
    # The other rule for two gammas: one composite gamma = V_r1 gamma_1 + V_r2 gamma_2 (the correlation lengths
    # variance-weighted) in both pressure factors, the shear flow as before.
    from unittest import mock

    from weftsim.physics.flow_factors import SurfacePair, pressure_flow_factor_of

    def composite_gamma(self, ratio, across, slope=False):
        w1, w2 = self.variance_ratios
        g = w1 * self.peklenik[0] + w2 * self.peklenik[1]
        out = pressure_flow_factor_of(ratio, 1.0 / g if across else g, True)
        return out if slope else out[0]

    with mock.patch.object(SurfacePair, "pressure", composite_gamma):
        g = (rq[0] ** 2 * gamma[0] + rq[1] ** 2 * gamma[1]) / (rq[0] ** 2 + rq[1] ** 2)
        lines.append(row(f"one composite gamma {g:.1f} in phi_x, phi_z (the other rule for two gammas)",
                         with_surfaces(elastic, rq, gamma)))
    return "\n".join(lines)


def clearance_table(rig) -> str:
    lines = ["| Psi | " + " | ".join(f"{c['load_n'] / 1e3:g} kN" for c in rig.loads) + " |", "|---|---|---|"]
    for psi in RELATIVE_CLEARANCES:
        scaled = replace(rig, bearings=tuple(replace(b, joint=replace(b.joint, clearance=psi * b.joint.journal_radius))
                                             for b in rig.bearings))
        cells = [" ".join(f"{n:g}:{q:.2f}" for n, q in zip(c["rpm"], c["ratio"])) for c in comparison(scaled)]
        lines.append(f"| {psi:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def variant_table(rig) -> str:
    """weftsim / published torque with one surface input changed (each a check of a cause, not a fit)."""
    big = rig.bearings[0].joint.lubrication
    variants = (("as published", {}),
                ("no asperity contact", {"asperity_density_radius_roughness": 0.0}),
                (f"boundary mu 0.1 (5 x the source's {big.boundary_friction_coefficient:g})",
                 {"boundary_friction_coefficient": 0.1}),
                ("sigma = the surfaces' composite Rq, sqrt(0.20^2 + 0.34^2) = 0.394 um",
                 {"roughness": math.hypot(0.20e-6, 0.34e-6)}))
    lines = ["| inputs | " + " | ".join(f"{c['load_n'] / 1e3:g} kN (least torque at)" for c in rig.loads) + " |",
             "|---|---|---|"]
    for name, change in variants:
        changed = replace(rig, bearings=tuple(replace(b, joint=replace(b.joint, lubrication=replace(
            b.joint.lubrication, **change))) for b in rig.bearings))
        cells = [" ".join(f"{n:g}:{q:.2f}" for n, q in zip(c["rpm"], c["ratio"])) + f" ({c['weftsim_minimum_rpm']:g})"
                 for c in comparison(changed)]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summit_offset_check(rig, offset: float) -> str:
    """The source's summit mean heights read as an offset of the contact's gap: Greenwood and Tripp's pressure at
    h - offset, i.e. the asperity term of the kernel at clearance c - offset beside the film at c (the two terms of
    weftsim.physics.lubricated.lubricated_force called apart and summed; equal to the kernel's sum at offset 0),
    solved for the load as weftsim.joint.steady does.  A diagnostic, not weftsim's model."""
    from scipy.optimize import brentq

    from weftsim.joint.steady import joint_block
    from weftsim.physics.joint import ASPERITY_COEF, VISCOSITY
    from weftsim.physics.lubricated import L_FX, L_FY, L_MJ, lubricated_force

    def torque(joint, load, omega):
        prm = joint_block(joint)
        film, contact = prm.copy(), prm.copy()
        film[ASPERITY_COEF], contact[VISCOSITY] = 0.0, 0.0
        c = joint.clearance

        def force(ecc):
            a = lubricated_force(film, c, ecc, 0.0, 0.0, 0.0, omega, 0.0)
            b = lubricated_force(contact, c - offset, ecc, 0.0, 0.0, 0.0, omega, 0.0)
            return a[L_FX] + b[L_FX], a[L_FY] + b[L_FY], a[L_MJ] + b[L_MJ]

        top = (c - offset) * (1.0 - 1e-9)  # the summit planes touch at c - offset
        if math.hypot(*force(top)[:2]) < load:
            return math.nan
        ecc = brentq(lambda e: math.hypot(*force(e)[:2]) - load, 1e-9 * c, top, xtol=1e-13 * c)
        return -force(ecc)[2]

    cells = []
    for case in rig.loads:
        row = []
        for rpm, published in zip(case["rpm"], case["torque_nm"]):
            omega = rpm * math.pi / 30.0
            total = sum(b.count * torque(b.joint, b.load_share * case["load_n"], omega) for b in rig.bearings)
            row.append(f"{rpm:g}:{total / published:.2f}" if math.isfinite(total) else f"{rpm:g}:no balance")
        cells.append(" ".join(row))
    return f"| summit offset {1e6 * offset:g} um | " + " | ".join(cells) + " |"


def elastic_estimate(rig, load: float, rpm: float) -> str:
    """The surfaces' elastic deflection under the rigid film's own pressure: the axially averaged pressure of the
    Reynolds solve at the big end's operating eccentricity (rough film, the kernel's), on a plane-strain
    half-space pair of the real parts' modulus, u(x) = -(2 / (pi E*)) integral p(s) ln abs(x - s) ds (Johnson,
    Contact Mechanics, 1985, eq. 2.25b); the deflection at the pressure peak less that where the pressure has
    fallen to a tenth of it."""
    from weftsim.joint.reynolds import operator, solve

    big = rig.bearings[0].joint
    radius, c, length = big.journal_radius, big.clearance, big.bearing_length
    point = rig_point(rig, load, rpm)["bearings"]["big_end"]
    eps, omega = point["eccentricity_ratio"], rpm * math.pi / 30.0
    sigma = big.lubrication.roughness
    f_along, f_ahead, field = solve(eps, 0.5 * math.pi, length / (2.0 * radius), roughness=sigma / c)
    _, nodes, volume = operator(eps, length / (2.0 * radius), field.shape[0], field.shape[1], sigma / c)
    speed = 0.5 * omega * eps * c  # the squeeze velocity of pure rotation, abs(V) = omega_m abs(e)
    scale = big.lubrication.viscosity * (radius / c) ** 2 * speed / c
    force = scale * radius**2 * math.hypot(f_along, f_ahead)
    dzeta = volume[0] / volume[0].sum()
    pressure = scale * field @ dzeta  # the axial mean at each angle
    order = np.argsort(nodes)
    x, p = radius * nodes[order], pressure[order]
    cells = np.linspace(x[0], x[-1], 4001)
    mids = 0.5 * (cells[1:] + cells[:-1])
    pc = np.interp(mids, x, p)

    def antiderivative(t):
        return np.where(t == 0.0, 0.0, t * np.log(np.abs(t) + 1e-300) - t)

    grid = np.linspace(x[0], x[-1], 2001)
    u = np.array([-(2.0 / (math.pi * REAL_MODULUS)) * np.sum(pc * (antiderivative(g - cells[:-1])
                                                                   - antiderivative(g - cells[1:]))) for g in grid])
    pg = np.interp(grid, x, p)
    zone = pg > 0.1 * pg.max()
    deflection = u[np.argmax(pg)] - u[zone].min()
    return (f"| {load / 1e3:g} kN | {rpm:g} | {eps:.4f} | {force:.0f} N | {1e6 * point['min_film_m']:.3f} um | "
            f"{pg.max() / 1e6:.0f} MPa | {math.degrees(np.ptp(grid[zone]) / radius):.0f} deg | "
            f"{1e6 * deflection:.2f} um ({deflection / point['min_film_m']:.1f} h_min) |")


def figure(rig, floored, elastic, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(rig.loads), figsize=(11, 4.2), sharey=False)
    for ax, case in zip(axes, rig.loads):
        ax.plot(case["rpm"], case["torque_nm"], "ko-", label="published (Sander et al. 2016)")
        for r, style, name in ((rig, "C0-", "weftsim, rigid film, floor sigma"),
                               (floored, "C1--", "weftsim, rigid film, floor sigma/4"),
                               (elastic, "C2-", "weftsim, elastic film")):
            start = time.perf_counter()
            curve = [rig_point(r, case["load_n"], n)["torque_nm"] for n in CURVE_RPM]
            spent = (time.perf_counter() - start) / (CURVE_RPM.size * len(r.bearings))
            print(f"{name}, {case['load_n'] / 1e3:g} kN: least torque {min(curve):.3f} N m at "
                  f"{CURVE_RPM[int(np.argmin(curve))]:.0f} rpm (grid of {CURVE_RPM.size} speeds; "
                  f"{1e3 * spent:.1f} ms a bearing's point)")
            ax.plot(CURVE_RPM, curve, style, label=name)
        ax.axvline(case["minimum_rpm"], color="0.6", lw=0.8, ls=":")
        ax.set_xscale("log")
        ax.set_xlabel("shaft speed, rpm")
        ax.set_ylabel("shaft input torque, N m (big end + 2 supports)")
        ax.set_title(f"F = {case['load_n'] / 1e3:g} kN on the big end")
        ax.set_ylim(0.0, 1.1 * max(max(case["torque_nm"]), 1.0))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Stribeck test of Sander et al. (Tribol. Int. 96, 2016) against weftsim bearing")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main():
    rig = load_rig(RIG)
    floored = with_floor(rig, FLOORS[1])
    rows, low = comparison(rig), comparison(floored)
    print(comparison_table(rig, rows, low))
    print()
    print("weftsim / published torque, by relative clearance Psi (source's assumption 1e-3):")
    print(clearance_table(rig))
    print()
    print("weftsim / published torque with one input changed:")
    print(variant_table(rig))
    print(summit_offset_check(rig, 0.0))
    print(summit_offset_check(rig, (0.21 + 0.39) * 1e-6))
    floor_gap = max(abs(p["torque_nm"] - q["torque_nm"]) / p["torque_nm"] for a, b in zip(rows, low)
                    for p, q in zip(a["points"], b["points"]) if p["bearings"]["big_end"]["film_ratio"] >= 1.0)
    print(f"largest relative torque change, floor sigma -> sigma/4, where h_min >= sigma: {floor_gap:.1e}")
    print()
    print("| load | rpm | eps | film force (solve) | h_min | peak p (axial mean) | arc above p_max / 10 | "
          "elastic flattening |")
    print("|---|---|---|---|---|---|---|---|")
    for load, rpm in ((8000.0, 3000.0), (8000.0, 500.0), (8000.0, 300.0), (4000.0, 300.0)):
        print(elastic_estimate(rig, load, rpm))
    elastic = with_elastic(rig)
    print()
    print("the elastic film (the rig's [elastic] keys):")
    print(elastic_table(rows, comparison(with_surfaces(elastic, None, None)), comparison(elastic)))
    print()
    print("the elastic film / published torque, the surfaces' assumptions changed one at a time:")
    print(surface_table(elastic))
    out = ROOT / "docs" / "img" / "stribeck_sander.png"
    figure(rig, floored, elastic, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
