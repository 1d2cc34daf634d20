"""Model only what a scene needs: the rigid rapier or the flexible tape (``rapier_tape.model``).

The tape answers the wheel's motion like a spring-mass system of its first axial frequency f1: a drive
harmonic of order k (frequency k f_rev) reaches the head amplified by 1 / (1 - r_k^2), r_k = k f_rev / f1,
so the flexible head's acceleration departs from the rigid rapier's by about

    epsilon = sum_k |A_k| r_k^2 / |1 - r_k^2|  /  max |a|,

A_k the amplitudes of the ideal mechanism's rapier acceleration a(theta) over one revolution (its Fourier
series) and f1 the lowest first frequency over the stroke (the longest free length,
:func:`weftsim.model.tape.first_frequency`).  Under ``"auto"`` the rigid rapier serves when epsilon is below
:data:`RIGID_SERVES_BELOW`.  The estimate covers the drive's harmonics only: a clearance joint's impacts
excite the tape at any frequency, and the flexible model (``model = "flexible"``) shows what they do.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from weftsim.input.params import Scene
from weftsim.model.tape import first_frequency, rigid_equivalent, stroke, tape_of

# Relative departure of the head's acceleration from the rigid rapier's below which the rigid rapier serves:
# a tenth of the engines' agreement on first-revolution peaks (compare.first_revolution_peaks = 1 %).
RIGID_SERVES_BELOW = 1e-3
_HARMONIC_SAMPLES = 4096
_ROUND_OFF = 1e-9  # relative amplitude below which a harmonic is the FFT's round-off


def _ideal(scene: Scene) -> np.ndarray:
    """The ideal mechanism's rapier acceleration at the drive speed over one revolution, m/s^2."""
    from weftsim.mechanism.kinematics import rapier_motion

    theta = np.arange(_HARMONIC_SAMPLES) * (2.0 * math.pi / _HARMONIC_SAMPLES)
    return rapier_motion(theta, scene.drive.speed, scene.geometry)[2]


def drive_harmonics(scene: Scene) -> np.ndarray:
    """Amplitudes A_k (m/s^2, k = 0 .. N/2) of the ideal rapier acceleration over one revolution."""
    amplitude = np.abs(np.fft.rfft(_ideal(scene))) * (2.0 / _HARMONIC_SAMPLES)
    amplitude[0] *= 0.5
    return amplitude


def tape_check(scene: Scene) -> dict:
    """The tape against the drive: first frequencies over the stroke, epsilon, and whether the rigid rapier serves.

    Returns ``{"first_frequency_hz": [f1 at the longest free length, at the shortest], "drive_hz": f_rev,
    "harmonic_error": epsilon, "limit": RIGID_SERVES_BELOW, "rigid_serves": bool, "model": "rigid" or
    "flexible" (what the run takes), "reason": one line}``.
    """
    tape = tape_of(scene)
    f_rev = scene.drive.speed / (2.0 * math.pi)
    lengths = np.array([tape.free_length + stroke(scene), tape.free_length])
    f1 = first_frequency(tape, lengths)
    amplitude = drive_harmonics(scene)
    r2 = (np.arange(amplitude.size) * f_rev / f1[0]) ** 2
    peak = float(np.max(np.abs(_ideal(scene))))
    # Harmonics above the FFT's round-off; one at r >= 1/2 is near resonance: the estimate does not hold.
    present = amplitude > _ROUND_OFF * peak
    if np.any(present & (r2 >= 0.25)):
        error = math.inf
    else:
        error = float(np.sum(amplitude[present] * r2[present] / (1.0 - r2[present])) / peak)
    serves = error < RIGID_SERVES_BELOW
    chosen = tape.model if tape.model != "auto" else ("rigid" if serves else "flexible")
    verdict = "serves" if serves else "does not serve"
    reason = (f"tape's first axial mode {f1[0]:.0f}-{f1[1]:.0f} Hz over the stroke, drive {f_rev:.2f} Hz: the "
              f"drive's harmonics would move the head's acceleration by {error:.2e} of its peak "
              f"(limit {RIGID_SERVES_BELOW:g}), the rigid rapier {verdict}")
    if serves and not scene.joint.is_ideal:
        # Measured on loom_tape (600 rpm, c = 0.02 mm, revolution 2, both engines): the head's acceleration peaks
        # at -4941 and +5371 m/s^2 on the flexible tape against -5269 and +5236 on the rigid rapier, and -18344 /
        # +20948 against -5227 / +12441 over the start-up (docs/rapier-tape.md section 5).
        reason += ("; the estimate covers the drive only: the clearance joint's impacts excite the tape beyond it "
                   "(rapier_tape.model = 'flexible' for the head's accelerations)")
    if tape.model == "auto":
        reason += f"; rapier_tape.model = 'auto' takes the {chosen} model"
    else:
        reason += f"; rapier_tape.model = {tape.model!r}"
    return {"first_frequency_hz": [float(f1[0]), float(f1[1])], "drive_hz": f_rev, "harmonic_error": error,
            "limit": RIGID_SERVES_BELOW, "rigid_serves": serves, "model": chosen, "reason": reason}


@functools.lru_cache(maxsize=64)
def tape_model(scene: Scene) -> str | None:
    """What a run of ``scene`` models the rapier as: None (no ``[rapier_tape]``), "rigid" or "flexible"."""
    if scene.rapier_tape is None:
        return None
    return tape_check(scene)["model"]


def rigid_scene(scene: Scene) -> Scene:
    """The scene a run integrates: the rigid equivalent (:func:`weftsim.model.tape.rigid_equivalent`) when its
    tape runs as the rigid rapier, else ``scene`` itself."""
    return rigid_equivalent(scene) if tape_model(scene) == "rigid" else scene


def flexible_problem(scene: Scene) -> str | None:
    """Why the flexible tape cannot run on ``scene`` in this version (one line), or None."""
    what = []
    if scene.joint.is_ideal:
        what.append("a clearance at E (joint_e.clearance_mm > 0): with ideal joints nothing of the linkage is "
                    "integrated")
    if not scene.joint_f.is_ideal:
        what.append("joint F ideal (joint_f.clearance_mm = 0)")
    if scene.joint.is_worn or scene.joint.is_lubricated:
        what.append("a dry, round joint E (no [joint_e.lubrication], no wear profiles)")
    if not what:
        return None
    return ("the flexible rapier tape (rapier_tape.model = 'flexible', or 'auto' choosing it) needs "
            + " and ".join(what) + "; set rapier_tape.model = 'rigid' to run the tape as the rigid rapier")
