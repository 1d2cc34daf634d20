"""The rapier tape as Exudyn ANCF cable elements (docs/rapier-tape.md, section 5).

:func:`add_guided_tape` builds a free length of tape as ``ObjectANCFCable2D`` elements along x, the head as an
``ObjectMassPoint2D`` on its end node, clamped where it leaves the wheel.  The guide holds the tape straight: the
y positions and y slopes of every node are fixed.  At the root, position and direction are fixed, but not the
slope's length, which is 1 + the axial strain there; fixing it too clamps the strain to zero at the root and costs
an O(h) error, 1.5 % in the first frequency with 8 elements.  :func:`axial_frequencies` gives the eigenfrequencies
of that model (``mbs.ComputeODE2Eigenvalues`` on the unconstrained coordinates), the Exudyn side of the check
against beta L tan(beta L) = M / m.  With the root's strain free, one element meets the closed form within 1.2e-6,
two within 3.5e-8, four within 8e-10 (0.25-1.49 m, the default tape).

:func:`driven_head_acceleration` drives the root along the guide with a prescribed wheel motion s(t) (a coordinate
constraint with an offset user function) at a fixed free length: the Exudyn side of the engines' agreement on the
head's acceleration (tests/test_rapier_tape.py).  The tape driven by the linkage's rapier wheel over a growing
free length is :mod:`.tape_tree` (the variable-length Ritz bar on the kinematic tree).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

import exudyn as exu
from exudyn.beams import GenerateBeamElementsAlongLine
from exudyn.itemInterface import (MarkerNodeCoordinate, NodePointGround, ObjectANCFCable2D, ObjectConnectorCoordinate,
                                  ObjectMassPoint2D, SensorNode)

from weftsim.exudyn_engine.sensors import silence
from weftsim.input.params import RapierTape

# NodePoint2DSlope1 coordinates: x, y, slope x, slope y.
_X, _Y, _SLOPE_X, _SLOPE_Y = range(4)


def bending_stiffness(tape: RapierTape) -> float:
    """EI of the rectangular cross-section about its thin axis, N m^2 (the cable needs one; the guide holds the
    tape straight, so it does not enter the axial modes)."""
    return tape.axial_modulus * tape.width * tape.thickness**3 / 12.0


def add_guided_tape(mbs, tape: RapierTape, free_length: float, elements: int) -> tuple[list[int], list[int]]:
    """Add the free length as ``elements`` ANCF cables from the root at x = 0 to the head at x = free_length.

    Returns (cable node numbers from the root to the head, the coordinates the guide and the root fix as ODE2
    indices, after ``mbs.Assemble()``).
    """
    # Kelvin-Voigt: the cable's axial damping multiplies the axial strain rate, EA tau (N s).
    template = ObjectANCFCable2D(massPerLength=tape.mass_per_length, bendingStiffness=bending_stiffness(tape),
                                 axialStiffness=tape.axial_stiffness,
                                 axialDamping=tape.axial_stiffness * tape.damping_time)
    nodes = GenerateBeamElementsAlongLine(mbs, [0.0, 0.0, 0.0], [free_length, 0.0, 0.0], elements, template)["nodes"]
    mbs.AddObject(ObjectMassPoint2D(mass=tape.head_mass, nodeNumber=nodes[-1]))
    mbs.Assemble()
    fixed = []
    for i, node in enumerate(nodes):
        k = mbs.GetNodeODE2Index(node)
        fixed += [k + _X, k + _Y, k + _SLOPE_Y] if i == 0 else [k + _Y, k + _SLOPE_Y]
    return list(nodes), fixed


def axial_frequencies(tape: RapierTape, free_length: float, elements: int = 4) -> np.ndarray:
    """Axial natural frequencies (Hz, ascending) of the guided free length clamped at the wheel, head at its end."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    _, fixed = add_guided_tape(mbs, tape, free_length, elements)
    frequencies, _ = mbs.ComputeODE2Eigenvalues(constrainedCoordinates=fixed, convert2Frequencies=True)
    return np.sort(np.asarray(frequencies))


def driven_head_acceleration(tape: RapierTape, free_length: float, wheel: Callable[[float], float], end_time: float,
                             step: float, elements: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """The head's acceleration (s, m/s^2) with the root driven along the guide by ``wheel(t)`` = s (m).

    The guided free length of :func:`add_guided_tape`, its guide and root coordinates held by coordinate
    constraints, the root's x by one with an offset user function; generalized-alpha (spectral radius 0.9) at
    the fixed ``step``, modified Newton.
    """
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    nodes, _ = add_guided_tape(mbs, tape, free_length, elements)
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))

    def offset(mbs_, t, item, value):  # the root's x follows the wheel
        return wheel(t)

    for i, node in enumerate(nodes):
        for coordinate in ((_X, _Y, _SLOPE_Y) if i == 0 else (_Y, _SLOPE_Y)):
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
            driven = i == 0 and coordinate == _X
            mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, marker],
                                                    offsetUserFunction=offset if driven else 0))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], outputVariableType=exu.OutputVariableType.Acceleration,
                                      storeInternal=True, writeToFile=False))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = int(round(end_time / step))
    settings.timeIntegration.endTime = end_time
    settings.timeIntegration.generalizedAlpha.spectralRadius = 0.9
    settings.timeIntegration.newton.useModifiedNewton = True
    silence(settings)
    mbs.SolveDynamic(settings)
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    return data[:, 0], data[:, 1]
