"""The plain bearing's heat balance: the effective film temperature, iterated with the oil's viscosity.

In steady running the friction power of the joint (:class:`weftsim.joint.steady.SteadyPoint`: film shear and
boundary friction, P_f = T omega) leaves as heat, carried off by the oil flowing through the film and
conducted through the housing to the air (ISO 7902-1 / DIN 31652-1: P_f = P_th,L + P_th,amb)::

    P_f(eta(T_eff)) = rho c_p (Q - Qs / 2) dT  +  k A (T_eff - T_amb),     T_eff = T_amb + dT / 2

- **Oil flow** (``oil_supply = "fed"``): oil at the ambient temperature floods the film at its line of
  thickest film, the inlet flow Q (:mod:`weftsim.joint.film_flow`) warms by dT through the film, the side
  flow Qs leaves from the pressurised film at the mean temperature T_amb + dT / 2 and the rest at T_amb + dT:
  the heat it carries is rho c_p (Q - Qs/2) dT and T_eff is the mean of inlet and outlet (Raimondi and Boyd,
  ASLE Trans. 1, 1958, as Shigley's Mechanical Engineering Design, ch. 12, writes their temperature rise).
  ``"sump"``: a self-contained bearing, whose oil returns its heat to the housing (no flow term).
- **Housing**: k A (T_eff - T_amb), the convection term of ISO 7902-1 / DIN 31652 with the bearing at the
  effective temperature; k A is the scene's ``housing_heat_transfer_w_k`` or :func:`housing_estimate`.

eta(T) is the oil's (:mod:`weftsim.physics.oil`), P_f, Q and Qs follow from the steady bearing at eta, so the
balance is one equation in T_eff: g(T) = P_f - heat out.  g(T_amb) = P_f > 0 and the oil thins as T rises; the
first root above T_amb is the temperature a bearing warming from ambient settles at.  It is bracketed by steps
from T_amb of 0.5 K, doubled each time (:data:`STEP_K`), up to the oil's limit (nu = 2 mm^2/s, or 200 C), and
found by Brent's method to :data:`TEMPERATURE_TOL`; power in equals heat out there to ~1e-14 relative
(tests/test_bearing.py checks 1e-6).
No root below the limit: the bearing overheats (a :class:`weftsim.errors.SceneError` saying so).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from weftsim.errors import SceneError
from weftsim.joint.steady import SteadyPoint, joint_block, steady_point

# Still air on a machine part: ISO 7902-1 and DIN 31652-2 take k = 15-20 W/(m^2 K); the upper value here.
HOUSING_K = 20.0
STEP_K = 0.5  # K: the first bracket above ambient, doubled until g changes sign
TEMPERATURE_TOL = 1e-9  # K, Brent's xtol on T_eff


def housing_estimate(joint) -> float:
    """k A (W/K) of a bushed pin's eye: k = 20 W/(m^2 K) over an eye of outer diameter 2 D and length B,
    A = 2 pi D B + 1.5 pi D^2 (its mantle and two annular faces), D = 2 R_j, B = L_b.  An estimate: the heat the
    pin and the arms conduct away comes on top (set ``housing_heat_transfer_w_k`` when it is known)."""
    d, b = 2.0 * joint.journal_radius, joint.bearing_length
    return HOUSING_K * (2.0 * math.pi * d * b + 1.5 * math.pi * d * d)


@dataclass(frozen=True)
class HeatBalance:
    """The converged heat balance of one operating point (SI, temperatures in C)."""

    temperature_c: float
    ambient_c: float
    viscosity_pa_s: float
    friction_power_w: float
    oil_heat_w: float
    housing_heat_w: float
    housing_heat_transfer_w_k: float
    oil_supply: str
    point: SteadyPoint

    @property
    def residual(self) -> float:
        """(power in - heat out) / power in (0 when no power is dissipated)."""
        out = self.oil_heat_w + self.housing_heat_w
        return (self.friction_power_w - out) / self.friction_power_w if self.friction_power_w > 0.0 else 0.0

    def as_dict(self) -> dict:
        """JSON-ready (plain floats)."""
        return {"temperature_c": self.temperature_c, "ambient_c": self.ambient_c,
                "viscosity_pa_s": self.viscosity_pa_s, "friction_power_w": self.friction_power_w,
                "oil_heat_w": self.oil_heat_w, "housing_heat_w": self.housing_heat_w,
                "housing_heat_transfer_w_k": self.housing_heat_transfer_w_k, "oil_supply": self.oil_supply,
                "residual": self.residual}


def heat_out(point: SteadyPoint, oil, temperature: float, ambient: float, housing: float,
             supply: str) -> tuple[float, float]:
    """(oil, housing) heat flows (W) at effective temperature ``temperature`` (C) of ``point`` (module docstring)."""
    rise = 2.0 * (temperature - ambient)
    oil_heat = 0.0
    if supply == "fed":
        carried = point.inlet_flow_m3_s - 0.5 * point.side_flow_m3_s
        oil_heat = float(oil.density(temperature)) * oil.heat_capacity * carried * rise
    return oil_heat, housing * (temperature - ambient)


def heat_balance(joint, load: float, omega: float, viscosity=None, oil=None, ambient: float | None = None,
                 housing: float | None = None, supply: str | None = None, warm: dict | None = None) -> HeatBalance:
    """The :class:`HeatBalance` of the lubricated ``joint`` under ``load`` (N) at journal speed ``omega``
    (rad/s), bearing still.

    The oil, ambient temperature, k A and supply default to the joint's lubrication; ``viscosity``, a function
    of the temperature in C (Pa s), defaults to the oil's (``viscosity`` lets a check use a fixed one).
    ``warm``: the elastic film's start, kept between the balance's temperatures and, when the caller passes one,
    between its points (:func:`weftsim.joint.ehl.elastic_point`).
    """
    from scipy.optimize import brentq

    lub = joint.lubrication
    oil = lub.oil_model if oil is None else oil
    if oil is None:
        raise SceneError("the heat balance needs an oil (lubrication.oil or oil.nu40_mm2_s/nu100_mm2_s)")
    ambient = lub.ambient_temperature if ambient is None else ambient
    housing = (housing_estimate(joint) if lub.housing_heat_transfer is None else lub.housing_heat_transfer) \
        if housing is None else housing
    supply = lub.oil_supply if supply is None else supply
    eta = oil.viscosity if viscosity is None else viscosity
    prm = joint_block(joint)
    warm = {} if warm is None else warm  # the elastic film's last solution starts the next one (weftsim.joint.ehl)

    def at(t: float) -> tuple[float, SteadyPoint]:
        point = steady_point(joint, load, omega, float(eta(t)), prm, warm)
        return point.power_loss_w - sum(heat_out(point, oil, t, ambient, housing, supply)), point

    limit = oil.temperature_limit()
    temperature, step = ambient, STEP_K
    if at(ambient)[0] > 0.0:
        low = ambient
        while True:  # brackets grow geometrically from ambient: the first sign change of g
            high = min(low + step, limit)
            if at(high)[0] <= 0.0:
                break
            if high >= limit:
                raise SceneError(f"the plain bearing's heat balance has no solution below {limit:.4g} C (where the "
                                 f"oil thins to 2 mm^2/s): the friction power {at(limit)[1].power_loss_w:.4g} W "
                                 "outgrows what the oil flow and the housing carry off; a thicker oil, a larger "
                                 "pin or more cooling (housing_heat_transfer_w_k)")
            low, step = high, 2.0 * step
        temperature = brentq(lambda t: at(t)[0], low, high, xtol=TEMPERATURE_TOL)
    point = at(temperature)[1]
    oil_heat, housing_heat = heat_out(point, oil, temperature, ambient, housing, supply)
    return HeatBalance(float(temperature), float(ambient), float(point.viscosity_pa_s), float(point.power_loss_w),
                       float(oil_heat), float(housing_heat), float(housing), supply, point)


def with_film_temperature(joint, load: float, omega: float):
    """(joint, balance): ``joint`` with its lubrication's viscosity at the effective film temperature of the
    operating point (``film_temperature`` set), and the :class:`HeatBalance`."""
    balance = heat_balance(joint, load, omega)
    lub = replace(joint.lubrication, viscosity=balance.viscosity_pa_s, film_temperature=balance.temperature_c)
    return replace(joint, lubrication=lub), balance
