"""Mechanism kinematics: the weft insertion linkage with ideal joints, no simulation.

:mod:`weftsim.mechanism.spherical` is the spherical 4R (members 0-3), :mod:`weftsim.mechanism.kinematics`
the whole linkage (four-bar, sector gear, pinion and rapier) and its assembly, and
:mod:`weftsim.mechanism.pin_loads` the loads on the pins E and F from the kinematics alone (the design
checks' reflected mass and pin pressure).
"""
