"""Lubricating oils: ISO 3448 viscosity grades, Walther's viscosity-temperature relation (ASTM D341), density
and heat capacity (the one definition; docs/lubricated-joint.md, "The film's temperature").

**Walther (ASTM D341).**  The kinematic viscosity nu (mm^2/s) of a petroleum oil follows

    log10 log10(nu + 0.7) = A - B log10 T,      T in K,

a straight line on the ASTM D341 chart, through the oil's two points at 40 and 100 C (ASTM D341-20, valid
from nu = 2 mm^2/s up; the constant 0.7 is the standard's for that range).

**Grades.**  ISO 3448 names an industrial oil by its kinematic viscosity at 40 C (the grade's midpoint,
:data:`ISO_VG`).  The second point is that of a mineral oil of viscosity index 95, the index of the
viscosity-temperature charts of bearing catalogues: nu_100 solves VI = 100 (L - nu_40) / (L - H) = 95 with L
and H of ASTM D2270 Table 1 (procedure A; for nu_100 > 70 mm^2/s its formulas L = 0.8353 Y^2 + 14.67 Y - 216,
H = 0.1684 Y^2 + 11.85 Y - 97), interpolated linearly between the table's rows.  VG 2-5 have nu_100 below
2 mm^2/s, where D2270 defines no index: give such an oil by its two viscosities.

**Density and heat capacity.**  Mineral oils have 860-900 kg/m^3 at 15 C; the density falls by
about 0.65 kg/m^3 per K (rho(t) = rho_15 - 0.65 (t - 15): a thermal expansion of ~7.5e-4 /K; it moves eta by
4 % over 60 K).  The specific heat of a mineral oil is 1.8-2.1 kJ/(kg K) between 20 and 100 C (Cragoe,
NBS Misc. Publ. 97, 1929: c_p = (1.684 + 0.00339 t) / sqrt(s_15) kJ/(kg K), 2.0 at 60 C for s_15 = 0.88); the
heat balance takes it constant, 2000 J/(kg K) by default.  Dynamic viscosity eta = nu rho.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

# ISO 3448 grade -> (midpoint kinematic viscosity at 40 C, nu_100 of a VI-95 mineral oil by ASTM D2270), mm^2/s.
ISO_VG = {
    7: (6.8, 2.064), 10: (10.0, 2.637), 15: (15.0, 3.381), 22: (22.0, 4.254), 32: (32.0, 5.289),
    46: (46.0, 6.645), 68: (68.0, 8.530), 100: (100.0, 11.066), 150: (150.0, 14.546), 220: (220.0, 18.750),
    320: (320.0, 23.957), 460: (460.0, 30.350), 680: (680.0, 39.063), 1000: (1000.0, 49.859),
    1500: (1500.0, 64.215), 2200: (2200.0, 81.18), 3200: (3200.0, 101.6),
}
GRADE_VI = 95.0
# Density of a mineral oil at 15 C (kg/m^3) and its fall per kelvin; specific heat, J/(kg K) (module docstring).
DENSITY_15C, DENSITY_PER_K, HEAT_CAPACITY = 880.0, 0.65, 2000.0
# ASTM D341 holds from 2 mm^2/s up; a film hotter than this is outside any mineral oil's use.
WALTHER_MIN_NU, MAX_TEMPERATURE_C = 2.0, 200.0
# "ISO VG 220", and as a command line writes it without spaces: "ISO_VG_220", "VG220".
_GRADE = re.compile(r"^\s*(?:ISO[\s_-]*)?VG[\s_-]*(\d+)\s*$", re.IGNORECASE)


def walther_kinematic(nu40: float, nu100: float, t_c):
    """Kinematic viscosity (mm^2/s) at ``t_c`` (C) of an oil of nu40, nu100 (mm^2/s at 40 and 100 C).

    ASTM D341 (Walther): log10 log10(nu + 0.7) = A - B log10 T (T in K) through the two points.
    """
    t = np.asarray(t_c, dtype=float) + 273.15
    z40, z100 = (math.log10(math.log10(v + 0.7)) for v in (nu40, nu100))
    b = (z40 - z100) / (math.log10(373.15) - math.log10(313.15))
    a = z40 + b * math.log10(313.15)
    return 10.0 ** (10.0 ** (a - b * np.log10(t))) - 0.7


def density(density_15c: float, t_c):
    """Density (kg/m^3) at ``t_c`` (C) from the density at 15 C: rho_15 - 0.65 (t - 15)."""
    return density_15c - DENSITY_PER_K * (np.asarray(t_c, dtype=float) - 15.0)


@dataclass(frozen=True)
class Oil:
    """A lubricating oil: its two kinematic viscosities, density and specific heat.

    Attributes
    ----------
    name : str
        ``"ISO VG 220"`` for a grade, ``"custom"`` for an oil given by its viscosities.
    nu40, nu100 : float
        Kinematic viscosity at 40 and 100 C, m^2/s.
    density_15c : float
        Density at 15 C, kg/m^3.
    heat_capacity : float
        Specific heat c_p, J/(kg K).
    """

    name: str
    nu40: float
    nu100: float
    density_15c: float = DENSITY_15C
    heat_capacity: float = HEAT_CAPACITY

    def kinematic_viscosity(self, t_c):
        """nu at ``t_c`` (C), m^2/s (:func:`walther_kinematic`)."""
        return 1e-6 * walther_kinematic(1e6 * self.nu40, 1e6 * self.nu100, t_c)

    def viscosity(self, t_c):
        """Dynamic viscosity eta = nu rho at ``t_c`` (C), Pa s."""
        return self.kinematic_viscosity(t_c) * density(self.density_15c, t_c)

    def density(self, t_c):
        """rho at ``t_c`` (C), kg/m^3."""
        return density(self.density_15c, t_c)

    def temperature_limit(self) -> float:
        """The temperature (C) where nu falls to ASTM D341's lower bound 2 mm^2/s (capped at 200 C)."""
        from scipy.optimize import brentq

        nu = lambda t: float(walther_kinematic(1e6 * self.nu40, 1e6 * self.nu100, t)) - WALTHER_MIN_NU  # noqa: E731
        return MAX_TEMPERATURE_C if nu(MAX_TEMPERATURE_C) > 0.0 else brentq(nu, 40.0, MAX_TEMPERATURE_C)


