"""Animation of a run: the linkage, the journal in its clearance and the rapier over one revolution.

Projection
----------
The picture is the orthographic projection onto the plane x = 0 of the model frame
(docs/physics.md section 1), seen along axis D (+x) with y to the right and z up. That plane is the
plane of the four-bar O-E-F-G, so rocker arm OE, rod EF and sector arm FG appear at their true
lengths. The spherical 4R (members 0-3) turns about axes that meet at O; it is drawn as the
projections of the unit vectors of crank axis B, b(theta), and rocker axis C, c(phi), scaled to a
display length. Axis A (+z) lies in the plane; c(phi) = (0, cos phi, sin phi) lies in it too and keeps
its length, while b(theta) traces an ellipse. The rapier rack moves along y; it is drawn in a strip
below, at its displacement s::

        z ^          E (bearing on rocker 3, journal on rod 4: clearance drawn magnified)
          |        /  \\
          |  OE  /      \\  rod EF
          |    /          F
          |  /  C       /  sector arm FG
          O ---------- G ----> y        rapier:  |====[]=========|  s, positive into the shed

Where the points come from
--------------------------
Everything is read from the run's accepted solver steps (``result.steps``, the engine's own states;
the output samples of an engine may be interpolated between steps), so the picture shows what the
engine computed:
the crank angle theta = omega t gives the rocker angle phi(theta) (:func:`weftsim.mechanism.spherical.rocker_angle`)
and so the bearing centre P_b = L_OE u(theta_OE0 + phi); the eccentricity channels give the journal
centre P_j = P_b + e; the rapier displacement gives the sector angle
theta_FG = theta_FG(0) + s / (d5 d7 / d6) and so F = G + L_FG u(theta_FG), the centre of the sector's
eye. With a clearance at F the rod's pin there is P_jF = F + e_F (the F eccentricity channels), and the
rod is drawn from P_j to P_jF. The rod length ``|P_jF - P_j|`` is then a check of the engine's
closure, not an input (``weftsim animate`` reports it). Each joint with a clearance is drawn as its
clearance circle, magnified, with its journal centre; an ideal joint as a plain pin.
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from weftsim.mechanism.kinematics import fourbar, rocker_angle
from weftsim.post.results import RunResult
from weftsim.mechanism.spherical import crank_axis, rocker_axis

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from matplotlib.artist import Artist
    from matplotlib.figure import Figure

FORMATS = (".gif", ".mp4")
DEFAULT_FRAMES = 72  # one frame per 5 deg of crank: smooth enough, ~1 MB as a GIF
DEFAULT_FPS = 18  # a revolution in 4 s: the loom's motion slowed about 27x at 400 rpm
# At most this many frames: one per 0.25 deg of crank, finer than the 0.5 deg output samples they are
# drawn from.  Pillow holds every frame of a GIF until it writes the file (0.42 MB each at 700 x 600
# pixels: ~600 MB here), and each takes ~10 ms to draw.
MAX_FRAMES = 1440
FRAME_BYTES = 7.0 * 6.0 * 100.0**2  # one palette frame of the 7 x 6 in figure at 100 dpi


def check_frames(frames: int) -> None:
    """Refuse a frame count outside 2..:data:`MAX_FRAMES`, or one whose frames do not fit in memory.

    Raises ValueError with one line naming the limit.
    """
    from weftsim.post.npz_guard import available_memory

    if isinstance(frames, bool) or not isinstance(frames, int) or not 2 <= frames <= MAX_FRAMES:
        raise ValueError(f"--frames must be a whole number from 2 to {MAX_FRAMES} (one frame per 0.25 deg of crank; "
                         f"a GIF holds every frame in memory while it is written), got {frames!r}")
    available = available_memory()
    if available is not None and frames * FRAME_BYTES > available:
        raise ValueError(f"--frames {frames}: the frames need ~{frames * FRAME_BYTES / 1e6:.0f} MB of memory, more "
                         f"than the {available / 1e6:.0f} MB available; ask for fewer")
AXIS_DISPLAY_LENGTH = 0.5  # crank and rocker axes drawn at this fraction of L_OE


@dataclass(frozen=True)
class MechanismFrames:
    """Points of the mechanism at each frame, in the four-bar plane (model y, z), m.

    Attributes
    ----------
    time_s, crank_angle_deg : ndarray, shape (n,)
        Time of each frame and its crank angle within the revolution (0..360 deg).
    crank_axis_tip, rocker_axis_tip : ndarray, shape (n, 2)
        Projections of the crank axis b(theta) and the rocker axis c(phi), scaled to the display
        length ``axis_length``.
    bearing, journal : ndarray, shape (n, 2)
        Bearing centre P_b (point E of rocker 3) and journal centre P_j = P_b + e (point E of rod 4).
    point_f : ndarray, shape (n, 2)
        Joint F between rod 4 and sector 5: the centre of the sector's eye (the bearing at F).
    point_g : ndarray, shape (2,)
        Sector pivot G = (L_OG, 0).
    eccentricity : ndarray, shape (n, 2)
        e = P_j - P_b.
    in_contact : ndarray of bool, shape (n,)
        Whether the journal touches the bearing (the engine's contact flag).
    rapier_displacement : ndarray, shape (n,)
        s, m, positive into the shed.
    clearance, axis_length : float
        Radial clearance c at E and the display length of the axes, m.
    eccentricity_f : ndarray, shape (n, 2)
        e_F = P_jF - F at joint F (zero where F is ideal).
    in_contact_f : ndarray of bool, shape (n,)
        Whether the rod's pin touches the sector's eye at F.
    clearance_f : float
        Radial clearance at F, m (0: ideal joint).
    """

    time_s: np.ndarray
    crank_angle_deg: np.ndarray
    crank_axis_tip: np.ndarray
    rocker_axis_tip: np.ndarray
    bearing: np.ndarray
    journal: np.ndarray
    point_f: np.ndarray
    point_g: np.ndarray
    eccentricity: np.ndarray
    in_contact: np.ndarray
    rapier_displacement: np.ndarray
    clearance: float
    axis_length: float
    eccentricity_f: np.ndarray | None = None
    in_contact_f: np.ndarray | None = None
    clearance_f: float = 0.0

    @property
    def journal_f(self) -> np.ndarray:
        """The rod's pin at F, P_jF = F + e_F (F itself where the joint is ideal), m."""
        return self.point_f if self.eccentricity_f is None else self.point_f + self.eccentricity_f

    @property
    def rod_length(self) -> np.ndarray:
        """``|P_jF - P_j|`` at each frame, m: the closure check (L_EF for a consistent run)."""
        return np.hypot(*(self.journal_f - self.journal).T)

    def joints(self) -> list[tuple[str, float]]:
        """(name, clearance) of each joint with a clearance, E before F."""
        return [(name, c) for name, c in (("E", self.clearance), ("F", self.clearance_f)) if c > 0.0]


def _unit(angle) -> np.ndarray:
    return np.stack([np.cos(angle), np.sin(angle)], axis=-1)


def animated_window(result: RunResult) -> tuple[float, float]:
    """Times (s) of the revolution to animate: the last complete one, or the whole run if shorter."""
    from weftsim.post.analysis import complete_revolutions

    n = complete_revolutions(result)
    period = result.scene.drive.period
    if n >= 1:
        return (n - 1) * period, n * period
    return 0.0, float(result.steps["time_s"][-1])


def mechanism_frames(result: RunResult, frames: int = DEFAULT_FRAMES) -> MechanismFrames:
    """Positions of the mechanism's points at ``frames`` instants evenly spread over a revolution.

    The instants are accepted solver steps of the run (the nearest to an even spread over
    :func:`animated_window`; the last instant of the window is left out, as it repeats the first),
    so every point is an engine's state, not an interpolation (the output samples of the Exudyn
    engine's kinematic tree are interpolated between its steps: the rod length drawn from them is
    off by 3e-7 of L_EF, from the steps by round-off only).

    Parameters
    ----------
    result : RunResult
        A run with at least two accepted steps.
    frames : int
        Number of frames, >= 2.

    Returns
    -------
    MechanismFrames
    """
    if frames < 2:
        raise ValueError(f"frames must be >= 2, got {frames}")
    steps = result.steps
    t = steps["time_s"]
    if t.size < 2:
        raise ValueError(f"the run has {t.size} solver steps; an animation needs at least 2")
    scene = result.scene
    g = scene.geometry
    t0, t1 = animated_window(result)
    wanted = t0 + (t1 - t0) * np.arange(frames) / frames
    rows = np.clip(np.searchsorted(t, wanted), 1, t.size - 1)
    rows = np.where(np.abs(t[rows - 1] - wanted) <= np.abs(t[rows] - wanted), rows - 1, rows)
    time = t[rows]
    theta = scene.drive.speed * time
    phi = rocker_angle(theta, g.crank_inclination)[0]
    bearing = g.l_oe * _unit(g.rocker_arm_angle + phi)
    ecc = np.column_stack([steps["eccentricity_y_m"][rows], steps["eccentricity_z_m"][rows]])
    phi0 = rocker_angle(0.0, g.crank_inclination)[0]
    theta_fg0 = float(fourbar(g.rocker_arm_angle + phi0, g).theta_fg)  # s = 0 here (docs/physics.md section 1)
    theta_fg = theta_fg0 + steps["rapier_displacement_m"][rows] / g.rapier_ratio
    point_g = np.array([g.l_og, 0.0])
    length = AXIS_DISPLAY_LENGTH * g.l_oe
    loose_f = not scene.joint_f.is_ideal and "eccentricity_f_y_m" in steps
    ecc_f = (np.column_stack([steps["eccentricity_f_y_m"][rows], steps["eccentricity_f_z_m"][rows]]) if loose_f
             else np.zeros((rows.size, 2)))
    return MechanismFrames(
        time_s=time,
        crank_angle_deg=np.degrees(theta) % 360.0,
        crank_axis_tip=length * crank_axis(theta, g.crank_inclination)[:, 1:],
        rocker_axis_tip=length * rocker_axis(phi)[:, 1:],
        bearing=bearing,
        journal=bearing + ecc,
        point_f=point_g + g.l_fg * _unit(theta_fg),
        point_g=point_g,
        eccentricity=ecc,
        in_contact=steps["in_contact"][rows] > 0.5,
        rapier_displacement=steps["rapier_displacement_m"][rows],
        clearance=scene.joint.clearance,
        axis_length=length,
        eccentricity_f=ecc_f,
        in_contact_f=(steps["in_contact_f"][rows] > 0.5) if loose_f else np.zeros(rows.size, dtype=bool),
        clearance_f=scene.joint_f.clearance if loose_f else 0.0,
    )


def clearance_magnification(clearance: float, rod_length: float) -> float:
    """A round factor (1, 2 or 5 times a power of ten) that draws the clearance circle at about 8 %
    of the rod length: large enough to see the journal move, small enough to keep the linkage legible."""
    if clearance <= 0.0:
        return 1.0
    raw = 0.08 * rod_length / clearance
    decade = 10.0 ** math.floor(math.log10(raw))
    return max(1.0, max(m * decade for m in (1.0, 2.0, 5.0) if m * decade <= raw))


def _linkage_artists(ax, frames: MechanismFrames, magnification: float):
    """Draw the static parts and return a function that moves the rest to frame k."""
    from matplotlib.patches import Circle

    ax.plot([0.0, frames.point_g[0]], [0.0, 0.0], color="0.55", lw=3, solid_capstyle="round", zorder=1)
    ax.plot([0.0, 0.0], [0.0, frames.axis_length], color="0.55", lw=1, ls=":", zorder=1)
    ax.annotate("A (+z)", (0.0, frames.axis_length), fontsize=7, color="0.4", ha="center", va="bottom")
    for point, name in ((np.zeros(2), "O"), (frames.point_g, "G")):
        ax.plot(*point, marker="^", color="0.3", ms=9, zorder=4)
        ax.annotate(name, point, xytext=(0, -14), textcoords="offset points", ha="center", fontsize=9)
    crank, = ax.plot([], [], color="tab:purple", lw=1.2, ls="--", label="crank axis B (projected)")
    rocker, = ax.plot([], [], color="tab:green", lw=1.2, ls="--", label="rocker axis C")
    arm, = ax.plot([], [], color="tab:green", lw=4, solid_capstyle="round", label="rocker arm OE (3)")
    rod, = ax.plot([], [], color="tab:blue", lw=4, solid_capstyle="round", label="rod EF (4)")
    sector, = ax.plot([], [], color="tab:orange", lw=4, solid_capstyle="round", label="sector arm FG (5)")
    ecc_f = frames.eccentricity_f if frames.eccentricity_f is not None else np.zeros_like(frames.eccentricity)
    contact_f = frames.in_contact_f if frames.in_contact_f is not None else np.zeros(len(ecc_f), dtype=bool)
    # Per joint: its bearing centres, eccentricities, contact flags and clearance.
    joints = (("E", frames.bearing, frames.eccentricity, frames.in_contact, frames.clearance),
              ("F", frames.point_f, ecc_f, contact_f, frames.clearance_f))
    moving_joints = []
    for index, (name, centres, ecc, contact, clearance) in enumerate(joints):
        ring = Circle((0.0, 0.0), magnification * clearance, fill=False, color="k", lw=1.0, zorder=5)
        journal, = ax.plot([], [], marker="o", ms=6, color="tab:blue", ls="none", zorder=6,
                           label="journal centre (red: in contact)" if index == 0 else None)
        trail, = ax.plot([], [], color="tab:red", lw=0.7, alpha=0.6, zorder=5)
        if clearance > 0.0:
            ax.add_patch(ring)
            text = f"clearance at {name} x{magnification:g}"
        else:
            ring.set_visible(False)
            text = f"ideal joint {name}"
        label = ax.text(0.0, 0.0, text, fontsize=8, ha="left", va="bottom")
        moving_joints.append((centres, ecc, contact, clearance, ring, journal, trail, label))
    moving = (crank, rocker, arm, rod, sector) + tuple(a for j in moving_joints for a in j[4:])

    def move(k: int):
        e, j, f = frames.bearing[k], frames.journal[k], frames.journal_f[k]
        crank.set_data([0.0, frames.crank_axis_tip[k, 0]], [0.0, frames.crank_axis_tip[k, 1]])
        rocker.set_data([0.0, frames.rocker_axis_tip[k, 0]], [0.0, frames.rocker_axis_tip[k, 1]])
        arm.set_data([0.0, e[0]], [0.0, e[1]])
        rod.set_data([j[0], f[0]], [j[1], f[1]])
        sector.set_data([frames.point_f[k, 0], frames.point_g[0]], [frames.point_f[k, 1], frames.point_g[1]])
        for centres, ecc, contact, clearance, ring, journal, trail, label in moving_joints:
            drawn = centres[k] + magnification * ecc[max(k - 11, 0): k + 1]
            journal.set_data([drawn[-1, 0]], [drawn[-1, 1]])
            journal.set_color("tab:red" if contact[k] else "tab:blue")
            trail.set_data(drawn[:, 0], drawn[:, 1])
            ring.center = tuple(centres[k])
            label.set_position((centres[k][0] + 1.2 * magnification * clearance + 0.004, centres[k][1]))

    return move, moving


def _rapier_artists(ax, frames: MechanismFrames, stroke: float):
    ax.plot([0.0, stroke * 1e3], [0.0, 0.0], color="0.6", lw=6, solid_capstyle="butt")
    head, = ax.plot([], [], marker="s", ms=10, color="tab:red")
    rack, = ax.plot([], [], color="tab:red", lw=3)
    text = ax.text(0.99, 0.9, "", transform=ax.transAxes, ha="right", va="top", fontsize=8)
    ax.set_xlim(-0.05 * stroke * 1e3, 1.05 * stroke * 1e3)
    ax.set_ylim(-1.0, 1.0)
    ax.set_yticks([])
    ax.set_xlabel("rapier displacement s [mm] (along y, positive into the shed)")

    def move(k: int):
        s = frames.rapier_displacement[k] * 1e3
        head.set_data([s], [0.0])
        rack.set_data([min(0.0, s), s], [0.0, 0.0])
        text.set_text(f"s = {s:7.1f} mm")

    return move, (head, rack, text)


def animation_figure(result: RunResult, frames: MechanismFrames,
                     magnification: float | None = None) -> tuple[Figure, Callable[[int], None], tuple[Artist, ...]]:
    """The figure of the animation and a function ``draw(k)`` that puts it at frame k.

    Parameters
    ----------
    result : RunResult
        The run (scene, engine and clearance for the labels).
    frames : MechanismFrames
        From :func:`mechanism_frames`.
    magnification : float, optional
        Scale of the clearance drawing; default :func:`clearance_magnification`.

    Returns
    -------
    figure : matplotlib.figure.Figure
    draw : callable
        ``draw(k)`` moves every artist to frame k.
    moving : tuple of matplotlib artists
        The artists ``draw`` changes (marked animated: a full draw of the figure leaves them out, so
        the static rest is drawn once and each frame redraws only these).
    """
    from weftsim.mechanism.kinematics import linkage_state
    from weftsim.post.plots import figure

    scene = result.scene
    if magnification is None:  # one scale for both joints, set by the larger clearance
        magnification = clearance_magnification(max(frames.clearance, frames.clearance_f), scene.geometry.l_ef)
    fig = figure(figsize=(7.0, 6.0))
    grid = fig.add_gridspec(2, 1, height_ratios=(5, 1))
    ax, strip = fig.add_subplot(grid[0]), fig.add_subplot(grid[1])
    points = np.concatenate([frames.bearing, frames.point_f, frames.crank_axis_tip, frames.rocker_axis_tip,
                             [frames.point_g, np.zeros(2), (0.0, frames.axis_length)]])
    low, high = points.min(axis=0), points.max(axis=0)
    margin = 0.12 * (high - low).max()
    ax.set_xlim(low[0] - margin, high[0] + margin)
    ax.set_ylim(low[1] - margin, high[1] + margin)
    ax.set_aspect("equal")
    ax.grid(alpha=0.25)
    ax.set_xlabel("y [m]")
    ax.set_ylabel("z [m]")
    move_linkage, linkage = _linkage_artists(ax, frames, magnification)
    ax.legend(fontsize=7, loc="lower left", ncol=2)
    stroke = float(np.ptp(linkage_state(np.linspace(0.0, 2.0 * math.pi, 721), scene.geometry).rapier_displacement))
    move_rapier, rapier = _rapier_artists(strip, frames, stroke)
    rpm = scene.drive.speed * 30.0 / math.pi
    title = fig.suptitle("", fontsize=9)
    caption = (f"scene {scene.name}, engine {result.engine}, {rpm:g} rpm, {joint_caption(frames, magnification)}\n"
               "projection on the four-bar plane x = 0 (view along axis D)")
    flags = {"E": frames.in_contact, "F": frames.in_contact_f}
    if frames.clearance_f > 0.0 and frames.in_contact_f is None:
        raise ValueError("frames with a clearance at joint F need in_contact_f (its contact flags)")
    in_contact: dict[str, np.ndarray] = {name: flag for name, flag in flags.items() if flag is not None}

    def draw(k: int):
        move_linkage(k)
        move_rapier(k)
        states = [f"journal at {name} {'in contact' if in_contact[name][k] else 'free flight'}"
                  for name, _ in frames.joints()] or ["ideal joints"]
        title.set_text(f"{caption}\ncrank angle {frames.crank_angle_deg[k]:5.1f} deg, {', '.join(states)}")

    fig.tight_layout()
    draw(0)
    moving = linkage + rapier + (title,)
    for artist in moving:
        artist.set_animated(True)
    return fig, draw, moving


def joint_caption(frames: MechanismFrames, magnification: float) -> str:
    """``c = 0.25 mm at F (E ideal), drawn x50``: the joints with a clearance, as the picture draws them."""
    loose = frames.joints()
    if not loose:
        return "ideal joints at E and F"
    sizes = ", ".join(f"c = {c * 1e3:g} mm at {name}" for name, c in loose)
    ideal = [name for name in ("E", "F") if name not in dict(loose)]
    return f"{sizes}{f' ({ideal[0]} ideal)' if ideal else ''}, drawn x{magnification:g}"


def render_frames(fig: Figure, draw: Callable[[int], None], moving: tuple[Artist, ...],
                  count: int) -> Iterator[np.ndarray]:
    """Yield frame k = 0..count-1 as an RGB array (height, width, 3) of uint8.

    Blitting: the static figure is drawn once; each frame restores it and draws only the moving
    artists (a full redraw, dominated by the tick labels, took 6-8x longer per frame).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for k in range(count):
        canvas.restore_region(background)
        draw(k)
        for artist in moving:
            fig.draw_artist(artist)
        yield np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _gif(frames, fps: float, target: Path, comment: str = "") -> None:
    """Save RGB frames as one looping GIF (Pillow ships with matplotlib), ``comment`` in its comment extension."""
    from PIL import Image

    images = (Image.fromarray(rgb).quantize(colors=128, method=Image.Quantize.FASTOCTREE) for rgb in frames)
    first = next(images)
    extra = {"comment": comment.encode("utf-8")} if comment else {}
    # A generator: Pillow keeps its own copy of each frame until the file is written; a list here held a second.
    first.save(target, format="GIF", save_all=True, append_images=images, duration=int(round(1000.0 / fps)), loop=0,
               disposal=1, **extra)


def _mp4(frames, fps: float, target: Path, comment: str = "") -> None:
    """Pipe RGB frames to ffmpeg as H.264 in an MP4 container, ``comment`` in its comment tag."""
    import subprocess

    frames = iter(frames)
    first = next(frames)
    height, width = first.shape[:2]
    # libx264 with yuv420p needs even sizes: crop a pixel row or column if needed.
    height, width = height - height % 2, width - width % 2
    command = ["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}",
               "-r", f"{fps:g}", "-i", "pipe:", "-vcodec", "libx264", "-pix_fmt", "yuv420p",
               *(["-metadata", f"comment={comment}"] if comment else []), "-f", "mp4", str(target)]
    with subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE) as ffmpeg:
        stdin, stderr = ffmpeg.stdin, ffmpeg.stderr
        if stdin is None or stderr is None:  # never: both are pipes
            raise OSError("ffmpeg was started without its stdin and stderr pipes")
        for rgb in (first, *frames):
            stdin.write(np.ascontiguousarray(rgb[:height, :width]).tobytes())
        stdin.close()
        error = stderr.read().decode(errors="replace").strip()
    if ffmpeg.returncode:
        raise OSError(f"ffmpeg failed (exit {ffmpeg.returncode}): {error.splitlines()[-1] if error else 'no message'}")


def check_format(path: str | Path) -> str:
    """The animation format of ``path`` from its suffix: ``.gif`` always, ``.mp4`` where ffmpeg is found.

    Raises ValueError with one line naming the suffix and what is allowed.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"the animation file must end in .gif or .mp4, got {str(path)!r}")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise ValueError(f"cannot write {str(path)!r}: MP4 needs ffmpeg, which is not on PATH; use a .gif file")
    return suffix


