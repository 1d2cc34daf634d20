"""Parameter objects of a weftsim scene: frozen dataclasses in SI units.

Scene files (TOML) speak mm, deg, rpm and GPa; :mod:`weftsim.input.scene` converts them
and validates them once, so every object here holds checked SI values (m, rad,
rad/s, kg, kg m^2, Pa).  Variants are made with :func:`dataclasses.replace`.

Frames follow docs/physics.md section 1: O is the origin, x = rocker axis D (normal of the
four-bar plane), y along OG, z = x cross y, gravity along -z.  Four-bar plane
coordinates are (Y, Z) = (y, z).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from weftsim.errors import SceneError


@dataclass(frozen=True)
class Geometry:
    """Link lengths and angles of the spatial linkage (docs/physics.md section 1).

    Attributes
    ----------
    crank_inclination : float
        beta, arc A-B of the spherical 4R, rad.  Arcs B-C, C-D, A-D are 90 deg.
    rocker_arm_angle : float
        theta_OE0, angle of OE (from +y towards +z) when the rocker angle phi is 0, rad.
    l_oe, l_ef, l_fg, l_og : float
        Lengths of rocker arm OE, connecting rod EF, sector arm FG and frame OG, m.
    fourbar_branch : int
        +1 or -1: sign in front of the acos of the four-bar assembly (the "+" branch of docs/physics.md section 1 is +1).
    sector_pitch_radius, pinion_pitch_radius, rapier_gear_pitch_radius : float
        d5, d6, d7, m.  Rapier s = (d5 d7 / d6) (theta_FG - theta_FG(0)).
    """

    crank_inclination: float = math.radians(20.0)
    rocker_arm_angle: float = math.radians(105.0)
    l_oe: float = 0.120
    l_ef: float = 0.270
    l_fg: float = 0.050
    l_og: float = 0.220
    fourbar_branch: int = 1
    sector_pitch_radius: float = 0.135
    pinion_pitch_radius: float = 0.030
    rapier_gear_pitch_radius: float = 0.150

    @property
    def rapier_ratio(self) -> float:
        """ds/dtheta_FG = d5 d7 / d6, m/rad."""
        return self.sector_pitch_radius * self.rapier_gear_pitch_radius / self.pinion_pitch_radius

    @property
    def pinion_ratio(self) -> float:
        """d(gear 6/7 angle)/dtheta_FG = -d5/d6 (magnitude d5/d6)."""
        return self.sector_pitch_radius / self.pinion_pitch_radius


@dataclass(frozen=True)
class Inertia:
    """Masses and inertias of members 1-8 (docs/physics.md section 1, reference mechanism).

    Attributes
    ----------
    crank_inertia : float
        J1, crank about axis A (balanced: centre of mass on A), kg m^2.
    coupler_mass : float
        m2, kg; centre of mass at O (no gravity work).
    coupler_inertia : tuple of float
        Principal inertia of the coupler about O in its body frame [b, c, b x c], kg m^2.
    rocker_mass, rocker_com, rocker_inertia : float
        m3 (kg); distance of its centre of mass from O along OE (m); J3 about axis D (kg m^2).
    rod_mass, rod_inertia : float
        m4 (kg), centre of mass at mid EF; J4 about that centre (kg m^2).
    sector_inertia : float
        J5 about G (balanced), kg m^2.
    pinion_gear_inertia : float
        J67, pinion 6 and rapier gear 7 on one shaft (balanced), kg m^2.
    rapier_mass : float
        m8, moves along y (no gravity work), kg.
    gravity : float
        g, m/s^2, acting along -z.
    """

    crank_inertia: float = 0.010
    coupler_mass: float = 1.0
    coupler_inertia: tuple[float, float, float] = (2e-3, 2e-3, 1e-3)
    rocker_mass: float = 1.2
    rocker_com: float = 0.040
    rocker_inertia: float = 0.010
    rod_mass: float = 0.6
    rod_inertia: float = 0.0045
    sector_inertia: float = 0.025
    pinion_gear_inertia: float = 0.0308
    rapier_mass: float = 0.5
    gravity: float = 9.81


@dataclass(frozen=True)
class Material:
    """Elastic constants of one contact partner."""

    youngs_modulus: float = 207e9  # Pa
    poisson_ratio: float = 0.3
    yield_strength: float | None = None  # Pa; None = not given (no contact-pressure warning)
    # Bushing limits (docs/plausibility.md), read on the bearing side; None = not given (no check).
    max_pressure: float | None = None  # Pa: permitted projected pin pressure F / (d B)
    max_pv: float | None = None  # Pa m/s: permitted product of that pressure and the sliding speed

    @property
    def compliance(self) -> float:
        """sigma = (1 - nu^2) / E, 1/Pa (docs/physics.md section 3)."""
        return (1.0 - self.poisson_ratio**2) / self.youngs_modulus


WEAR_REGIMES = ("boundary", "dry")  # of the solid contact (the dry law's load): weftsim.wear.regimes


@dataclass(frozen=True)
class WearModel:
    """Archard wear of a clearance joint and the cycle extrapolation that integrates it (docs/wear.md).

    Archard's law: the volume a surface of hardness H loses is V = k F_N s / H (Archard, J. Appl.
    Phys. 24, 1953), with the dimensionless wear coefficient k of the pair and the sliding distance s;
    k / H is the specific wear rate (mm^3/(N m) with H in N/mm^2 and s in m, times 1e3).  k depends on the
    regime of the contact (docs/wear.md section 5, :mod:`weftsim.wear.regimes`, with the tables it comes from):

    - the **solid contact** (the dry law's load beyond e = c, the only load of a joint without an oil film)
      wears with ``dry_wear_coefficient`` (unlubricated metal on metal) or ``boundary_wear_coefficient``
      (a grease or oil layer on the surfaces, no hydrodynamic film), as ``regime`` says;
    - the **asperity load** of an oil-lubricated joint in the mixed regime (Greenwood-Tripp, the load the
      film does not carry) wears with ``mixed_wear_coefficient``; the film's load wears nothing.

    Attributes
    ----------
    regime : str
        ``"boundary"`` (default) or ``"dry"``: which of the two coefficients the solid contact takes.
    dry_wear_coefficient, boundary_wear_coefficient, mixed_wear_coefficient : float
        k of each regime, dimensionless.  Defaults: steel on steel, 5e-3 clean (Rabinowicz's table of
        adhesive wear coefficients, like metals), 1e-7 boundary and mixed (the lower end of his "excellent
        lubrication", 2e-6 to 1e-7).
    wear_coefficient : float or None
        One k for every load of the joint, overriding the three above (the key of scenes written before the
        regimes; None: the regime keys apply).
    bearing_hardness, journal_hardness : float
        H of each surface, Pa (default 2.0e9: through-hardened steel, ~200 HB).
    max_clearance_change : float
        Update criterion: one geometry update may grow the effective clearance by at most this
        fraction of its current value.
    revolutions_per_update : int
        Steady crank revolutions simulated per update (after ``settle_revolutions``).
    settle_revolutions : int
        Revolutions simulated first and not counted (the start from the centred journal).
    profile_points : int
        Points of the tabulated wear profiles h_b(psi), h_j(psi) over 360 deg.
    """

    wear_coefficient: float | None = None
    bearing_hardness: float = 2.0e9
    journal_hardness: float = 2.0e9
    max_clearance_change: float = 0.02
    revolutions_per_update: int = 4
    settle_revolutions: int = 1
    profile_points: int = 360
    regime: str = "boundary"
    dry_wear_coefficient: float = 5e-3
    boundary_wear_coefficient: float = 1e-7
    mixed_wear_coefficient: float = 1e-7
    run_in_roughness: float | None = None  # m: the lubricated joint's run-in roughness (weftsim.wear.extrapolate)
    run_in_depth: float = 1e-6  # m: the worn depth over which the roughness runs in by 1/e

    @property
    def contact_wear_coefficient(self) -> float:
        """k of the solid contact's load (the dry law's): ``wear_coefficient`` if given, else the regime's."""
        if self.wear_coefficient is not None:
            return self.wear_coefficient
        return self.dry_wear_coefficient if self.regime == "dry" else self.boundary_wear_coefficient

    @property
    def asperity_wear_coefficient(self) -> float:
        """k of the asperity load of a lubricated joint (mixed regime): ``wear_coefficient`` if given."""
        return self.mixed_wear_coefficient if self.wear_coefficient is None else self.wear_coefficient


# Film models of Lubrication.model (the codes of weftsim.physics.film: MODEL_FINITE, MODEL_SHORT, MODEL_LONG,
# MODEL_SHORT_HALF, in this order).
FILM_MODELS = ("finite", "short", "long", "short_half")


@dataclass(frozen=True, kw_only=True)
class Lubrication:
    """Oil film and asperity contact of a lubricated clearance joint (docs/lubricated-joint.md).

    A joint without a ``Lubrication`` (``ClearanceJoint.lubrication = None``) is the dry joint.  With
    one, the film's pressure carries the journal for every eccentricity (no contact needed), the
    asperities of both surfaces carry load where the minimum film thickness ``h_min = c - |e|`` is below
    4 sigma (Greenwood and Tripp, Proc. Instn Mech. Engrs 185, 1970), and the dry contact law of the
    joint takes over beyond e = c, continuously (:mod:`weftsim.physics.lubricated`).

    Attributes
    ----------
    viscosity : float
        Dynamic viscosity eta of the oil at operating temperature, Pa s (>= 0; 0 = no film).
    model : str
        Film model: ``"finite"`` (finite length, default), ``"short"`` (Ocvirk), ``"long"``
        (Sommerfeld with Guembel cavitation) or ``"short_half"`` (the short bearing as Flores, Ambrosio,
        Claro and Lankarani write it), :data:`FILM_MODELS` (docs/lubrication.md).
    roughness : float
        Combined RMS roughness sigma = sqrt(sigma_j^2 + sigma_b^2) of journal and bearing, m.
        Default 0.4 um: two ground surfaces of Rq ~ 0.3 um.
    asperity_density_radius_roughness : float
        eta_s beta sigma of Greenwood-Tripp (asperity density x asperity summit radius x sigma),
        dimensionless; 0 switches asperity contact off.  Default 0.04 (0.03-0.07 for ground and honed
        steel, the usual range of mixed-lubrication bearing models).
    roughness_radius_ratio : float
        sigma / beta (RMS roughness over asperity summit radius).  Default 1e-3.
    boundary_friction_coefficient : float
        mu_b of the boundary friction on the asperity load (modified Coulomb, with the joint's
        ``friction_velocities``).  Default 0.1 (boundary-lubricated steel on steel or bronze).
    film_floor_ratio : float
        A numerical knob: the film force is evaluated down to h_min = film_floor_ratio x sigma and continued
        below it with its slope, curvature and turning rate there (:func:`weftsim.physics.lubricated.film_at_floor`)
        down to the wall sigma / 4, where it is held, so it stays finite where the dry law starts (e = c).  In
        [0.25, 4] (the rough film's table reaches sigma / 4); default 1 (film ratio 1).
    elastic_film : bool
        ``weftsim bearing`` solves the steady point with the surfaces' elastic deformation under the film's and the
        asperities' pressure (:mod:`weftsim.joint.ehl`; moduli of ``journal_material`` and ``bearing_material``).
        The transient engines keep the rigid film (a transient run refuses the key).  Default False.
    summit_height : float
        delta, the mean height of the asperity summits above the surfaces' mean planes (both surfaces'
        together), m: Greenwood and Tripp's pressure is taken at the separation h - delta (MBDyn's "asperity mean
        height").  Used by the elastic film only (refused > 0 without it).  Default 0.
    pressure_viscosity : float
        Barus' pressure-viscosity coefficient alpha, 1/Pa: the film's viscosity eta exp(alpha p) (mineral oils
        1-3e-8).  Used by the elastic film only (refused > 0 without it).  Default 0 (isoviscous).
    surface_roughness : tuple of float or None
        (sigma_journal, sigma_bearing), m: the two surfaces' own RMS roughnesses for Patir and Cheng's average flow
        of the elastic film (its H = h / sqrt(sigma_j^2 + sigma_b^2), and the shear flow of unlike surfaces,
        :class:`weftsim.physics.flow_factors.SurfacePair`); ``roughness`` stays the asperity contact's.  Used by the
        elastic film only.  Default None: both alike, of the combined ``roughness``.
    peklenik_numbers : tuple of float or None
        (gamma_journal, gamma_bearing): the surfaces' Peklenik numbers, the ratio of their correlation lengths
        along the sliding (circumferential) direction and across it (> 1: ridges along the motion), for Patir and
        Cheng's anisotropic flow factors of the elastic film.  Used by the elastic film only.  Default None:
        isotropic (1, 1).
    asperity_modulus : float
        E* of the asperity contact, Pa, where a source gives it apart from the parts' moduli (0: the joint's
        effective modulus from its two materials, the default).
    oil : str
        An ISO 3448 grade (``"ISO VG 220"``, :func:`weftsim.physics.oil.grade_names`): the viscosity then follows
        from the film's temperature (:mod:`weftsim.joint.heat`) instead of ``viscosity``.  Empty: not given.
    oil_nu40, oil_nu100 : float
        A custom oil instead of a grade: kinematic viscosities at 40 and 100 C, m^2/s (0: not given).
    oil_density, oil_heat_capacity : float
        The oil's density at 15 C (kg/m^3, default 880) and specific heat (J/(kg K), default 2000).
    ambient_temperature : float
        Temperature of the air around the joint and of the oil fed to it, C (default 25).
    housing_heat_transfer : float or None
        Heat flow from the bearing to the ambient per kelvin, k A, W/K; None: estimated
        (:func:`weftsim.joint.heat.housing_estimate`).
    oil_supply : str
        ``"fed"`` (default: oil at the ambient temperature floods the film at its thickest line and its flow
        carries heat off) or ``"sump"`` (self-contained: the heat leaves through the housing alone).
    film_temperature : float or None
        The effective film temperature (C) the heat balance found for the scene's operating point, with
        ``viscosity`` the oil's viscosity there; None until computed (:func:`weftsim.joint.bearing.resolve_scene`).
    """

    viscosity: float
    model: str = "finite"
    roughness: float = 0.4e-6
    asperity_density_radius_roughness: float = 0.04
    roughness_radius_ratio: float = 1e-3
    boundary_friction_coefficient: float = 0.1
    film_floor_ratio: float = 1.0
    elastic_film: bool = False
    summit_height: float = 0.0
    pressure_viscosity: float = 0.0
    asperity_modulus: float = 0.0
    surface_roughness: tuple[float, float] | None = None
    peklenik_numbers: tuple[float, float] | None = None
    oil: str = ""
    oil_nu40: float = 0.0
    oil_nu100: float = 0.0
    oil_density: float = 880.0
    oil_heat_capacity: float = 2000.0
    ambient_temperature: float = 25.0
    housing_heat_transfer: float | None = None
    oil_supply: str = "fed"
    film_temperature: float | None = None

    def __post_init__(self):
        problem = lubrication_problem(self)
        if problem is not None:
            raise SceneError(problem)

    @property
    def has_oil(self) -> bool:
        """True when an oil is named (grade or viscosities): the viscosity follows from the film temperature."""
        return bool(self.oil) or self.oil_nu40 > 0.0 or self.oil_nu100 > 0.0

    @property
    def oil_model(self):
        """The :class:`weftsim.physics.oil.Oil` named, or None."""
        from weftsim.physics.oil import Oil, grade_oil

        if self.oil:
            return grade_oil(self.oil, self.oil_density, self.oil_heat_capacity)
        if self.has_oil:
            return Oil("custom", self.oil_nu40, self.oil_nu100, self.oil_density, self.oil_heat_capacity)
        return None

    @property
    def model_code(self) -> int:
        """The film kernel's model code (weftsim.physics.film: finite 0, short 1, long 2)."""
        return FILM_MODELS.index(self.model)


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def lubrication_problem(lub: Lubrication) -> str | None:
    """One line naming the first invalid field of ``lub`` and what is allowed, or None."""
    if not (_number(lub.viscosity) and lub.viscosity >= 0.0):
        return f"`lubrication.viscosity` must be >= 0 (Pa s; 0 = no film), got {lub.viscosity!r}"
    if lub.model not in FILM_MODELS:
        return f"`lubrication.model` must be one of {FILM_MODELS}, got {lub.model!r}"
    if not (_number(lub.roughness) and lub.roughness > 0.0):
        return f"`lubrication.roughness` must be > 0 (m, combined RMS of both surfaces), got {lub.roughness!r}"
    eta = lub.asperity_density_radius_roughness
    if not (_number(eta) and 0.0 <= eta <= 1.0):
        return (f"`lubrication.asperity_density_radius_roughness` must be in [0, 1] (0 = no asperity contact), "
                f"got {eta!r}")
    ratio = lub.roughness_radius_ratio
    if not (_number(ratio) and 0.0 < ratio <= 1.0):
        return f"`lubrication.roughness_radius_ratio` must be in (0, 1] (sigma / beta), got {ratio!r}"
    mu = lub.boundary_friction_coefficient
    if not (_number(mu) and 0.0 <= mu <= 2.0):
        return f"`lubrication.boundary_friction_coefficient` must be in [0, 2], got {mu!r}"
    floor = lub.film_floor_ratio
    if not (_number(floor) and 0.25 <= floor <= 4.0):
        return (f"`lubrication.film_floor_ratio` must be in [0.25, 4] (film floor / sigma; the rough film is tabulated "
                f"down to h_min = sigma / 4), got {floor!r}")
    if not isinstance(lub.elastic_film, bool):
        return f"`lubrication.elastic_film` must be true or false, got {lub.elastic_film!r}"
    delta = lub.summit_height
    if not (_number(delta) and 0.0 <= delta <= 4.0 * lub.roughness):
        return (f"`lubrication.summit_height` must be in [0, 4 sigma] (m, the summits' mean height above the mean "
                f"planes; sigma = {lub.roughness:.3g} m), got {delta!r}")
    if delta > 0.0 and not lub.elastic_film:
        return ("`lubrication.summit_height` is used by the elastic film only (the rigid kernel's asperities touch "
                f"at h = 4 sigma): set `lubrication.elastic_film` = true or summit_height = 0, got {delta!r}")
    alpha = lub.pressure_viscosity
    if not (_number(alpha) and 0.0 <= alpha <= 1e-7):
        return f"`lubrication.pressure_viscosity` must be in [0, 1e-7] (1/Pa, Barus' alpha), got {alpha!r}"
    if alpha > 0.0 and not lub.elastic_film:
        return ("`lubrication.pressure_viscosity` is used by the elastic film only (the rigid kernel's film is "
                f"isoviscous): set `lubrication.elastic_film` = true or pressure_viscosity = 0, got {alpha!r}")
    for name, pair, allowed in (("surface_roughness", lub.surface_roughness, "RMS roughnesses of journal and "
                                                                                "bearing, m, each > 0"),
                                ("peklenik_numbers", lub.peklenik_numbers, "Peklenik numbers of journal and "
                                                                           "bearing, each > 0")):
        if pair is None:
            continue
        if not (isinstance(pair, (tuple, list)) and len(pair) == 2 and all(_number(v) and v > 0.0 for v in pair)):
            return f"`lubrication.{name}` must be two numbers ({allowed}), got {pair!r}"
        if not lub.elastic_film:
            return (f"`lubrication.{name}` is used by the elastic film only (the rigid kernel's table has isotropic "
                    f"alike surfaces): set `lubrication.elastic_film` = true or leave {name} unset, got {pair!r}")
    if not (_number(lub.asperity_modulus) and lub.asperity_modulus >= 0.0):
        return f"`lubrication.asperity_modulus` must be >= 0 (Pa; 0 = the joint's effective modulus), got {lub.asperity_modulus!r}"
    return oil_problem(lub)


OIL_SUPPLIES = ("fed", "sump")


def oil_problem(lub: Lubrication) -> str | None:
    """One line naming the first invalid oil field of ``lub`` (:class:`Lubrication`), or None."""
    from weftsim.physics.oil import custom_problem, grade_problem

    if not isinstance(lub.oil, str):
        return f"`lubrication.oil` must be a grade name such as 'ISO VG 220', got {lub.oil!r}"
    for name in ("oil_nu40", "oil_nu100", "oil_density", "oil_heat_capacity", "ambient_temperature"):
        if not _number(getattr(lub, name)):
            return f"`lubrication.{name}` must be a finite number, got {getattr(lub, name)!r}"
    custom = lub.oil_nu40 > 0.0 or lub.oil_nu100 > 0.0
    if lub.oil and custom:
        return ("`lubrication.oil` names a grade and `lubrication.oil_nu40`/`oil_nu100` give viscosities: give the oil "
                "one way (the grade, or its two viscosities)")
    if lub.oil and grade_problem(lub.oil):
        return grade_problem(lub.oil)
    if lub.oil_nu40 > 0.0 and lub.oil_nu100 > 0.0 and custom_problem(lub.oil_nu40, lub.oil_nu100):
        return custom_problem(lub.oil_nu40, lub.oil_nu100)  # one of the two alone: weftsim.joint.bearing says so
    if lub.has_oil and lub.viscosity > 0.0 and lub.film_temperature is None:
        return ("`lubrication.viscosity` and `lubrication.oil` are both given: give the oil (its viscosity then follows "
                "from the film temperature) or a fixed viscosity, not both")
    if not (lub.oil_density > 0.0 and lub.oil_heat_capacity > 0.0):
        return "`lubrication.oil_density` and `oil_heat_capacity` must be > 0 (kg/m^3 at 15 C, J/(kg K))"
    if not -40.0 <= lub.ambient_temperature <= 150.0:
        return f"`lubrication.ambient_temperature` must be in [-40, 150] C, got {lub.ambient_temperature!r}"
    heat = lub.housing_heat_transfer
    if heat is not None and not (_number(heat) and heat >= 0.0):
        return f"`lubrication.housing_heat_transfer` must be >= 0 (W/K) or None (estimated), got {heat!r}"
    if lub.oil_supply not in OIL_SUPPLIES:
        return f"`lubrication.oil_supply` must be one of {OIL_SUPPLIES}, got {lub.oil_supply!r}"
    return None


# Impact velocity rules of ClearanceJoint.impact_velocity_rule (weftsim.input.scene re-exports it).
IMPACT_VELOCITY_RULES = ("max_approach", "onset")


@dataclass(frozen=True, kw_only=True)
class ClearanceJoint:
    """A revolute joint with radial clearance: E, or F (docs/physics.md sections 2 and 3).

    ``clearance`` and ``law`` have no default: a joint is a choice of both (the loom's joint at E of
    the reference mechanism is :data:`LOOM_JOINT_E`, c = 0.25 mm with the paper's ``variable_kd``).
    The other fields default to a steel journal of 10 mm radius in a 20 mm bearing, ce = 0.9, no
    friction.  Every value is checked here (one line naming the field and what is allowed), so a
    joint built in Python is as safe as one loaded from a scene.

    Attributes
    ----------
    clearance : float
        Radial clearance c = R_b - R_j, m, >= 0.  0 means the ideal revolute joint.
    journal_radius : float
        R_j, m.  Bearing radius R_b = R_j + c.
    bearing_length : float
        L_b, axial length of the bearing, m (used by ``elastic_foundation`` and ``cylindrical``).
    bushing_wall : float or None
        t, radial wall thickness of the bushing between its bore and the housing (the link's eye), m;
        used by the ``cylindrical`` law (its stiffness is fitted with the wall), None = not given.
    journal_material, bearing_material : Material
    law : str
        Name of the contact force law in :data:`weftsim.joint.contact.LAWS`.
    restitution : float
        Coefficient of restitution ce in (0, 1].
    friction_coefficient : float
        mu of the modified Coulomb law; 0 switches friction off.
    friction_velocities : tuple of float
        (v0, v1), m/s: the friction factor ramps from 0 to 1 between them.
    min_impact_velocity : float
        Floor v_min on the held impact velocity, m/s.
    impact_velocity_rule : str
        How the impact velocity delta_dot^- of the damping term is held through a contact:
        ``"max_approach"`` (default), the largest approach rate since the onset, floored at
        v_min (identical to the onset value in an isolated impact, bounded in a driven lasting
        contact: xi delta_dot / delta_dot^- <= xi); ``"onset"``, the approach rate at the onset
        alone (Lankarani-Nikravesh, Flores), for comparison with published results.
    wear : WearModel
        Archard wear parameters (``[joint_e.wear]`` or ``[joint_f.wear]``), used by ``weftsim wear`` only.
    design_clearance : tuple of float
        (low, high): the design range of the radial clearance over the journal diameter, c / (2 R_j)
        (dimensionless).  Default (0.5e-3, 1.0e-3): a bushed pin in oscillating motion (docs/plausibility.md);
        a clearance outside it is warned about before the run.
    lubrication : Lubrication or None
        Oil film and asperity contact (``[joint_e.lubrication]``); None = the dry joint.
    bearing_wear, journal_wear : tuple of float
        Worn depth, m, at equally spaced angles over 360 deg in the bearing's (rocker 3) and the
        journal's (rod 4) body frame; empty = unworn (round).  The contact sees the clearance
        c(psi) = c + h_b + h_j along the eccentricity direction (docs/wear.md).
    """

    clearance: float
    journal_radius: float = 10e-3
    bearing_length: float = 20e-3
    bushing_wall: float | None = None
    journal_material: Material = field(default_factory=Material)
    bearing_material: Material = field(default_factory=Material)
    law: str
    restitution: float = 0.9
    friction_coefficient: float = 0.0
    friction_velocities: tuple[float, float] = (1e-4, 2e-4)
    min_impact_velocity: float = 1e-4
    impact_velocity_rule: str = "max_approach"
    wear: WearModel = field(default_factory=WearModel)
    design_clearance: tuple[float, float] = (0.5e-3, 1.0e-3)
    bearing_wear: tuple[float, ...] = ()
    journal_wear: tuple[float, ...] = ()
    lubrication: Lubrication | None = None

    @property
    def is_lubricated(self) -> bool:
        """True when the joint has an oil film (``lubrication`` given)."""
        return self.lubrication is not None

    @property
    def is_worn(self) -> bool:
        return bool(self.bearing_wear or self.journal_wear)

    def __post_init__(self):
        problem = joint_problem(self)
        if problem is not None:
            raise SceneError(problem)

    @property
    def is_ideal(self) -> bool:
        return self.clearance == 0.0

    @property
    def bearing_radius(self) -> float:
        return self.journal_radius + self.clearance

    @property
    def effective_modulus(self) -> float:
        """E* = 1 / (sigma_b + sigma_j), Pa."""
        return 1.0 / (self.journal_material.compliance + self.bearing_material.compliance)


def _positive_finite(value) -> bool:
    return isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0


def joint_problem(joint: ClearanceJoint) -> str | None:
    """One line naming the first invalid field of ``joint`` and what is allowed, or None.

    The law's name is checked where the laws live (:func:`weftsim.joint.contact.make_law`).
    """
    c = joint.clearance
    if not (isinstance(c, (int, float)) and math.isfinite(c) and c >= 0.0):
        return f"`clearance` must be >= 0 (m; 0 = ideal joint), got {c!r}"
    for name in ("journal_radius", "bearing_length", "min_impact_velocity"):
        value = getattr(joint, name)
        if not _positive_finite(value):
            unit = "m/s" if name == "min_impact_velocity" else "m"
            return f"`{name}` must be > 0 ({unit}), got {value!r}"
    wall = joint.bushing_wall
    if wall is not None and not _positive_finite(wall):
        return f"`bushing_wall` must be > 0 (m) or None (not given), got {wall!r}"
    if not isinstance(joint.law, str) or not joint.law:
        return f"`law` must name a contact law (weftsim.joint.contact.LAWS), got {joint.law!r}"
    ce = joint.restitution
    if not (isinstance(ce, (int, float)) and 0.0 < ce <= 1.0):
        return f"`restitution` must be in (0, 1], got {ce!r}"
    mu = joint.friction_coefficient
    if not (isinstance(mu, (int, float)) and math.isfinite(mu) and mu >= 0.0):
        return f"`friction_coefficient` must be >= 0 (0 = no friction), got {mu!r}"
    ramp = tuple(joint.friction_velocities)
    if len(ramp) != 2 or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in ramp) \
            or not 0.0 <= ramp[0] < ramp[1]:
        return f"`friction_velocities` must be (v0, v1) with 0 <= v0 < v1 (m/s), got {joint.friction_velocities!r}"
    if joint.impact_velocity_rule not in IMPACT_VELOCITY_RULES:
        return f"`impact_velocity_rule` must be one of {IMPACT_VELOCITY_RULES}, got {joint.impact_velocity_rule!r}"
    for side in ("journal_material", "bearing_material"):
        m = getattr(joint, side)
        if not _positive_finite(m.youngs_modulus):
            return f"`{side}.youngs_modulus` must be > 0 (Pa), got {m.youngs_modulus!r}"
        if not (isinstance(m.poisson_ratio, (int, float)) and 0.0 <= m.poisson_ratio < 0.5):
            return f"`{side}.poisson_ratio` must be in [0, 0.5), got {m.poisson_ratio!r}"
        for name in ("yield_strength", "max_pressure", "max_pv"):
            value = getattr(m, name)
            if value is not None and not _positive_finite(value):
                return f"`{side}.{name}` must be > 0 or None (not given), got {value!r}"
    band = tuple(joint.design_clearance)
    if len(band) != 2 or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in band) \
            or not 0.0 <= band[0] < band[1]:
        return (f"`design_clearance` must be (low, high) with 0 <= low < high (radial clearance / diameter), "
                f"got {joint.design_clearance!r}")
    lub = joint.lubrication
    if lub is not None:
        if not isinstance(lub, Lubrication):
            return f"`lubrication` must be a weftsim.input.params.Lubrication or None, got {type(lub).__name__}"
        if joint.friction_coefficient > 0.0:
            return (f"`friction_coefficient` ({joint.friction_coefficient:g}) is the dry joint's: in oil the solids' "
                    f"contact carries `lubrication.boundary_friction_coefficient`; set friction_coefficient = 0")
        if c > 0.0 and lub.film_floor_ratio * lub.roughness >= c:
            return (f"`lubrication.roughness` x `film_floor_ratio` ({lub.film_floor_ratio * lub.roughness:.3g} m) "
                    f"must be smaller than the clearance {c:.3g} m (the film needs room between the surfaces)")
    return None