def grade_names() -> list[str]:
    """The ISO VG grades weftsim knows, as a scene names them (``"ISO VG 220"``; also ``"ISO_VG_220"``)."""
    return [f"ISO VG {g}" for g in ISO_VG]


def grade_problem(name: str) -> str | None:
    """One line saying why ``name`` is not a known ISO VG grade, or None."""
    match = _GRADE.match(name) if isinstance(name, str) else None
    if match and int(match.group(1)) in ISO_VG:
        return None
    if match and int(match.group(1)) in (2, 3, 5):
        return (f"oil {name!r}: ISO VG 2-5 have a viscosity below 2 mm^2/s at 100 C, where ASTM D2270 and D341 do not "
                "hold; give the oil by its viscosities (oil.nu40_mm2_s, oil.nu100_mm2_s)")
    return (f"oil {name!r} is not an ISO 3448 grade weftsim knows; give one of {', '.join(grade_names())} or the "
            "oil's viscosities (oil.nu40_mm2_s and oil.nu100_mm2_s)")


def grade_oil(name: str, density_15c: float = DENSITY_15C, heat_capacity: float = HEAT_CAPACITY) -> Oil:
    """The :class:`Oil` of an ISO VG grade (``"ISO VG 220"``; ValueError naming the grades otherwise)."""
    problem = grade_problem(name)
    if problem is not None:
        raise ValueError(problem)
    match = _GRADE.match(name)
    assert match is not None  # grade_problem accepted the name
    grade = int(match.group(1))
    nu40, nu100 = ISO_VG[grade]
    return Oil(f"ISO VG {grade}", 1e-6 * nu40, 1e-6 * nu100, density_15c, heat_capacity)


def custom_problem(nu40: float, nu100: float) -> str | None:
    """One line saying why (nu40, nu100) in m^2/s is not an oil ASTM D341 describes, or None."""
    if not (math.isfinite(nu40) and math.isfinite(nu100) and nu40 > nu100 >= WALTHER_MIN_NU * 1e-6):
        return (f"oil.nu40_mm2_s = {1e6 * nu40:g} and oil.nu100_mm2_s = {1e6 * nu100:g}: an oil needs nu40 > nu100 "
                f">= {WALTHER_MIN_NU:g} mm^2/s (it thins when hot; ASTM D341 holds from 2 mm^2/s)")
    return None
