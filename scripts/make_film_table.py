"""Build the finite-bearing table that weftsim.physics.film interpolates (weftsim/physics/film_table.npz).

Usage::

    python scripts/make_film_table.py [--check]

Solves Reynolds' equation with cavitation (:func:`weftsim.joint.reynolds.film`) on every node of the
grid of :mod:`weftsim.physics.film` (eccentricity ratio x squeeze-velocity angle x B/D) and stores
the scaled dimensionless force.  Deterministic: the same code gives the same table.  About
5000 solves, a few minutes on one core.  ``--check`` instead compares the kernel's interpolated
force with fresh solves half-way between the nodes and prints the largest relative errors.
Writing the table also writes its digest into film.py (``TABLE_DIGEST``): numba freezes the table
into the compiled functions and keys its cache by that source file, so the file must change.
"""

from __future__ import annotations

import argparse
import math
import re
import time
from pathlib import Path

import numpy as np

from weftsim.joint import reynolds
from weftsim.physics import film

TABLE = Path(film.__file__).with_name("film_table.npz")


def build() -> np.ndarray:
    eps_nodes = film.table_eccentricities()
    xi_nodes = film.table_angles()
    widths = film.table_widths()
    out = np.empty((widths.size, eps_nodes.size, xi_nodes.size, 2))
    start = time.perf_counter()
    for k, width in enumerate(widths):
        for i, eps in enumerate(eps_nodes):
            for j, xi in enumerate(xi_nodes):
                f = reynolds.film(float(eps), float(xi), float(width))
                out[k, i, j] = np.asarray(f) * film.table_scale(float(eps), float(width))
        print(f"B/D = {width:.3f} done, {time.perf_counter() - start:.0f} s", flush=True)
    return out


def check() -> None:
    """Kernel (interpolated) against fresh solves at points between the nodes."""
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(60):
        u = rng.uniform(0.0, film.U_MAX)
        eps = 1.0 - (1.0 - u) ** 2
        xi = rng.uniform(-math.pi, math.pi)
        width = math.exp(rng.uniform(math.log(film.WIDTH_MIN), math.log(film.WIDTH_MAX)))
        exact = np.asarray(reynolds.film(eps, xi, width))
        got = np.asarray(film.finite_force(eps, xi, width))
        err = float(np.hypot(*(got - exact)) / np.hypot(*exact))
        worst = max(worst, err)
        print(f"eps {eps:.4f} xi {math.degrees(xi):7.1f} B/D {width:.3f}: relative error {err:.2e}")
    print(f"largest {worst:.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare the kernel with fresh solves")
    args = parser.parse_args()
    if args.check:
        check()
        return
    table = build()
    np.savez_compressed(TABLE, force=table)
    source = Path(film.__file__)
    text = re.sub(r'^TABLE_DIGEST = ".*"$', f'TABLE_DIGEST = "{film.table_digest(table)}"', source.read_text(),
                  flags=re.MULTILINE)
    source.write_text(text)
    print(f"wrote {TABLE} {table.shape}")


if __name__ == "__main__":
    main()