# The loom's joint at E in the reference mechanism (docs/physics.md sections 1-3): c = 0.25 mm,
# the paper's law; the default of Scene.joint, which every scene file then overrides key by key.
LOOM_JOINT_E = ClearanceJoint(clearance=0.25e-3, law="variable_kd")


TAPE_MODELS = ("auto", "flexible", "rigid")


@dataclass(frozen=True)
class RapierTape:
    """The flexible rapier tape and its head (docs/rapier-tape.md), the scene's ``[rapier_tape]`` table.

    The defaults are a stated basis, not published tape data (none was found): a carbon/epoxy laminate of
    two thirds 0 deg and one third 90 deg plies of AS4/3501-6 (E1 = 145 GPa, E2 = 10.5 GPa, 1.58 g/cm^3,
    lamina data of the composites literature, e.g. Daniel and Ishai, Engineering Mechanics of Composite
    Materials), axial modulus by the iso-strain rule of mixtures 2/3 145 + 1/3 10.5 = 100 GPa; an assumed
    cross-section of 30 x 2.5 mm; a Kelvin-Voigt time of 1 us (loss factor omega tau = 0.5 % at the first
    mode of the mid-stroke free length, of the order of carbon/epoxy's low material damping).

    Attributes
    ----------
    length : float
        Whole tape from the head to its tail behind the wheel, m (>= free length + stroke).
    width, thickness : float
        Cross-section, m.
    axial_modulus : float
        E along the tape, Pa.
    density : float
        rho, kg/m^3.
    damping_time : float
        Kelvin-Voigt retardation time tau, s: stress = E (strain + tau strain rate).
    head_mass : float
        The rapier head at the tape's end, kg.
    free_length : float
        The wheel's engagement: tape between the point where it leaves the wheel and the head with the
        rapier outermost (s = 0), m.
    guide_friction_coefficient : float
        Coulomb friction of the head and the free tape on the guide rail under their weight; 0 = off.
    model : str
        "auto" (the rigid rapier when the tape's first mode over the stroke is far above the drive's
        harmonics, :func:`weftsim.model.tape.rigid_serves`), "flexible" or "rigid".
    modes : int
        Ritz functions of the tape's axial displacement.
    """

    length: float = 1.9
    width: float = 0.030
    thickness: float = 0.0025
    axial_modulus: float = 100e9
    density: float = 1580.0
    damping_time: float = 1e-6
    head_mass: float = 0.125
    free_length: float = 0.25
    guide_friction_coefficient: float = 0.0
    model: str = "auto"
    modes: int = 4

    @property
    def mass_per_length(self) -> float:
        """mu = rho A, kg/m."""
        return self.density * self.width * self.thickness

    @property
    def axial_stiffness(self) -> float:
        """EA, N."""
        return self.axial_modulus * self.width * self.thickness

    @property
    def mass(self) -> float:
        """Tape and head, kg: the rigid rapier's m8."""
        return self.head_mass + self.mass_per_length * self.length