def write_animation(result: RunResult, path: str | Path, frames: int = DEFAULT_FRAMES, fps: float = DEFAULT_FPS,
                    magnification: float | None = None, comment: str = "") -> MechanismFrames:
    """Write the animation of ``result`` over a revolution to ``path`` (.gif, or .mp4 with ffmpeg).

    The file is written atomically (:func:`weftsim.post.output.write_atomic`): a failed or interrupted
    write leaves no partial file.  ``comment`` goes into the file's own metadata (the GIF comment
    extension, the MP4 comment tag): the command line writes the resolved scene there
    (:func:`weftsim.post.record.scene_toml`), so a single animation file says how it was made.

    Parameters
    ----------
    result : RunResult
        The run to animate (its last complete revolution, or all of it if shorter).
    path : str or Path
        Output file; its suffix chooses the format.
    frames : int
        Frames over the revolution.
    fps : float
        Frames per second of the file.
    magnification : float, optional
        Scale of the clearance drawing; default :func:`clearance_magnification`.
    comment : str
        Text stored in the file's metadata; empty for none.

    Returns
    -------
    MechanismFrames
        The drawn points (for checks such as the rod length).
    """
    from weftsim.post.output import write_atomic

    suffix = check_format(path)
    check_frames(frames)
    if not fps > 0:
        raise ValueError(f"fps must be > 0, got {fps}")
    points = mechanism_frames(result, frames)
    fig, draw, moving = animation_figure(result, points, magnification)
    save = _gif if suffix == ".gif" else _mp4
    write_atomic(Path(path), lambda tmp: save(render_frames(fig, draw, moving, frames), fps, tmp, comment))
    return points
