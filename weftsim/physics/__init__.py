"""The physics of weftsim, written once as scalar functions that numba compiles.

Every engine and route evaluates the same definitions:

- :mod:`.laws`: the contact force laws (stiffness, elastic force, normal force, damping
  coefficient, elastic energy) and the friction ramp, on the law's numbers (law id, coefficient,
  clearance, hysteresis factor);
- :mod:`.hold`: the impact-velocity rules (held value, the ``"max_approach"`` raise, the onset
  interpolated inside a step, the floor, the damping dead zone of resting contact);
- :mod:`.joint`: the force of the clearance joint from its eccentricity (normal force, friction,
  moments), and the connector force of the Exudyn callbacks;
- :mod:`.chain`: the 2-DOF chain (members 4-8) driven by the prescribed crank side, its
  right-hand side, eccentricity and penetration, on one parameter array;
- :mod:`.chain_f`: the chains with a clearance at F (F alone: 2 DOF; E and F: 4 DOF, the rod free),
  and the right-hand side and penetration of any topology (E alone is :mod:`.chain` unchanged);
- :mod:`.film`: the oil film of a lubricated joint (short, long and finite journal bearing: film
  force from the eccentricity, its rate and the two spins, with cavitation; film friction torques);
- :mod:`.roots`: the event search of the reference engine on a step's dense output (Illinois root
  finder, golden-section maximum, first rising crossing, peak of the approach rate);
- :mod:`.python`: the plain-Python form of any of these (same source, no compilation) and the
  compiled specialization of the event search to a dense output.

Each function is ``@njit(cache=True, error_model="numpy")``: the compiled paths call it from
compiled code (one compilation per machine, loaded from numba's cache afterwards); plain Python
callers that run off the hot path call the same source in plain Python (:mod:`.python`: no
compilation), and array callers map it over their elements.  A fix to the physics lands in one place.
"""
