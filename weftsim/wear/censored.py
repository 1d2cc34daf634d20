"""Predictions that never reach a clearance limit: censored hours (docs/wear.md section 9, "Lubricated").

A lubricated joint whose film separates the surfaces over the whole cycle wears nothing (Archard's
law is applied to the load the solids carry, never the film's), and a slowly wearing one may not reach
a limit within any horizon worth predicting.  Such a prediction is **censored**: its hours to the limit
are known only to exceed the horizon H ("> H h"), or, with a wear rate of exactly zero, to be infinite
("never").  Internally a censored sample's hours are ``inf``; what is written (``ensemble.json``,
``wear.json``) is ``null`` with a ``censored`` flag, never a non-finite number.

- :func:`no_wear_reason`: why an update wears nothing at all (or None);
- :func:`censored_quantile`: the p-quantile of hours among which some are ``inf``, with its
  order-statistic interval (a bound that falls among the censored is ``inf``);
- :func:`fraction_interval`: the fraction of samples reaching the limit, with a Clopper-Pearson interval.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from weftsim.input.params import Scene
    from weftsim.wear.extrapolate import Update


def no_wear_reason(scene: Scene, update: Update) -> str | None:
    """Why ``update`` (the last of a prediction) wears nothing at any wearing joint, as one clause; None when
    it wears."""
    parts = update.worn() if hasattr(update, "worn") else (update,)
    if any(float(np.max(p.rate_bearing, initial=0.0)) > 0.0 or float(np.max(p.rate_journal, initial=0.0)) > 0.0
           for p in parts):
        return None
    from weftsim.wear.extrapolate import effective_clearance

    joint_name = getattr(update, "joint", "e")
    ratios = [update.response.get(f"film_ratio_min_{p.joint}", math.nan) for p in parts if hasattr(p, "joint")]
    ratio = min((r for r in ratios if math.isfinite(r)), default=update.response.get("film_ratio_min", math.nan))
    joint = scene.joint_f if joint_name == "f" else scene.joint
    c0 = joint.clearance
    c = effective_clearance(c0, update.bearing, update.journal)
    ran_in = f" after running in from {1e3 * c0:.4g} to {1e3 * c:.4g} mm" if c > c0 else ""
    if math.isfinite(ratio):  # a film ratio is recorded: a lubricated joint
        return (f"the asperities carry no load{ran_in} (film ratio min {ratio:.3g}: the oil film separates the "
                "surfaces over the whole cycle)")
    return "the contact carries no load over the steady cycle"


def limit_note(scene: Scene, updates: list[Update], limit: float, reached: float | None) -> dict:
    """``wear.json``'s fields on a clearance limit: ``limit_censored``, ``never`` and, when censored, ``note``."""
    if reached is not None:
        return {"limit_censored": False, "never": None}
    never = no_wear_reason(scene, updates[-1])
    note = (f"does not reach {1e3 * limit:g} mm: {never}" if never else
            f"does not reach {1e3 * limit:g} mm within {updates[-1].hours:.6g} h (the hours asked for)")
    return {"limit_censored": True, "never": never, "note": note}


def censored_quantile(hours: np.ndarray, p: float, confidence: float = 0.9) -> tuple[float, float, float]:
    """(estimate, low, high) of the p-quantile of ``hours`` (``inf`` = censored), as
    :func:`weftsim.wear.uncertain.quantile_interval`; a value that falls among the censored is ``inf``.

    Sorting puts the censored last whatever their true hours, so every order statistic below them is
    exact: the estimate (the linear interpolation of numpy's default quantile between two order
    statistics) is ``inf`` as soon as the upper of the two is censored.
    """
    from scipy import stats

    x = np.sort(np.asarray(hours, dtype=float))
    n = x.size
    pos = p * (n - 1)
    lo_i, hi_i = math.floor(pos), math.ceil(pos)
    if math.isinf(x[hi_i]):
        est = math.inf
    else:
        est = float(x[lo_i] + (x[hi_i] - x[lo_i]) * (pos - lo_i))
    alpha = (1.0 - confidence) / 2.0
    lo = int(stats.binom.ppf(alpha, n, p))
    hi = int(stats.binom.ppf(1.0 - alpha, n, p)) + 1
    low = float(x[lo - 1]) if lo >= 1 else math.nan
    high = float(x[hi - 1]) if hi <= n else math.nan
    return est, low, high


def fraction_interval(reached: int, n: int, confidence: float = 0.9) -> tuple[float, float, float]:
    """(fraction, low, high): ``reached`` of ``n`` samples, with the Clopper-Pearson ``confidence`` interval
    (exact for independent samples; Latin-hypercube samples scatter less, so it is conservative)."""
    from scipy import stats

    alpha = (1.0 - confidence) / 2.0
    low = 0.0 if reached == 0 else float(stats.beta.ppf(alpha, reached, n - reached + 1))
    high = 1.0 if reached == n else float(stats.beta.ppf(1.0 - alpha, reached + 1, n - reached))
    return reached / n, low, high


def json_hours(value: float, horizon: float) -> dict:
    """One quantile's hours for JSON: ``{"hours": h or None, "censored": bool, "beyond_hours": H or None}``."""
    if math.isfinite(value):
        return {"hours": float(value), "censored": False, "beyond_hours": None}
    return {"hours": None, "censored": True, "beyond_hours": float(horizon)}


def interval_bounds(low: float, high: float, horizon: float) -> dict:
    """An interval's bounds for JSON: ``{"low", "high", "low_beyond_hours", "high_beyond_hours"}``.

    A bound from :func:`censored_quantile` is a number, ``inf`` (it falls among the censored samples: None,
    beyond ``horizon``) or NaN: the order statistic's rank lies outside 1..n, so the samples give no bound
    on that side (20 samples bound neither p10 from below nor p90 from above at 90 %): None, and no
    ``*_beyond_hours``, since it is not a censored value.
    """
    out: dict = {}
    for name, value in (("low", low), ("high", high)):
        out[name] = float(value) if math.isfinite(value) else None
        out[f"{name}_beyond_hours"] = float(horizon) if value == math.inf else None
    return out


def text_interval(q: dict, samples: int) -> str:
    """``"1.5 h - 2.8 h"`` of a quantile's interval (:func:`interval_bounds`): a censored bound as
    ``"> H h"``, a bound the samples cannot give as ``"0 h"`` below (hours are not negative) or
    ``"unbounded"`` above, saying so."""
    def bound(name: str) -> str:
        if q[name] is not None:
            return f"{q[name]:.4g} h"
        if q.get(f"{name}_beyond_hours") is not None:
            return f"> {q[f'{name}_beyond_hours']:.4g} h"
        return "0 h" if name == "low" else "unbounded"

    missing = [side for side, name in (("lower", "low"), ("upper", "high"))
               if q[name] is None and q.get(f"{name}_beyond_hours") is None]
    what = ("lower and upper bounds" if len(missing) == 2 else
            f"{'an' if missing[0] == 'upper' else 'a'} {missing[0]} bound" if missing else "")
    note = f": {samples} samples are too few for {what}" if what else ""
    return f"{bound('low')} - {bound('high')}{note}"


def text_hours(value: float, horizon: float, never: bool = False) -> str:
    """``"123.4 h"``, or ``"never"`` / ``"> H h"`` for a censored value."""
    if value is None or not math.isfinite(value):
        return "never" if never else f"> {horizon:.4g} h"
    return f"{value:.4g} h"
