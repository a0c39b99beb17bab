"""One episode played by a controller: reset, step to the end, record what the piano sounded.

Evaluation during training, ``pianobot play``, the benchmarks and the tests all play episodes
through :func:`rollout`, so they record and time notes the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from pianobot.env.piano import PianoEnv
from pianobot.music.metrics import Report, compare
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Piece
from pianobot.sim.recorder import NoteRecorder


class Controller(Protocol):
    """What plays an episode: the scripted pianist, the random controller and a trained policy alike."""

    def reset(self) -> None:
        """Called once at the start of every episode."""

    def act(self, observation: dict) -> np.ndarray:
        """An action in the environment's action space for this observation."""


@dataclass
class Rollout:
    """One episode: the piece it asked for, what the piano sounded, and what it earned."""

    reference: Piece
    played: Piece
    total_reward: float
    steps: int
    frames: list[np.ndarray] | None = None
    """Rendered images, first before the first step, when asked for."""
    start: float = 0.0
    """Simulated time (s) of the piece's time 0: the lead-in before it (the video's first frame is at 0)."""
    pedal: Pedal = Pedal()
    """The sustain pedal as the foot worked it, in the piece's time."""
    written_pedal: Pedal = Pedal()
    """The sustain pedal the piece asked for."""

    def report(self) -> Report:
        """Note F1, velocity and timing errors of ``played`` against ``reference`` (and the pedal's figures
        where either uses it)."""
        return compare(self.reference, self.played, pedals=(self.written_pedal, self.pedal))


def rollout(
    env: PianoEnv,
    controller: Controller,
    seed: int | None = None,
    video: bool = False,
    on_step: Callable[[int, int], None] | None = None,
) -> Rollout:
    """Play one episode of ``env`` (reset with ``seed``) with ``controller`` to its end.

    ``video`` keeps a rendered frame per step; ``on_step(done, total)`` reports progress."""
    observation, info = env.reset(seed=seed)
    controller.reset()
    recorder = NoteRecorder()
    frames = [env.render()] if video else None
    total, steps = 0.0, 0
    while True:
        now = env.world.time
        observation, reward, terminated, truncated, step = env.step(controller.act(observation))
        recorder.add(step["events"], step["fingers"])
        recorder.press(now, step["pedal"])
        total += reward
        steps += 1
        if frames is not None:
            frames.append(env.render())
        if on_step is not None:
            on_step(steps, env.horizon)
        if terminated or truncated:
            break
    reference = info["piece"]
    played = recorder.piece(end=env.world.time, start=env.score_start, bpm=reference.bpm)
    pedal = recorder.pedal(end=env.world.time, start=env.score_start)
    return Rollout(reference, played, total, steps, frames, env.score_start, pedal, env.pedal)