@dataclass(frozen=True)
class Exchange:
    """The weft exchange at mid-shed (docs/rapier-tape.md section 7), the scene's ``[exchange]`` table.

    The giver head is this scene's mechanism; the taker head is the same mechanism mirrored on the other side
    of the shed, on the same crank (both heads reach their deepest position, the dead centre, together), with
    its own radial clearance at E and everything else the giver's.  Neither value below is published loom data
    (none was found): both are assumptions, named as such.

    Attributes
    ----------
    enabled : bool
        False: the table describes an exchange that is not computed (the run is the scene's without it).
    taker_clearance : float or None
        The taker's radial clearance at E, m; 0 = an ideal joint; None = the giver's (a symmetric machine).
    overlap : float
        How far the heads of the ideal mechanism pass each other at the dead centre, m (assumed 50 mm: the
        taker's hook reaches into the giver head).  It places the two mechanisms: their outermost head
        positions are 2 x stroke - overlap apart.
    window : float or None
        Full width of the transfer window in crank angle, centred on the dead centre, rad; None = the crank
        angles over which the ideal heads overlap.
    """

    enabled: bool = True
    taker_clearance: float | None = None
    overlap: float = 0.050
    window: float | None = None


def exchange_problem(scene: Scene, stroke: float, flexible_tape: bool) -> str:
    """Why the scene's ``[exchange]`` cannot be computed ('' when it can, or when it is absent or off): one line
    naming the key.  ``stroke``: the ideal head's deepest position, m; ``flexible_tape``: the scene's tape runs
    flexible (the scene reader passes its explicit ``rapier_tape.model``, :func:`weftsim.model.exchange.
    exchange_problem` the automatic choice too)."""
    exchange = scene.exchange
    if exchange is None or not exchange.enabled:
        return ""
    c = scene.joint.clearance if exchange.taker_clearance is None else exchange.taker_clearance
    if c >= scene.joint.journal_radius:
        return (f"key 'exchange.taker_clearance_mm' must be smaller than the journal radius "
                f"{scene.joint.journal_radius * 1e3:g} mm, got {c * 1e3:g}")
    if exchange.overlap >= 2.0 * stroke:
        return (f"key 'exchange.overlap_mm' must be smaller than twice the stroke, {2e3 * stroke:.1f} mm (the heads "
                f"start apart), got {exchange.overlap * 1e3:g}")
    if c == 0.0 and flexible_tape:
        return ("key 'exchange.taker_clearance_mm' = 0 gives the taker ideal joints, which the flexible rapier tape "
                "cannot run (it needs a clearance at E): give the taker a clearance > 0, or set rapier_tape.model = "
                "'rigid'")
    return ""


