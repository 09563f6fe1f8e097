"""A side view (x-z) of a particle-model run of the buoy, as an animated GIF or MP4.

Each frame draws the tank (floor and walls, full of water) at its displacement, the string from
the anchor on the tank floor through its beads (if any) to the attachment point, and the sphere:
a circle of its radius around the centre particle, a dot at the attachment point and a spoke
from the centre to the vertex that starts on top, so that the sphere's rotation shows. Every
position is read from the run's :class:`vinculo.Solution`; the tank from the run's tank
displacement.

Frames are taken at ``fps`` frames per second of simulated time (the animation plays in real
time), at the stored state nearest each frame time, over the last ``max_frames / fps`` seconds
of the run by default (the steady state), or from ``start`` on.

Coordinates as in :mod:`vinculo.buoy.model`: x along the shaking, z up, the anchor at the origin
of the tank floor. The tank is drawn centred on the anchor (where the anchor sits on the real
floor is not known; the fluid moves rigidly with the tank whatever its size).
"""

from __future__ import annotations

import math
import numbers
import os
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from vinculo.buoy.case import BuoyCase
from vinculo.buoy.model import ParticleRun
from vinculo.errors import InvalidInputError
from vinculo.io.output import checked_file, file_written_in_place

__all__ = ["SUFFIXES", "animate", "animate_frequency", "frame_indices", "mp4_available"]

#: The animation formats, by file suffix.
SUFFIXES = (".gif", ".mp4")


def frame_indices(
    times: np.ndarray, fps: float, max_frames: int, start: float | None = None
) -> np.ndarray:
    """The stored states an animation shows.

    Frame times are spaced ``1 / fps`` apart and end at the last stored time; each frame shows the
    stored state nearest its time (a state is shown once, so runs stored more coarsely than
    ``fps`` give fewer frames).

    Arguments:
        times: (s,) the run's stored times, increasing.
        fps: frames per second of simulated time (> 0).
        max_frames: the most frames to show (>= 1).
        start: the first frame time (s); None: as early as ``max_frames`` allows, and not
            before the first stored time.

    Returns:
        The increasing indices into ``times`` of the frames.

    Raises:
        InvalidInputError: ``fps`` is not finite and positive, ``max_frames`` is not a whole
            number >= 1, ``start`` is not within the run, or ``times`` is empty.
    """
    times = np.asarray(times, dtype=np.float64)
    if times.size == 0:
        raise InvalidInputError("the run holds no stored state to animate", name="times", value=0)
    if isinstance(fps, bool) or not (
        isinstance(fps, numbers.Real) and math.isfinite(fps) and fps > 0
    ):
        raise InvalidInputError(
            f"fps must be a finite positive number, got {fps!r}", name="fps", value=fps
        )
    if (
        isinstance(max_frames, bool)
        or not isinstance(max_frames, (int, np.integer))
        or max_frames < 1
    ):
        raise InvalidInputError(
            f"max_frames must be a whole number >= 1, got {max_frames!r}",
            name="max_frames",
            value=max_frames,
        )
    first, last = float(times[0]), float(times[-1])
    if start is None:
        start = max(first, last - (max_frames - 1) / fps)
    elif not (math.isfinite(start) and first <= start <= last):
        raise InvalidInputError(
            f"start = {start!r} s is outside the run ({first:g} to {last:g} s)",
            name="start",
            value=start,
        )
    count = min(int(max_frames), math.floor((last - start) * fps + 1e-9) + 1)
    frame_times = last - np.arange(count - 1, -1, -1, dtype=np.float64) / fps
    if times.size == 1:
        return np.zeros(1, dtype=np.int64)
    right = np.clip(np.searchsorted(times, frame_times), 1, times.size - 1)
    left = right - 1
    nearest = np.where(times[right] - frame_times < frame_times - times[left], right, left)
    return np.unique(nearest)


def mp4_available() -> bool:
    """Whether an ffmpeg program is at hand for MP4 files (on PATH, or from imageio-ffmpeg).

    Returns:
        True if :func:`animate` can write ``.mp4``.
    """
    return _ffmpeg() is not None


def _ffmpeg() -> str | None:
    """The path of an ffmpeg program, or None."""
    found = shutil.which("ffmpeg")
    if found:
        return found
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    try:
        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except RuntimeError:  # pragma: no cover - a broken imageio-ffmpeg install
        return None


def _require_ffmpeg(path: Path) -> str:
    """The ffmpeg program for an MP4 file, or an InvalidInputError naming the file."""
    program = _ffmpeg()
    if program is None:
        raise InvalidInputError(
            f"{str(path)!r}: writing .mp4 needs ffmpeg, which was not found (install ffmpeg or "
            f"the imageio-ffmpeg package), or use a .gif file",
            name="path",
            value=str(path),
        )
    return program


