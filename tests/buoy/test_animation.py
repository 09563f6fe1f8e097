"""The side-view animation of a particle-model run."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import vinculo
from vinculo import cli
from vinculo.buoy import BuoyCase
from vinculo.buoy.animation import (
    _scene,
    animate,
    animate_frequency,
    frame_indices,
    mp4_available,
)
from vinculo.buoy.model import run_particle_model

# An abrupt start with a large table amplitude, so that the sphere moves visibly in 2 s.
CASE = BuoyCase(amplitude=0.02, ramp_periods=0.0)


@pytest.fixture(scope="module")
def run():
    return run_particle_model(CASE, 1.0, 2.0, dt=2e-3, save_every=5)


def gif_frames(path):
    with Image.open(path) as image:
        return image.n_frames


def test_gif_has_one_frame_per_frame_time(run, tmp_path):
    path = animate(run, tmp_path / "buoy.gif", case=CASE, fps=10, max_frames=12, dpi=40)
    assert path == tmp_path / "buoy.gif"
    # The last 12 frames at 10 per second: t = 0.9, 1.0, ..., 2.0 s (stored every 10 ms).
    assert gif_frames(path) == 12
    indices = frame_indices(run.time, 10, 12)
    np.testing.assert_allclose(run.time[indices], np.linspace(0.9, 2.0, 12), atol=1e-9)
    assert [p.name for p in tmp_path.iterdir()] == ["buoy.gif"]


def test_frame_times_from_start_and_progress(run, tmp_path):
    calls = []
    animate(run, tmp_path / "all.gif", case=CASE, fps=5, max_frames=100, start=0.0, dpi=30,
            progress=lambda done, total: calls.append((done, total)))
    # From t = 0 to 2 s at 5 per second: 11 frames, each reported.
    assert gif_frames(tmp_path / "all.gif") == 11
    assert calls == [(k, 11) for k in range(1, 12)]


def test_frames_draw_the_sphere_at_the_centre_particle(run):
    # The sphere's fill colour is centred on the centre particle's (x, z) in every frame.
    figure, update = _scene(run, CASE, dpi=60)
    axes = figure.axes[0]
    centre = run.model.centre.index
    seen = []
    for k in (0, len(run.time) - 1):
        pixels = update(k)[:, :, :3].astype(int)
        mask = (np.abs(pixels - [0xF2, 0x9E, 0x4C]).sum(axis=2) < 30)
        rows, columns = np.nonzero(mask)
        x, z = run.solution.positions[k, centre, [0, 2]]
        px, py = axes.transData.transform((x, z))
        height = pixels.shape[0]
        assert abs(columns.mean() - px) < 1.5 and abs(rows.mean() - (height - py)) < 1.5
        seen.append(columns.mean())
    # The centre moved by more than a few pixels between the two frames, and so did the disc.
    moved = run.solution.positions[-1, centre, 0] - run.solution.positions[0, centre, 0]
    scale = axes.transData.transform((1.0, 0.0))[0] - axes.transData.transform((0.0, 0.0))[0]
    assert abs(moved * scale) > 3
    assert seen[1] - seen[0] == pytest.approx(moved * scale, abs=1.5)


@pytest.mark.parametrize(
    "name, expected", [("buoy.avi", "unknown suffix"), ("missing/buoy.gif", "does not exist")]
)
def test_bad_paths_are_refused(run, tmp_path, name, expected):
    with pytest.raises(vinculo.InvalidInputError, match=expected) as info:
        animate(run, tmp_path / name, case=CASE)
    assert info.value.name == "path"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "options, name",
    [({"fps": 0.0}, "fps"), ({"max_frames": 0}, "max_frames"), ({"start": 5.0}, "start")],
)
def test_bad_frame_settings_are_refused(run, tmp_path, options, name):
    with pytest.raises(vinculo.InvalidInputError) as info:
        animate(run, tmp_path / "buoy.gif", case=CASE, **options)
    assert info.value.name == name
    assert list(tmp_path.iterdir()) == []


def test_only_particle_runs_are_animated(tmp_path):
    with pytest.raises(vinculo.InvalidInputError, match="ParticleRun") as info:
        animate(object(), tmp_path / "buoy.gif")
    assert info.value.name == "run"


@pytest.mark.parametrize("frequency", [0.0, -1.0, float("nan")])
def test_non_positive_frequency_is_refused_before_running(tmp_path, frequency):
    with pytest.raises(vinculo.InvalidInputError, match="frequency") as info:
        animate_frequency(CASE, frequency, tmp_path / "buoy.gif", t_end=1.0)
    assert info.value.name == "frequency"
    assert list(tmp_path.iterdir()) == []


def test_a_failed_render_leaves_no_file(run, tmp_path):
    def stop(done, total):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        animate(run, tmp_path / "buoy.gif", case=CASE, fps=10, max_frames=8, dpi=30,
                progress=stop)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not mp4_available(), reason="no ffmpeg for MP4 files")
def test_mp4_is_written_when_ffmpeg_is_available(run, tmp_path):
    path = animate(run, tmp_path / "buoy.mp4", case=CASE, fps=10, max_frames=5, dpi=40)
    assert path.stat().st_size > 1000
    assert [p.name for p in tmp_path.iterdir()] == ["buoy.mp4"]
    try:
        import imageio_ffmpeg
    except ImportError:  # pragma: no cover - ffmpeg from PATH: no frame counter at hand
        return
    frames, seconds = imageio_ffmpeg.count_frames_and_secs(str(path))
    assert frames == 5 and seconds == pytest.approx(0.5)


def test_cli_animate_writes_the_gif(tmp_path, capsys):
    out = tmp_path / "out"
    code = cli.main(["buoy", "--animate", "1.0", "--output", str(out), "--settle-periods", "1",
                     "--fit-periods", "1", "--animation-frames", "6", "--no-progress"])
    assert code == 0
    assert gif_frames(out / "buoy_1Hz.gif") == 6
    assert "animation:" in capsys.readouterr().out


@pytest.mark.parametrize(
    "arguments, expected",
    [(["--animate", "0"], "--animate"), (["--animate", "-2"], "--animate"),
     (["--animate", "1", "--animation-file", "x.avi"], "unknown suffix")],
)
def test_cli_bad_animation_arguments_exit_with_code_2(tmp_path, capsys, arguments, expected):
    with pytest.raises(SystemExit) as info:
        cli.main(["buoy", "--output", str(tmp_path), "--no-progress", *arguments])
    assert info.value.code == 2
    assert expected in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