@dataclass(frozen=True)
class Drive:
    """Crank speed and run length; the drive law of a stop-start's transient (:func:`weftsim.physics.chain.crank_motion`).

    ``law``: ``"constant"`` (theta = omega t: every run of a scene file), ``"run_down"`` (omega until
    ``ramp_start``, then to rest over ``ramp`` s) or ``"start_up"`` (at rest until ``ramp_start``, then to omega
    over ``ramp`` s, the journal resting on the bearing's wall at t = 0: no film).  The transients are set by
    the duty cycle (:mod:`weftsim.wear.duty`), not by scene keys; ``start_angle`` is the crank angle at t = 0.
    """

    speed: float = 400.0 * (2.0 * math.pi / 60.0)  # omega, rad/s (same rounding as a scene file's 400 rpm)
    revolutions: float = 2.0
    law: str = "constant"
    ramp_start: float = 0.0  # s
    ramp: float = 0.0  # s
    start_angle: float = 0.0  # rad

    @property
    def period(self) -> float:
        """Time of one crank revolution, s."""
        return 2.0 * math.pi / self.speed

    @property
    def end_time(self) -> float:
        return self.revolutions * self.period


@dataclass(frozen=True)
class Duty:
    """How a loom runs in a day (``[duty]``; :mod:`weftsim.wear.duty`, docs/wear.md section 12).

    Attributes
    ----------
    stops_per_hour : float
        Stops per hour of running (warp and weft breaks, other stops); each is a run-down to rest and a start-up
        from rest with the film built up again from zero, whose simulated wear is added per hour of running.
        0 (default): the steady prediction alone.
    stop_minutes : float
        Mean time the loom stands per stop, min (repair of the break): the calendar time, not the wear.
    hours_per_day, days_per_week : float
        The loom's scheduled hours (24 = three shifts) and working days.
    startup_revolutions, rundown_revolutions : float
        Crank revolutions of the start-up ramp from rest to full speed and of the run-down to rest.
    """

    stops_per_hour: float = 0.0
    stop_minutes: float = 2.87
    hours_per_day: float = 24.0
    days_per_week: float = 7.0
    startup_revolutions: float = 1.0
    rundown_revolutions: float = 1.0

    def calendar_days(self, running_hours: float) -> float:
        """Calendar days for ``running_hours`` of running: each running hour costs 1 + stops x stop time of the
        scheduled hours, hours_per_day of them a working day, days_per_week working days a week."""
        scheduled = running_hours * (1.0 + self.stops_per_hour * self.stop_minutes / 60.0)
        return scheduled / self.hours_per_day * 7.0 / self.days_per_week


