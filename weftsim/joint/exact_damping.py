"""The exact damping of round restitutions, solved once: :func:`weftsim.joint.contact.exact_hysteresis`'s roots.

``EXACT_HYSTERESIS[ce]`` is the root xi of phi(-xi ce) = phi(xi), phi(z) = z - ln(1 + z), for ce = 0.05, 0.10,
..., 0.95, exactly as :func:`weftsim.joint.contact.solve_exact_hysteresis` (scipy's ``brentq``) returns it.  A
run of the cylindrical law at one of these restitutions (every bundled scene: 0.9) reads its root here instead
of importing ``scipy.optimize`` for one root: that import was 0.35-0.38 s of CPU, a third of the target of a
``weftsim run`` (docs/performance.md, "The first second").  Any other ce is solved as before.

The values are the solver's to the last bit (tests/test_cylindrical.py solves each again and compares them
exactly), so a run reads the same damping either way; regenerate them with::

    python -c "from weftsim.joint.contact import solve_exact_hysteresis as s; [print(f'{c!r}: {s(c)!r},') for c in
    (float(f'{0.05 * k:.2f}') for k in range(1, 20))]"
"""

from __future__ import annotations

EXACT_HYSTERESIS: dict[float, float] = {
    0.05: 19.999999681532362,
    0.1: 9.998159397495668,
    0.15: 6.642131672809698,
    0.2: 4.919166715790786,
    0.25: 3.8408060397780144,
    0.3: 3.0870819811296246,
    0.35: 2.523377705951347,
    0.4: 2.082498164147007,
    0.45: 1.726670194242525,
    0.5: 1.432750533271375,
    0.55: 1.1856141261279551,
    0.6: 0.9748717108132653,
    0.65: 0.7931009088580948,
    0.7: 0.6348282812664174,
    0.75: 0.4959113182344873,
    0.8: 0.37314620336505355,
    0.85: 0.26400940608340956,
    0.9: 0.1664819506853082,
    0.95: 0.07892660528741537,
}