class _GifFile:
    """Frames collected as palette images and saved as one looping GIF."""

    def __init__(self, path: Path, fps: float) -> None:
        self.path = path
        self.duration = 1000.0 / fps
        self.frames: list[Any] = []

    def add(self, pixels: np.ndarray) -> None:
        from PIL import Image

        image = Image.fromarray(pixels[:, :, :3])
        self.frames.append(image.convert("P", palette=Image.Palette.ADAPTIVE, colors=128))

    def close(self) -> None:
        first, *rest = self.frames
        first.save(self.path, format="GIF", save_all=True, append_images=rest,
                   duration=self.duration, loop=0)


class _Mp4File:
    """Frames piped as raw RGBA to an ffmpeg process encoding H.264."""

    def __init__(self, path: Path, fps: float, program: str) -> None:
        self.path = path
        self.fps = fps
        self.program = program
        self.process: subprocess.Popen[bytes] | None = None

    def add(self, pixels: np.ndarray) -> None:
        if self.process is None:
            height, width = pixels.shape[:2]
            self.process = subprocess.Popen(
                [self.program, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba",
                 "-s", f"{width}x{height}", "-r", f"{self.fps:g}", "-i", "-",
                 "-c:v", "libx264", "-pix_fmt", "yuv420p", "-vf",
                 "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-f", "mp4", str(self.path)],
                stdin=subprocess.PIPE, stderr=subprocess.PIPE,
            )
        assert self.process.stdin is not None
        self.process.stdin.write(np.ascontiguousarray(pixels).tobytes())

    def close(self) -> None:
        assert self.process is not None
        _, errors = self.process.communicate()
        if self.process.returncode != 0:
            raise RuntimeError(
                f"ffmpeg failed writing {str(self.path)!r}: {errors.decode(errors='replace')}"
            )

    def abort(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def animate(
    run: ParticleRun,
    path: str | os.PathLike[str],
    *,
    case: BuoyCase | None = None,
    fps: float = 25.0,
    max_frames: int = 250,
    start: float | None = None,
    dpi: int = 80,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write a side view of a particle-model run as an animated GIF or MP4.

    The file is written under a temporary name in its folder and renamed to ``path`` when
    complete, so a failed or interrupted render leaves nothing under that name.

    Arguments:
        run: a run of :func:`vinculo.buoy.model.run_particle_model` (a run stopped early is
            animated up to where it stopped).
        path: the file to write: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg, see
            :func:`mp4_available`).
        case: the run's parameters, for the tank's size (default: the study's tank).
        fps: frames per second of simulated time, also the playback rate (real time).
        max_frames: the most frames (the default 250 at 25 fps shows the last 10 s of the run).
        start: the time of the first frame (s); None: the last ``max_frames`` frames.
        dpi: resolution of the 6 x 4.5 inch frames.
        progress: called as ``progress(done, total)`` after each frame.

    Returns:
        The path written.

    Raises:
        InvalidInputError: the suffix is not .gif or .mp4, the path is a folder or its folder does
            not exist, ``.mp4`` without ffmpeg, ``run`` is not a particle-model run (or carries
            no model), or a frame setting is out of range (see :func:`frame_indices`).
    """
    if not isinstance(run, ParticleRun) or run.model is None:
        raise InvalidInputError(
            "animate needs a ParticleRun from vinculo.buoy.model.run_particle_model, got "
            f"{type(run).__name__}",
            name="run",
            value=type(run).__name__,
        )
    target = checked_file(path, SUFFIXES, "animation file")
    suffix = target.suffix.lower()
    indices = frame_indices(run.time, fps, max_frames, start)
    program = _require_ffmpeg(target) if suffix == ".mp4" else ""
    case = case if case is not None else BuoyCase()
    _, render = _scene(run, case, dpi)
    with file_written_in_place(target) as temporary:
        sink = _Mp4File(temporary, fps, program) if program else _GifFile(temporary, fps)
        try:
            for done, index in enumerate(indices, start=1):
                sink.add(render(int(index)))
                if progress is not None:
                    progress(done, len(indices))
            sink.close()
        finally:
            if isinstance(sink, _Mp4File):
                sink.abort()
    return target


def _scene(
    run: ParticleRun, case: BuoyCase, dpi: int
) -> tuple[Any, Callable[[int], np.ndarray]]:
    """The figure, and a function that draws the stored state ``k`` and returns its RGBA pixels.

    The axes, ticks and labels are drawn once as a background; each frame restores it and draws
    only the moving artists (tank, water, string, sphere, time), which is several times faster
    than redrawing the figure.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Rectangle

    model = run.model
    assert model is not None
    positions = run.solution.positions
    centre = model.centre.index
    attachment = model.attachment.index
    beads = [b.index for b in model.beads]
    vertices = [v.index for v in model.body["vertices"]]
    initial = positions[0]
    radius = float(np.linalg.norm(initial[vertices[0]] - initial[centre]))
    top = vertices[int(np.argmax(initial[vertices, 2]))]
    width, _, height = case.tank_size
    tank = np.asarray(run.tank, dtype=np.float64)

    figure = Figure(figsize=(6.0, 4.5), dpi=dpi, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    margin = 0.02
    axes.set_xlim(float(tank.min()) - width / 2 - margin, float(tank.max()) + width / 2 + margin)
    axes.set_ylim(-margin, height + margin)
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("z (m)")
    axes.set_title(f"buoy in the shaken tank, f = {run.frequency:g} Hz (side view)")
    water = Rectangle((tank[0] - width / 2, 0.0), width, height, color="#cfe8f7", zorder=0)
    axes.add_patch(water)
    (walls,) = axes.plot([], [], color="0.25", linewidth=3.0, zorder=1)
    (string,) = axes.plot([], [], color="0.1", linewidth=1.2, marker=".", markersize=4, zorder=2)
    sphere = Circle((0.0, 0.0), radius, facecolor="#f29e4c", edgecolor="#8a4b12", zorder=3)
    axes.add_patch(sphere)
    (spoke,) = axes.plot([], [], color="#8a4b12", linewidth=1.5, zorder=4)
    (tie,) = axes.plot([], [], "o", color="#c0392b", markersize=5, zorder=5)
    (anchor,) = axes.plot([], [], "s", color="0.1", markersize=5, zorder=5)
    label = axes.text(0.02, 0.97, "", transform=axes.transAxes, va="top", family="monospace")
    moving = [water, walls, string, sphere, spoke, tie, anchor, label]
    for artist in moving:
        artist.set_animated(True)
    canvas = figure.canvas
    canvas.draw()  # the background: everything but the moving artists
    figure.set_layout_engine("none")
    background = canvas.copy_from_bbox(figure.bbox)

    def update(k: int) -> np.ndarray:
        x_t = float(tank[k])
        q = positions[k]
        water.set_x(x_t - width / 2)
        walls.set_data(
            [x_t - width / 2, x_t - width / 2, x_t + width / 2, x_t + width / 2],
            [height, 0.0, 0.0, height],
        )
        path = np.array([[x_t, 0.0], *(q[i, [0, 2]] for i in beads), q[attachment, [0, 2]]])
        string.set_data(path[:, 0], path[:, 1])
        sphere.set_center((float(q[centre, 0]), float(q[centre, 2])))
        spoke.set_data([q[centre, 0], q[top, 0]], [q[centre, 2], q[top, 2]])
        tie.set_data([q[attachment, 0]], [q[attachment, 2]])
        anchor.set_data([x_t], [0.0])
        label.set_text(
            f"t = {run.time[k]:7.2f} s\ntank x = {round(x_t * 1e3, 2) + 0.0:+6.2f} mm\n"
            f"buoy x = {round(q[centre, 0] * 1e3, 2) + 0.0:+6.2f} mm"
        )
        canvas.restore_region(background)
        for artist in moving:
            axes.draw_artist(artist)
        return np.array(canvas.buffer_rgba())

    return figure, update


def animate_frequency(
    case: BuoyCase,
    frequency: float,
    path: str | os.PathLike[str],
    *,
    t_end: float,
    dt: float = 2e-3,
    save_every: int = 5,
    simulation_progress: Callable[[float, float], None] | None = None,
    **options: Any,
) -> tuple[Path, ParticleRun]:
    """Run the particle model at one frequency from rest and animate the run.

    The path and the frequency are checked before the simulation starts.

    Arguments:
        case: the study's parameters.
        frequency: excitation frequency (Hz, > 0).
        path: the animation file (``.gif`` or ``.mp4``).
        t_end: duration of the run (s).
        dt: time step (s).
        save_every: keep every k-th step (the frames are taken from the kept states).
        simulation_progress: passed to :func:`vinculo.simulate` as ``progress``.
        **options: passed to :func:`animate` (``fps``, ``max_frames``, ``start``, ``dpi``,
            ``progress``).

    Returns:
        ``(path, run)``: the file written and the run it shows.

    Raises:
        InvalidInputError: the frequency is not finite and positive, or the path is not a
            writable ``.gif``/``.mp4`` file name (see :func:`animate`).
    """
    from vinculo.buoy.model import run_particle_model, tank_law

    if (
        isinstance(frequency, bool)
        or not isinstance(frequency, numbers.Real)
        or not (math.isfinite(frequency) and frequency > 0)
    ):
        raise InvalidInputError(
            f"the frequency to animate must be a finite positive number (Hz), got {frequency!r}",
            name="frequency",
            value=frequency,
        )
    tank_law(case, float(frequency))
    target = checked_file(path, SUFFIXES, "animation file")
    if target.suffix.lower() == ".mp4":
        _require_ffmpeg(target)  # fails now, not after the run, when ffmpeg is missing
    run = run_particle_model(
        case, float(frequency), t_end, dt=dt, save_every=save_every,
        progress=simulation_progress,
    )
    return animate(run, target, case=case, **options), run