@dataclass(frozen=True)
class ReferenceSolver:
    """Settings of the closed-form Lagrange solver (scipy)."""

    # "auto": the compiled DOP853 (weftsim.reference.compiled, numba) at rtol / atol below, the fastest
    # path that meets the accuracy targets on the benchmark's cases (docs/performance.md):
    # first-revolution peaks within 2.4e-3 of the converged solution at 1e-5, statistics within
    # the scatter of the converged ensemble.  scipy's methods are named explicitly (the
    # independent integrator check); they were run at rtol 1e-9, atol 1e-12.
    method: str = "auto"
    rtol: float = 1e-5
    atol: float = 1e-8
    max_step: float = math.radians(0.5)  # crank angle, rad


@dataclass(frozen=True)
class ExudynSolver:
    """Settings of the Exudyn engine.

    ``model``: "auto" (the kinematic tree unless the scene needs the rigid-body model:
    :mod:`weftsim.exudyn_engine.selection`), "rigid_body" (members 1-8 as bodies and joints,
    generalized-alpha with ``spectral_radius`` and the Newton settings; its step is error-controlled
    to ``local_error`` under ``step_control = "adaptive"``, or ``step_size`` under ``"fixed"``) or
    "kinematic_tree" (members 1-3 prescribed, 4-8 in minimal coordinates, explicit
    ``explicit_method`` with automatic step size to ``relative_tolerance`` /
    ``absolute_tolerance``, or ``tree_solver = "implicit"``: generalized-alpha with the rigid-body
    model's error control to ``local_error``; "auto": implicit with friction in the joint, explicit
    without; docs/performance.md).
    """

    model: str = "auto"
    step_control: str = "adaptive"  # rigid_body: "adaptive" (local error control, step_control.py) or "fixed"
    local_error: float = 3e-10  # m; rigid_body, adaptive: local error tolerance on the eccentricity at E
    step_size: float = 2e-6  # s; fixed: the step (ideal joint: see exudyn_engine.solver); adaptive: unused
    spectral_radius: float = 0.8
    modified_newton: bool = True
    newton_relative_tolerance: float = 1e-8
    newton_max_iterations: int = 25
    callback: str = "auto"
    tree_solver: str = "auto"  # kinematic_tree: "explicit" (explicit_method), "implicit" (generalized-alpha), auto
    explicit_method: str = "DOPRI5"  # kinematic_tree only
    relative_tolerance: float = 1e-6  # kinematic_tree: error control of the explicit solver
    absolute_tolerance: float = 1e-9  # kinematic_tree: on joint angles (rad) and rates (rad/s)


