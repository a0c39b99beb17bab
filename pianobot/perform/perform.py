"""Performing a whole piece in one continuous simulation and recording what the piano sounded.

:func:`perform` runs a controller (anything with ``reset()`` and ``act(observation)``) through
the piece from the first step to the last, collects the keyboard's note events with the finger
that touched each key, and returns them as a :class:`~pianobot.music.piece.Piece` beside the
score it was asked to play.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Protocol

import numpy as np

from pianobot.pianist.scripted import RandomController, ScriptedPianist
from pianobot.env.piano import JOINT_KINDS, EnvConfig, PianoEnv
from pianobot.errors import PianobotError
from pianobot.files import check_writable, move_into_place, temporary_beside
from pianobot.music.piece import Piece
from pianobot.sim.recorder import NoteRecorder

CONTROLLERS = ("sac", "scripted", "random")


class Controller(Protocol):
    def reset(self) -> None: ...

    def act(self, observation: dict) -> np.ndarray: ...


@dataclass
class Performance:
    """What was played, and the frames of the video if one was asked for."""

    played: Piece
    steps: int
    frames: list[np.ndarray] | None = None


def make_controller(name: str, env: PianoEnv, seed: int | None = None) -> Controller:
    """The scripted or random controller (``sac`` needs the model store: see pianobot.perform.compose)."""
    if name == "scripted":
        return ScriptedPianist(env.config)
    if name == "random":
        return RandomController(env.action_space.shape[0], seed=seed)
    raise PianobotError(f"--controller {name}: choose one of {', '.join(CONTROLLERS)}")


def perform(
    piece: Piece,
    controller: str | Callable[[PianoEnv], Controller] = "scripted",
    config: EnvConfig = EnvConfig(tactile=False, actuated=JOINT_KINDS),
    seed: int = 0,
    video: bool = False,
    on_step: Callable[[int, int], None] | None = None,
) -> Performance:
    """Play ``piece`` from start to end in one continuous simulation.

    ``controller`` is 'scripted', 'random', or a function that makes a controller for the
    environment (compositional execution passes one). ``on_step(done, total)`` reports progress.
    """
    env = PianoEnv(piece=piece, config=config)
    try:
        agent = controller(env) if callable(controller) else make_controller(controller, env, seed)
        observation, _ = env.reset(seed=seed)
        agent.reset()
        recorder = NoteRecorder()
        frames = [env.render()] if video else None
        steps = 0
        while True:
            observation, _, terminated, truncated, info = env.step(agent.act(observation))
            recorder.add(info["events"], info["fingers"])
            steps += 1
            if frames is not None:
                frames.append(env.render())
            if on_step is not None:
                on_step(steps, env.horizon)
            if terminated or truncated:
                break
        played = recorder.piece(end=env.world.time, start=env.score_start, bpm=piece.bpm)
        return Performance(played, steps, frames)
    finally:
        env.close()


def write_video(frames: list[np.ndarray], path: str | Path, fps: float) -> Path:
    """Encode frames to an MP4 file (imageio with its ffmpeg plugin), written atomically."""
    import imageio.v2 as imageio  # only needed for videos

    path = check_writable(path)
    tmp = temporary_beside(path)
    try:
        with imageio.get_writer(tmp, format="FFMPEG", fps=fps, codec="libx264", quality=7, macro_block_size=16) as writer:
            for frame in frames:
                writer.append_data(frame)
        move_into_place(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
