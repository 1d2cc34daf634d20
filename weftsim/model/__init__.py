"""The shared model: the loom's equations turned into the kernel's numbers, below both engines.

Both engines build on it, neither owns it (issue 32): the reference engine integrates these equations,
the Exudyn engine's kinematic tree evaluates the same crank-side terms and chain constants beside its own
multibody model.

- :mod:`.dynamics`: the kernel parameter array of a scene (:func:`~.dynamics.pack_parameters`), the chain's
  constants, the initial state of the clearance coordinates (:func:`~.dynamics.initial_state`), the
  eccentricity and energy of the chain;
- :mod:`.ideal`: the crank side (members 1-3) in closed form, its equivalent inertia J13 and potential
  U13 and their derivatives, and the ideal mechanism's channels;
- :mod:`.stiffness`: which joint laws of a scene are stiff for an explicit integrator;
- :mod:`.channels`: the names of the channels every engine reports and their optional groups.
"""