@dataclass(frozen=True)
class Output:
    """Output sampling."""

    sample_angle: float = math.radians(0.5)  # crank angle between output samples, rad


@dataclass(frozen=True)
class CompareTolerance:
    """Agreement the two engines must reach (relative, see issue text / docs/physics.md section 6)."""

    first_contact_angle: float = math.radians(0.1)
    first_revolution_peaks: float = 0.01
    # Statistics over revolutions 2..N (N >= 10) are random draws of a chaotic impact sequence: one
    # engine's 10-revolution RMS/mean scatter by s <= 1.08 %, its 99th percentiles by s <= 2.62 %
    # (16-member ensemble, scripts/statistics_scatter.py).  Two engines differ by two draws: allow
    # 4 s sqrt(2), a 4-sigma event for correct engines (more revolutions allow less: the test uses 40).
    rms: float = 0.06
    percentile_99: float = 0.15
    ideal_curves: float = 1e-4


@dataclass(frozen=True)
class Limits:
    """Run-time failure criteria and budgets, checked by both engines (:mod:`weftsim.checks.guards`).

    A run that crosses one ends with ``status = "failed"``, a message saying what, when
    (time and crank angle) and what to try, and keeps what it computed up to then.
    docs/hard-cases.md gives the reasons for the defaults.

    Attributes
    ----------
    max_wall_time : float
        Wall-clock budget of one run, s; 0 = no limit.
    max_steps : int
        Budget of accepted solver steps; 0 = no limit.
    max_penetration : float
        Largest penetration delta allowed, as a fraction of the journal radius R_j.
        Beyond about a tenth of R_j the rigid bodies with a local contact compliance are
        no model of the joint any more (the journal would be flattened by R_j / 10).  The bound
        is the same for every law: it does not depend on the clearance, so a conformal law's
        delta of twice a small clearance (40 um at 20 um, a 30 mm pin under 30 kN: 0.003 R_j) is
        far inside it; the law's own range of delta / c is a warning (docs/plausibility.md).
    min_step : float
        Step-size collapse, s: the reference engine fails on an accepted step shorter
        than this; the Exudyn engine uses it as the floor of its step reduction after
        Newton failures.  Far below the ~1e-7 s that the stiffest impacts need.
    max_energy_error : float
        Largest residual of the energy balance W = dKE + dPE + E_contact + E_dissipated
        at any step, as a fraction of the largest kinetic energy of the run.  Sound runs
        stay below 1e-5; a step that does not resolve the impacts creates energy.
    max_rapier_acceleration : float
        Largest rapier acceleration a rapier head is built for, m/s^2 (default 3000: modern looms
        accelerate the giver rapier up to about 3000 m/s^2, Previdi, Savaresi & Volpi, American
        Control Conference 2006).  Above it: a warning, before the run from the ideal kinematics and
        after it from the run (docs/plausibility.md).
    max_damping_ratio : float
        Largest damping force, as a multiple of the law's xi times the elastic force:
        (F_N - F_el) / (xi F_el) = delta_dot / v_imp.  An isolated impact, the case the laws
        were derived for, stays within 1, and the default impact velocity rule
        ``max_approach`` keeps every step within 1: a step beyond it fails the run.  Under the
        ``onset`` rule a driven lasting contact exceeds it as a property of that model: a
        warning (:mod:`weftsim.checks.plausibility`).
    """

    max_wall_time: float = 0.0
    max_steps: int = 0
    max_penetration: float = 0.1
    min_step: float = 1e-12
    max_energy_error: float = 0.01
    max_damping_ratio: float = 1.0
    max_rapier_acceleration: float = 3000.0


