"""The controllers ``pianobot play --controller`` names, besides trained policies.

- ``scripted``: :class:`~pianobot.pianist.scripted.ScriptedPianist`, the hand-written pianist;
- ``random``: :class:`RandomController`, uniform random actions (the paper's random baseline);
- ``idle``: :class:`IdleController`, zero actions: what a policy that presses nothing earns
  (a baseline of ``benchmarks/paper.py``, not offered by ``pianobot play``).

Each has the :class:`~pianobot.perform.rollout.Controller` interface, as a loaded policy does.
"""

from __future__ import annotations

import numpy as np

from pianobot.env.piano import PianoEnv
from pianobot.perform.rollout import Controller
from pianobot.pianist.scripted import ScriptedPianist

CONTROLLERS = ("sac", "scripted", "random")
"""Who can play: trained phrase policies (see :mod:`pianobot.perform.compose`), or one of :func:`make_controller`'s."""


class RandomController:
    """Uniform random actions in [-1, 1]."""

    def __init__(self, action_size: int, seed: int | None = None):
        self.action_size = action_size
        self.rng = np.random.default_rng(seed)

    def reset(self) -> None:
        pass

    def act(self, observation: dict) -> np.ndarray:
        return self.rng.uniform(-1.0, 1.0, self.action_size).astype(np.float32)


class IdleController:
    """Zero actions: under velocity control no joint moves, and the hand holds its starting pose
    above the keys."""

    def __init__(self, action_size: int):
        self.action = np.zeros(action_size, np.float32)

    def reset(self) -> None:
        pass

    def act(self, observation: dict) -> np.ndarray:
        return self.action


def make_controller(name: str, env: PianoEnv, seed: int | None = None) -> Controller:
    """The ``scripted``, ``random`` or ``idle`` controller for ``env``."""
    if name == "scripted":
        return ScriptedPianist(env.config)
    if name == "random":
        return RandomController(env.action_space.shape[0], seed=seed)
    if name == "idle":
        return IdleController(env.action_space.shape[0])
    raise ValueError(f"unknown controller {name!r}: make_controller knows 'scripted', 'random' and 'idle'")
