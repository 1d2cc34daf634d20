"""The cylindrical contact law against a plane-strain finite-element model of the pin in its bushing.

    python scripts/cylinder_fe_check.py [--quick] [--fit] [--out docs/data/cylinder_fe.json]

1. Mesh convergence: the approach at 1, 10 and 50 kN (per 30 mm) on four meshes halving h0, the
   change between the two finest (must be < 1 %) and a fit delta(h) = delta_inf + C h^p.
2. The Hertz limit: contact half-width and peak pressure of the FE model (mesh at b/60) against Hertz's
   line contact (Johnson 1985, eq. 4.43-4.45) at 1 kN as the clearance grows against the contact width.
3. (--fit) The FE grid c = 0.02, 0.05, 0.1, 0.25 mm x t = 2.5, 4, 6 mm x 1-50 kN and the least-squares
   fit of the cylindrical law's constants (weftsim.joint.contact.CYLINDRICAL_FIT).
4. The check: the loom's joint (R = 15 mm, L = 30 mm, steel in aluminium bronze, the wall of
   models/loom.toml) at c = 0.02, 0.1 and 0.25 mm, 1-50 kN: the approach of the FE model and of every
   law at the same load, and the figure docs/img/cylinder_fe.png (law against FE).

Needs the ``fe`` extra (scikit-fem).  Prints the tables as Markdown; writes the numbers as JSON.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from weftsim.joint.contact import LAWS, make_law
from weftsim.studies.cylinder_fe import Mesh, PinBushing, PinBushingFE, hertz_line_contact

ROOT = Path(__file__).resolve().parents[1]
LOADS_KN = (1.0, 2.0, 5.0, 10.0, 20.0, 35.0, 50.0)
CHECK_CLEARANCES_MM = (0.02, 0.1, 0.25)
FIT_CLEARANCES_MM = (0.02, 0.05, 0.1, 0.25)
FIT_WALLS_MM = (2.5, 4.0, 6.0)
H0_MM = (0.1, 0.05, 0.025, 0.0125)
CHECK_H0_MM = 0.025  # the check's mesh: within 0.1 % of the finest in the convergence study


def loom_joint():
    from weftsim.input.scene import load_scene

    return load_scene("loom").joint


def fe_for(joint, clearance: float, h0: float) -> PinBushingFE:
    """The FE model of ``joint`` at ``clearance`` (m) on a mesh of h0 (m); the fine arc covers 50 kN."""
    fine = 50.0 if clearance < 0.04e-3 else 30.0
    model = PinBushing.from_joint(replace(joint, clearance=clearance), joint.bushing_wall)
    return PinBushingFE(model, Mesh(h0=h0, fine_deg=fine, candidate_deg=fine + 20.0))


def convergence(joint) -> list[dict]:
    rows = []
    for c_mm in (0.02, 0.25):
        approaches = []
        for h0 in H0_MM:
            fe = fe_for(joint, c_mm * 1e-3, h0 * 1e-3)
            approaches.append([fe.solve(f * 1e3 / joint.bearing_length).approach for f in (1.0, 10.0, 50.0)])
            print(f"  convergence c = {c_mm} mm, h0 = {h0} mm: {fe.nodes} nodes", flush=True)
        a = np.array(approaches)
        for j, f in enumerate((1.0, 10.0, 50.0)):
            d = a[:, j]
            p = math.log(abs(d[-3] - d[-2]) / abs(d[-2] - d[-1])) / math.log(2.0) if d[-2] != d[-1] else float("inf")
            limit = d[-1] + (d[-1] - d[-2]) / (2.0**p - 1.0)
            rows.append({"clearance_mm": c_mm, "load_kN": f, "approach_um": list(d * 1e6),
                         "finest_change": float(abs(d[-1] / d[-2] - 1.0)), "order": p,
                         "extrapolated_um": limit * 1e6})
    return rows


def hertz_limit(joint) -> list[dict]:
    rows = []
    for c_mm in (0.25, 1.0, 3.0, 6.0):
        model = PinBushing.from_joint(replace(joint, clearance=c_mm * 1e-3), joint.bushing_wall)
        load = 1e3 / joint.bearing_length
        b, p0 = hertz_line_contact(model, load)
        fine = math.degrees(3.0 * b / model.radius)
        fe = PinBushingFE(model, Mesh(h0=b / 60.0, fine_deg=fine, candidate_deg=fine + 20.0))
        s = fe.solve(load)
        # the FE contact's half-width and peak from a least-squares semi-ellipse through the nodal pressures
        x = (model.radius + model.clearance) * np.sin(s.angles)
        inside = s.pressure > 0.0
        grid = np.linspace(0.8, 1.2, 801) * b
        errs = [np.sum((s.pressure[inside] - _ellipse_fit(x[inside], s.pressure[inside], bb)[1]) ** 2) for bb in grid]
        b_fe = float(grid[int(np.argmin(errs))])
        p_fe = _ellipse_fit(x[inside], s.pressure[inside], b_fe)[0]
        rows.append({"clearance_mm": c_mm, "b_over_R": b / model.radius, "b_hertz_mm": b * 1e3,
                     "b_fe_mm": b_fe * 1e3, "p0_hertz_MPa": p0 / 1e6, "p0_fe_MPa": p_fe / 1e6,
                     "b_error": b_fe / b - 1.0, "p0_error": p_fe / p0 - 1.0})
    return rows


def _ellipse_fit(x, p, b):
    shape = np.sqrt(np.clip(1.0 - (x / b) ** 2, 0.0, None))
    p0 = float(shape @ p / (shape @ shape))
    return p0, p0 * shape


def fe_grid(joint, clearances_mm, walls_mm, h0: float) -> list[dict]:
    rows = []
    for t_mm in walls_mm:
        for c_mm in clearances_mm:
            j = replace(joint, bushing_wall=t_mm * 1e-3)
            fe = fe_for(j, c_mm * 1e-3, h0)
            for f in LOADS_KN:
                s = fe.solve(f * 1e3 / joint.bearing_length)
                rows.append({"wall_mm": t_mm, "clearance_mm": c_mm, "load_kN": f, "approach_um": s.approach * 1e6,
                             "contact_half_angle_deg": math.degrees(s.contact_half_angle),
                             "peak_pressure_MPa": s.peak_pressure / 1e6})
            print(f"  FE t = {t_mm} mm, c = {c_mm} mm: {fe.nodes} nodes", flush=True)
    return rows


def fit_constants(rows, radius: float) -> tuple:
    """Least squares in ln F of ln(F / (L E* R)) = K(rho, tau) + n(rho, tau) ln(delta / R), K and n linear
    in ln rho and ln tau (per unit E* L: F here is the load over L E*)."""
    j = loom_joint()
    scale = j.bearing_length * j.effective_modulus * radius
    lr = np.log(np.array([r["clearance_mm"] for r in rows]) * 1e-3 / radius)
    lt = np.log(np.array([r["wall_mm"] for r in rows]) * 1e-3 / radius)
    ld = np.log(np.array([r["approach_um"] for r in rows]) * 1e-6 / radius)
    lf = np.log(np.array([r["load_kN"] for r in rows]) * 1e3 / scale)
    A = np.column_stack([np.ones_like(lr), lr, lt, ld, ld * lr, ld * lt])
    coef, *_ = np.linalg.lstsq(A, lf, rcond=None)
    return tuple(float(x) for x in coef)


def law_approach(law, force: float) -> float:
    from scipy.optimize import brentq

    return brentq(lambda d: float(law.elastic_force(d)) - force, 1e-13, 1e-3, xtol=1e-16, rtol=1e-12)


def pereira_force(joint, delta: float) -> float:
    """Pereira, Ramalho & Ambrosio's internal cylinder contact (Nonlinear Dyn. 63, 2011), N, as restated in
    Skrinjar's public multibody code (the review Skrinjar, Slavic & Boltezar, Int. J. Mech. Sci. 145, 2018):
    F = (a dR + b) L E* delta^n / dR, a = 0.965, b = 0.0965, n = Y dR^-0.005, Y = 1.51 ln(1000 dR)^-0.151
    for 0.005 <= dR <= 0.3495 mm, else 0.0151 dR + 1.151, with dR = c, L, delta in mm and E* in MPa
    (a dimensional fit; the original paper was not at hand to check the constants)."""
    dr = joint.clearance * 1e3
    y = 1.51 * math.log(1000.0 * dr) ** -0.151 if dr <= 0.34954 else 0.0151 * dr + 1.151
    n = y * dr**-0.005
    return (0.965 * dr + 0.0965) * joint.bearing_length * 1e3 * joint.effective_modulus / 1e6 / dr * (delta * 1e3) ** n


def check(joint, rows) -> list[dict]:
    from scipy.optimize import brentq

    out = []
    for r in rows:
        j = replace(joint, clearance=r["clearance_mm"] * 1e-3)
        entry = dict(r)
        entry["pereira_2011_um"] = brentq(lambda d: pereira_force(j, d) - r["load_kN"] * 1e3, 1e-13, 1e-3,
                                          xtol=1e-16) * 1e6
        for name in LAWS:
            if name in ("flores", "hunt_crossley", "gonthier"):
                continue  # the elastic force of lankarani_nikravesh
            law = make_law(replace(j, law=name))
            entry[name + "_um"] = law_approach(law, r["load_kN"] * 1e3) * 1e6
        out.append(entry)
    return out


def figure(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 4), sharey=True)
    for ax, c_mm in zip(axes, CHECK_CLEARANCES_MM):
        sub = [r for r in rows if r["clearance_mm"] == c_mm]
        force = [r["load_kN"] for r in sub]
        ax.plot([r["approach_um"] for r in sub], force, "ko", label="FE (plane strain)")
        for name, style in (("cylindrical", "C3-"), ("pereira_2011", "C4-"), ("elastic_foundation", "C0--"),
                            ("lankarani_nikravesh", "C1-."), ("variable_kd", "C2:")):
            ax.plot([r[name + "_um"] for r in sub], force, style, label=name)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"c = {c_mm} mm")
        ax.set_xlabel("approach delta (um)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("load per 30 mm (kN)")
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Pin of 30 mm in an aluminium-bronze bushing, wall {rows[0]['wall_mm']:g} mm: laws against FE")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def markdown(conv, hertz, rows) -> str:
    lines = ["| c mm | load kN | h0 = 0.1 | 0.05 | 0.025 | 0.0125 mm | change between finest | order p | extrapolated |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in conv:
        a = r["approach_um"]
        lines.append(f"| {r['clearance_mm']} | {r['load_kN']:g} | " + " | ".join(f"{x:.4f}" for x in a)
                     + f" | {100 * r['finest_change']:.3f} % | {r['order']:.2f} | {r['extrapolated_um']:.4f} |")
    lines += ["", "| c mm | b/R | b Hertz mm | b FE mm | p0 Hertz MPa | p0 FE MPa | b error | p0 error |",
              "|---|---|---|---|---|---|---|---|"]
    for r in hertz:
        lines.append(f"| {r['clearance_mm']} | {r['b_over_R']:.4f} | {r['b_hertz_mm']:.3f} | {r['b_fe_mm']:.3f} | "
                     f"{r['p0_hertz_MPa']:.1f} | {r['p0_fe_MPa']:.1f} | {100 * r['b_error']:+.1f} % | "
                     f"{100 * r['p0_error']:+.1f} % |")
    lines += ["", "| c mm | load kN | FE um | cylindrical | Pereira 2011 | elastic_foundation | lankarani_nikravesh "
              "| variable_kd |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        fe = r["approach_um"]
        cells = [f"{r[n + '_um']:.2f} ({100 * (r[n + '_um'] / fe - 1):+.0f} %)" if n != "cylindrical"
                 else f"{r[n + '_um']:.3f} ({100 * (r[n + '_um'] / fe - 1):+.1f} %)"
                 for n in ("cylindrical", "pereira_2011", "elastic_foundation", "lankarani_nikravesh", "variable_kd")]
        lines.append(f"| {r['clearance_mm']} | {r['load_kN']:g} | {fe:.3f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fit", action="store_true", help="run the FE grid and print the law's constants")
    ap.add_argument("--quick", action="store_true",
                    help="keep the convergence study and the Hertz limit of the earlier run's JSON")
    ap.add_argument("--out", default=str(ROOT / "docs" / "data" / "cylinder_fe.json"))
    args = ap.parse_args(argv)
    joint = loom_joint()
    start = time.process_time()
    result = {"wall_mm": joint.bushing_wall * 1e3, "check_h0_mm": CHECK_H0_MM}
    previous = json.loads(Path(args.out).read_text()) if Path(args.out).exists() else {}
    if not args.fit:  # keep the fit of an earlier --fit run
        result.update({k: previous[k] for k in ("fit_grid", "fit") if k in previous})
    if args.fit:
        grid = fe_grid(joint, FIT_CLEARANCES_MM, FIT_WALLS_MM, CHECK_H0_MM * 1e-3)
        result["fit_grid"] = grid
        result["fit"] = fit_constants(grid, joint.journal_radius)
        print("CYLINDRICAL_FIT =", result["fit"])
    # --quick keeps the convergence study and the Hertz limit of an earlier full run
    conv = previous.get("convergence", []) if args.quick else convergence(joint)
    hertz = previous.get("hertz", []) if args.quick else hertz_limit(joint)
    rows = check(joint, fe_grid(joint, CHECK_CLEARANCES_MM, (joint.bushing_wall * 1e3,), CHECK_H0_MM * 1e-3))
    worst = max(abs(r["cylindrical_um"] / r["approach_um"] - 1.0) for r in rows)
    result.update(convergence=conv, hertz=hertz, check=rows, worst_cylindrical_error=worst,
                  cpu_s=time.process_time() - start)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=1))
    figure(rows, ROOT / "docs" / "img" / "cylinder_fe.png")
    print(markdown(conv, hertz, rows))
    print(f"\nworst |cylindrical / FE - 1| = {100 * worst:.1f} %; CPU {result['cpu_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
