"""Performing a whole piece in one continuous simulation and recording what the piano sounded.

:func:`perform` runs a controller through the piece from the first step to the last (one
:func:`~pianobot.perform.rollout.rollout`) and returns what was played as a
:class:`~pianobot.music.piece.Piece`; :func:`write_video` encodes the frames.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.files import check_writable, move_into_place, temporary_beside
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
) -> Rollout:
    """Play ``piece`` from start to end in one continuous simulation.

    ``controller`` is 'scripted', 'random', or a function that makes a controller for the
    environment (compositional execution passes one). ``on_step(done, total)`` reports progress.
    """
    env = PianoEnv(piece=piece, config=config)
    try:
        agent = controller(env) if callable(controller) else make_controller(controller, env, seed)
        return rollout(env, agent, seed=seed, video=video, on_step=on_step)
    finally:
        env.close()


def write_video(frames: list[np.ndarray], path: str | Path, fps: float) -> Path:
    """Encode frames to an MP4 file (imageio with its ffmpeg plugin), written atomically."""
    import imageio.v2 as imageio  # only needed for videos

    path = check_writable(path)
    tmp = temporary_beside(path)
    try:
        with imageio.get_writer(
            tmp, format="FFMPEG", fps=fps, codec="libx264", quality=7, macro_block_size=16
        ) as writer:
            for frame in frames:
                writer.append_data(frame)
        move_into_place(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