@dataclass(frozen=True)
class Scene:
    """Everything one simulation needs; produced by :func:`weftsim.input.scene.load_scene`."""

    name: str = "reference"
    geometry: Geometry = field(default_factory=Geometry)
    inertia: Inertia = field(default_factory=Inertia)
    joint: ClearanceJoint = LOOM_JOINT_E  # joint E (rocker 3 - rod 4)
    # Joint F (rod 4 - sector 5): ideal unless a scene gives it a clearance (docs/clearance-f.md).
    joint_f: ClearanceJoint = field(default_factory=lambda: replace(LOOM_JOINT_E, clearance=0.0))
    drive: Drive = field(default_factory=Drive)
    duty: Duty = field(default_factory=Duty)
    reference_solver: ReferenceSolver = field(default_factory=ReferenceSolver)
    exudyn_solver: ExudynSolver = field(default_factory=ExudynSolver)
    output: Output = field(default_factory=Output)
    compare: CompareTolerance = field(default_factory=CompareTolerance)
    limits: Limits = field(default_factory=Limits)
    # The flexible rapier tape ([rapier_tape], docs/rapier-tape.md); None: the rigid rapier of mass m8.
    rapier_tape: RapierTape | None = None
    # The weft exchange with a taker head ([exchange], docs/rapier-tape.md section 7); None: no taker.
    exchange: Exchange | None = None
    source: str = ""
    # Keys of [joint_f] (without the table name) that F takes from [joint_e] because the scene does not
    # give them (weftsim.input.joint_keys); bookkeeping of how the scene was written, not part of the machine.
    joint_f_inherits: tuple[str, ...] = field(default=(), compare=False)

    @property
    def loose_joints(self) -> tuple[str, ...]:
        """Names of the joints with a clearance, in the order E, F: ``()`` is the ideal mechanism."""
        return tuple(name for name, joint in (("e", self.joint), ("f", self.joint_f)) if not joint.is_ideal)

    @property
    def is_ideal(self) -> bool:
        """True when every joint is ideal (no free coordinate: the closed form of docs/physics.md section 4)."""
        return not self.loose_joints
