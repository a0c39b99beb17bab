"""Performing a whole piece in one continuous simulation and recording what the piano sounded.

:func:`perform` runs a controller through the piece from the first step to the last (one
:func:`~pianobot.perform.rollout.rollout`) and returns what was played as a
:class:`~pianobot.music.piece.Piece`; :func:`write_video` encodes the frames.
"""

from __future__ import annotations

import errno
import os
import shutil
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.errors import one_line
from pianobot.files import check_writable, move_into_place, not_written
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Piece
from pianobot.perform.controllers import make_controller
from pianobot.perform.rollout import Controller, Rollout, rollout

PLAY_CONFIG = EnvConfig(tactile=False)
"""The environment for controllers that do not read touch (the scripted pianist, random actions)."""


def perform(
    piece: Piece,
    controller: str | Callable[[PianoEnv], Controller] = "scripted",
    config: EnvConfig = PLAY_CONFIG,
    seed: int = 0,
    video: bool = False,
    on_step: Callable[[int, int], None] | None = None,
    pedal: Pedal | None = None,
) -> Rollout:
    """Play ``piece`` from start to end in one continuous simulation.

    ``controller`` is 'scripted', 'random', or a function that makes a controller for the
    environment (compositional execution passes one). ``on_step(done, total)`` reports progress.
    ``pedal``: the piece's sustain pedal (the environment works it as written where the
    controller does not: ``EnvConfig.pedal_action``).
    """
    env = PianoEnv(piece=piece, config=config, render_mode="rgb_array" if video else None, pedal=pedal)
    try:
        agent = controller(env) if callable(controller) else make_controller(controller, env, seed)
        return rollout(env, agent, seed=seed, video=video, on_step=on_step)
    finally:
        env.close()


def write_video(frames: list[np.ndarray], path: str | Path, fps: float, audio: Path | None = None) -> Path:
    """Encode frames to an MP4 file (imageio with its ffmpeg plugin), written atomically; with
    ``audio`` (a WAV file starting with the first frame), the video carries it as an AAC track.

    ffmpeg writes into a temporary folder beside ``path``, removed however the writing ends: ffmpeg
    may still finish a file after an interruption (SIGTERM) has stopped the frames, and in a removed
    folder it can leave none."""
    import imageio.v2 as imageio  # only needed for videos

    path = check_writable(path)
    folder = None
    try:
        folder = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent))
        tmp = folder / f"video{path.suffix}"
        with imageio.get_writer(
            tmp, format="FFMPEG", fps=fps, codec="libx264", quality=7, macro_block_size=16, ffmpeg_log_level="quiet"
        ) as writer:
            for frame in frames:
                writer.append_data(frame)
        if frames and not _complete_mp4(tmp):  # ffmpeg may stop short (a full disk) without an error
            full = shutil.disk_usage(path.parent).free < 1_000_000
            raise OSError(errno.ENOSPC if full else errno.EIO, "the encoder stopped before the video was complete")
        if audio is not None:
            _add_audio(tmp, audio)
        move_into_place(tmp, path)
    except (OSError, RuntimeError) as e:  # imageio-ffmpeg raises these when ffmpeg or the disk fails
        raise not_written(path, e if isinstance(e, OSError) else OSError(None, str(e))) from None
    finally:
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
    return path


def _add_audio(video: Path, audio: Path) -> None:
    """Mux ``audio`` into the MP4 file ``video`` in place (ffmpeg from imageio-ffmpeg; the frames are copied)."""
    import subprocess

    import imageio_ffmpeg

    muxed = video.with_name(video.name + ".av.mp4")
    command = [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-loglevel", "error", "-i", str(video), "-i", str(audio),
               "-map", "0:v", "-map", "1:a", "-c:v", "copy", "-c:a", "aac", str(muxed)]  # fmt: skip
    try:
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0 or not _complete_mp4(muxed):
            raise OSError(errno.EIO, f"ffmpeg could not add the sound ({one_line(done.stderr.strip())[:200]})")
        os.replace(muxed, video)
    finally:
        muxed.unlink(missing_ok=True)


def _complete_mp4(path: Path) -> bool:
    """Whether an MP4 file's top-level boxes run exactly to its end and include the index ('moov')."""
    size, seen = path.stat().st_size, set()
    with open(path, "rb") as f:
        at = 0
        while at + 8 <= size:
            f.seek(at)
            header = f.read(16)
            length, kind = int.from_bytes(header[:4], "big"), header[4:8]
            if length == 1 and len(header) == 16:  # a 64-bit size follows
                length = int.from_bytes(header[8:16], "big")
            elif length == 0:  # the box runs to the end of the file
                length = size - at
            if length < 8:
                return False
            seen.add(kind)
            at += length
    return at == size and b"moov" in seen
