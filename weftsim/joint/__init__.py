"""Contact and lubrication laws of the revolute clearance joint.

:mod:`weftsim.joint.clearance` is the joint's geometry, normal and friction force,
:mod:`weftsim.joint.contact` the continuous contact force laws, :mod:`weftsim.joint.lubrication` the
channels of a lubricated joint and :mod:`weftsim.joint.reynolds` the finite-difference solution of
Reynolds' equation behind the film table.  The compiled physics every engine calls is written once in
:mod:`weftsim.physics`; these modules are its Python face, its laws' names and its tables.
"""
