"""Uncertain inputs of a wear ensemble: ``KEY=DISTRIBUTION`` texts, sampling, quantiles and their confidence.

``--uncertain joint_e.wear.wear_coefficient=lognormal(1e-7,0.6)`` names a scene key and a distribution
in the key's file units (docs/wear.md section 9):

- ``normal(mean,sd)``, ``lognormal(median,sigma_of_log)``, ``uniform(low,high)``,
  ``triangular(low,mode,high)``;
- ``walther(nu40,nu100,t_low,t_high)`` for a viscosity key (mPa s): an oil of kinematic viscosity
  ``nu40`` and ``nu100`` (mm^2/s) at 40 and 100 C, at a temperature uniform between ``t_low`` and
  ``t_high`` (C), through Walther's relation of ASTM D341 (:func:`walther_viscosity`).

Samples are drawn by Latin hypercube (each input's probability axis cut into N equal strata, one draw
in each, the strata of different inputs paired at random): for the smooth, monotone responses of a
wear prediction the median converges much faster than with independent draws.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from weftsim.errors import WearError
from weftsim.physics.oil import DENSITY_15C, DENSITY_PER_K

# Each distribution and its parameters, in the key's file units: the one source of the parser, its
# messages and the command line's help (``weftsim wear --help``).
SIGNATURES = {"normal": ("mean", "sd"), "lognormal": ("median", "sigma_of_log"), "uniform": ("low", "high"),
              "triangular": ("low", "mode", "high"), "walther": ("nu40", "nu100", "t_low", "t_high")}
KINDS = {kind: len(names) for kind, names in SIGNATURES.items()}
ALLOWED = ", ".join(f"{kind}({','.join(names)})" for kind, names in SIGNATURES.items())
# Density of a mineral oil, g/cm^3 at 15 C, and its fall per kelvin (weftsim.physics.oil, in kg/m^3 there).
OIL_DENSITY_15C, OIL_DENSITY_PER_K = 1e-3 * DENSITY_15C, 1e-3 * DENSITY_PER_K

_TEXT = re.compile(r"^\s*([A-Za-z0-9_.]+)\s*=\s*([a-z]+)\s*\(([^()]*)\)\s*$")


@dataclass(frozen=True)
class Uncertain:
    """One uncertain scene key: ``key`` (dotted file key), ``kind`` and its ``args`` in the key's units."""

    key: str
    kind: str
    args: tuple[float, ...]

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Values at the probabilities ``u`` (0 < u < 1): the inverse of the distribution function."""
        from scipy import stats

        a = self.args
        if self.kind == "normal":
            return stats.norm.ppf(u, loc=a[0], scale=a[1])
        if self.kind == "lognormal":
            return a[0] * np.exp(a[1] * stats.norm.ppf(u))
        if self.kind == "uniform":
            return a[0] + (a[1] - a[0]) * np.asarray(u, dtype=float)
        if self.kind == "walther":  # hotter = thinner: the hot end at u = 0, so the values rise with u
            return walther_viscosity(a[0], a[1], a[3] - (a[3] - a[2]) * np.asarray(u, dtype=float))
        low, mode, high = a
        return stats.triang.ppf(u, (mode - low) / (high - low), loc=low, scale=high - low)

    @property
    def text(self) -> str:
        return f"{self.key}={self.kind}({','.join(f'{v:g}' for v in self.args)})"


def parse_uncertain(text: str) -> Uncertain:
    """``KEY=KIND(a,b[,c])`` -> :class:`Uncertain`; WearError (one line) for anything else."""
    allowed = ALLOWED
    m = _TEXT.match(text)
    if not m or m.group(2) not in KINDS:
        raise WearError(f"--uncertain {text!r}: give KEY=DISTRIBUTION with one of {allowed}")
    key, kind = m.group(1), m.group(2)
    try:
        args = tuple(float(v) for v in m.group(3).split(","))
    except ValueError:
        raise WearError(f"--uncertain {text!r}: the parameters of {kind} must be numbers") from None
    if len(args) != KINDS[kind] or not all(math.isfinite(v) for v in args):
        raise WearError(f"--uncertain {text!r}: {kind} takes {KINDS[kind]} finite numbers ({allowed})")
    if kind == "normal":
        problem = args[1] > 0.0 or "sd must be > 0"
    elif kind == "lognormal":
        problem = (args[0] > 0.0 or "median must be > 0") if args[1] > 0.0 else "sigma_of_log must be > 0"
    elif kind == "uniform":
        problem = args[0] < args[1] or "low must be < high"
    elif kind == "walther":
        problem = (args[0] > args[1] > 0.3 or "needs nu40 > nu100 > 0.3 mm^2/s (kinematic viscosities at 40 and "
                   "100 C; ASTM D341 holds above 0.3)") if key.endswith("viscosity_mpa_s") else \
            "walther(...) gives a viscosity in mPa s: use it for a *.lubrication.viscosity_mpa_s key"
        if problem is True and not (-20.0 <= args[2] < args[3] <= 150.0):
            problem = "needs -20 <= t_low < t_high <= 150 C (the range of a loom's oil)"
    else:
        problem = (args[0] <= args[1] <= args[2] and args[0] < args[2]) or "needs low <= mode <= high, low < high"
    if problem is not True:
        raise WearError(f"--uncertain {text!r}: {problem}")
    return Uncertain(key, kind, args)


def walther_viscosity(nu40: float, nu100: float, t_c: np.ndarray) -> np.ndarray:
    """Dynamic viscosity (mPa s) at ``t_c`` (C) of an oil with kinematic viscosities nu40, nu100 (mm^2/s).

    Walther's relation of ASTM D341 through the two points (:func:`weftsim.physics.oil.walther_kinematic`), times
    the density of a mineral oil (:func:`weftsim.physics.oil.density`, OIL_DENSITY_15C at 15 C).
    """
    from weftsim.physics.oil import density, walther_kinematic

    return walther_kinematic(nu40, nu100, t_c) * density(1e3 * OIL_DENSITY_15C, t_c) * 1e-3


def latin_hypercube(n: int, dims: int, rng: np.random.Generator) -> np.ndarray:
    """(n, dims) probabilities in (0, 1): one in each of n equal strata per column, columns paired at random."""
    u = (np.arange(n)[:, None] + rng.random((n, dims))) / n
    for j in range(dims):
        u[:, j] = u[rng.permutation(n), j]
    return np.clip(u, 1e-12, 1.0 - 1e-12)


def quantile_interval(values: np.ndarray, p: float, confidence: float = 0.9) -> tuple[float, float, float]:
    """(estimate, low, high): the p-quantile and a distribution-free ``confidence`` interval from order statistics.

    The number of samples below the true p-quantile is binomial(n, p), so the order statistics of
    ranks binom.ppf((1 -+ confidence) / 2) bracket it with at least that probability.  NaN bounds
    when n is too small to bracket it.
    """
    from scipy import stats

    x = np.sort(np.asarray(values, dtype=float))
    n = x.size
    est = float(np.quantile(x, p))
    alpha = (1.0 - confidence) / 2.0
    lo = int(stats.binom.ppf(alpha, n, p))  # rank (1-based) of the lower bound
    hi = int(stats.binom.ppf(1.0 - alpha, n, p)) + 1
    low = float(x[lo - 1]) if lo >= 1 else math.nan
    high = float(x[hi - 1]) if hi <= n else math.nan
    return est, low, high


def rank_shares(inputs: dict[str, np.ndarray], output: np.ndarray) -> dict[str, tuple[float, float]]:
    """Per input: (Spearman rank correlation with ``output``, its share rho^2 / sum rho^2 of the spread).

    An output without spread (every sample the same, e.g. all censored) has no shares to give: every input
    gets (0, 0), not a share of nothing (nor scipy's warning about a constant input).
    """
    from scipy import stats

    output = np.asarray(output, dtype=float)
    if output.size < 2 or np.all(output == output.flat[0]):
        return {name: (0.0, 0.0) for name in inputs}
    rho = {}
    for name, x in inputs.items():
        x = np.asarray(x, dtype=float)
        rho[name] = 0.0 if np.ptp(x) == 0.0 else float(stats.spearmanr(x, output)[0])
    total = sum(r * r for r in rho.values())
    return {name: (r, (r * r / total) if total > 0.0 else 0.0) for name, r in rho.items()}
