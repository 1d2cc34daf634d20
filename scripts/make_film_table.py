"""Build the finite-bearing table that weftsim.physics.film interpolates (weftsim/physics/film_table.npz).

Usage::

    python scripts/make_film_table.py [--check] [--jobs 2]

Solves Reynolds' equation with cavitation (:func:`weftsim.joint.reynolds.film`) on every node of the
grid of :mod:`weftsim.physics.film` (roughness axis s = exp(-0.56 h_min / sigma) x B/D x eccentricity ratio
x squeeze-velocity angle; s = 0 the smooth film, s > 0 Patir and Cheng's average-flow equation) and
stores the scaled dimensionless force.  Deterministic: the same code gives the same table.  About
64 000 nodes (one or two solves each, every sweep over the squeeze angle started from the previous angle's
film); the smooth slice s = 0 is taken from the stored table when that is the one of ``TABLE_DIGEST`` (the
same solver; ``--resolve-smooth`` solves it again), the four rough slices are solved (``--jobs`` processes
share them; ``--keep DIR`` saves each finished slice and resumes from them).  ``--check`` instead compares the
kernel's interpolated force with fresh solves at random points between the nodes and prints the
largest relative errors.  Writing the table also writes its digest into weftsim/physics/film.py (``TABLE_DIGEST``):
numba freezes the table into the compiled functions and keys its cache by that source file, so the
file must change.
"""

from __future__ import annotations

import argparse
import math
import re
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from weftsim.joint import reynolds
from weftsim.physics import film

TABLE = Path(film.__file__).with_name("film_table.npz")


def _slice(args: tuple[int, int]) -> tuple[int, int, np.ndarray]:
    """One (r, B/D) slice of the table: the scaled force on the eccentricity x angle nodes."""
    m, k = args
    r = float(film.table_roughness_axis()[m])
    width = float(film.table_widths()[k])
    out = np.empty((film.N_U, film.N_XI, 2))
    for i, eps in enumerate(film.table_eccentricities()):
        sigma = film.roughness_of(float(eps), r)
        fields: dict = {}  # each angle's solve starts from the previous angle's film
        for j, xi in enumerate(film.table_angles()):
            f = reynolds.film(float(eps), float(xi), width, roughness=sigma, fields=fields)
            out[i, j] = np.asarray(f) * film.table_scale(float(eps), width)
    return m, k, out


def stored_smooth() -> np.ndarray | None:
    """The smooth slice (B/D x eps x xi x 2) of the stored table if that table is the one of ``TABLE_DIGEST`` (the
    smooth table of before the roughness axis, or the rough one), else None."""
    if not TABLE.exists():
        return None
    with np.load(TABLE) as data:
        core = np.asarray(data["force"], dtype=np.float64)
    if film.table_digest(core) != film.TABLE_DIGEST:
        return None
    smooth = core if core.ndim == 4 else core[0]
    return smooth if smooth.shape == (film.N_WIDTH, film.N_U, film.N_XI, 2) else None


def build(jobs: int, keep: Path | None, resolve_smooth: bool = False) -> np.ndarray:
    """The table; with ``keep`` each finished slice is saved there and a saved one is not solved again (an
    interrupted build resumes).  The smooth slice comes from the stored table unless ``resolve_smooth``."""
    out = np.empty((film.N_R, film.N_WIDTH, film.N_U, film.N_XI, 2))
    start = time.perf_counter()
    smooth = None if resolve_smooth else stored_smooth()
    tasks = []
    for m in range(film.N_R):
        for k in range(film.N_WIDTH):
            saved = keep / f"slice_{m}_{k}.npy" if keep else None
            if m == 0 and smooth is not None:
                out[m, k] = smooth[k]
            elif saved is not None and saved.exists():
                out[m, k] = np.load(saved)
            else:
                tasks.append((m, k))
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for n, (m, k, block) in enumerate(pool.map(_slice, tasks), 1):
            out[m, k] = block
            if keep is not None:
                np.save(keep / f"slice_{m}_{k}.npy", block)
            print(f"s = {film.table_roughness_axis()[m]:.3f}, B/D = {film.table_widths()[k]:.3f} done "
                  f"({n}/{len(tasks)}), {time.perf_counter() - start:.0f} s", flush=True)
    return out


def check(points: int) -> None:
    """Kernel (interpolated) against fresh solves at random points between the nodes."""
    rng = np.random.default_rng(1)
    worst = {"smooth": 0.0, "rough": 0.0}
    for n in range(points):
        u = rng.uniform(0.0, film.U_MAX)
        eps = 1.0 - (1.0 - u) ** 2
        xi = rng.uniform(-math.pi, math.pi)
        width = math.exp(rng.uniform(math.log(film.WIDTH_MIN), math.log(film.WIDTH_MAX)))
        ratio = math.inf if n % 4 == 0 else math.exp(rng.uniform(math.log(film.RATIO_MIN), math.log(20.0)))
        sigma = (1.0 - eps) / ratio  # sigma / c
        r = math.exp(-film.ROUGH_DECAY * ratio)
        exact = np.asarray(reynolds.film(eps, xi, width, roughness=sigma))
        got = np.asarray(film.rough_finite_force(eps, xi, width, sigma))
        err = float(np.hypot(*(got - exact)) / np.hypot(*exact))
        kind = "smooth" if r == 0.0 else "rough"
        worst[kind] = max(worst[kind], err)
        print(f"eps {eps:.4f} xi {math.degrees(xi):7.1f} B/D {width:.3f} h_min/sigma "
              f"{ratio:7.3f}: relative error {err:.2e}")
    print(f"largest: smooth {worst['smooth']:.2e}, rough {worst['rough']:.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare the kernel with fresh solves")
    parser.add_argument("--points", type=int, default=80, help="points of --check")
    parser.add_argument("--jobs", type=int, default=1, help="processes sharing the solves")
    parser.add_argument("--keep", type=Path, help="directory of finished slices (resumes an interrupted build)")
    parser.add_argument("--resolve-smooth", action="store_true", help="solve the smooth slice again")
    args = parser.parse_args()
    if args.check:
        check(args.points)
        return
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    table = build(args.jobs, args.keep, args.resolve_smooth)
    np.savez_compressed(TABLE, force=table)
    source = Path(film.__file__)
    text = re.sub(r'^TABLE_DIGEST = ".*"$', f'TABLE_DIGEST = "{film.table_digest(table)}"', source.read_text(),
                  flags=re.MULTILINE)
    source.write_text(text)
    print(f"wrote {TABLE} {table.shape} in {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
