"""The gymnasium environment (:mod:`pianobot.env.piano`) and its rewards (:mod:`pianobot.env.rewards`).

The ids ``pianobot/Piano-v1`` (give ``piece=``: a :class:`~pianobot.music.piece.Piece`, or the
path of a file to read as :func:`pianobot.load_piece` reads it) and one per task family
(``pianobot/OneNote-v1``, ``pianobot/ThreeNote-v1``, ...; :data:`VERSION`) are registered with gymnasium on
``import pianobot``; the simulator is imported only when ``gymnasium.make`` builds one. The
``melody`` family has no id: its phrases are fingered by the planner, above this layer;
``pianobot.agent.tasks.make_env("melody", config)`` makes its environment.

Every id's ``max_episode_steps`` is the longest episode the environment runs with the default
:class:`~pianobot.env.piano.EnvConfig` (it ends every episode itself, ``truncated``, after the
lead-in, the piece and a short tail): for a task family its longest instance, for
``pianobot/Piano-v1`` the longest piece pianobot reads. A ``config`` with a longer lead-in or
tail, or a faster control rate, runs longer episodes: pass ``max_episode_steps=`` to
``gymnasium.make`` then (it warns, with the number).
"""

from __future__ import annotations

import os
import warnings

import gymnasium as gym

from pianobot.music.piece import MAX_SECONDS
from pianobot.music.tasks import BPM, TASKS
from pianobot.music.tensor import ScoreSpec, steps_for

ENTRY_POINT = "pianobot.env:make_env"

VERSION = 1
"""The environments' version: the ``-v<N>`` of every gymnasium id, and the simulator a stored
policy records it was trained on (its manifest's ``simulator``). It goes up whenever the same
actions could play differently (physics, keyboard, hand, control rate, observations), as
Gymnasium versions its own environments, so that figures and policies of two versions are never
taken for one. What each version changed: :mod:`pianobot.env.piano`'s version history. The ids
of earlier versions are not registered: their physics is gone, and ``gymnasium.make`` of one
says so and names this version (Gymnasium's ``DeprecatedEnv``)."""

LONGEST_BEATS = {"one-note": 1, "three-note": 3, "six-note": 6, "rhythmic": 3, "chord": 3}
"""Beats in the longest instance of each task family (:func:`pianobot.music.tasks.make_task`)."""
DEFAULT_STEPS = {"control_hz": ScoreSpec.control_hz, "lead_in": 1.0, "tail": 0.25}
"""The default EnvConfig's control rate, lead-in and tail, for the registered ``max_episode_steps``
(lead-in and tail written here so that ``import pianobot`` need not import the simulator; a test
checks them against :class:`~pianobot.env.piano.EnvConfig`)."""


def longest_episode(seconds: float, control_hz: float, lead_in: float, tail: float) -> int:
    """Steps in an episode of a piece ``seconds`` long, as :class:`~pianobot.env.piano.PianoEnv` counts them."""
    spec = ScoreSpec(control_hz=control_hz)
    return steps_for(lead_in, spec) + steps_for(seconds + tail, spec)


def _longest_seconds(task: str | None) -> float:
    return MAX_SECONDS if task is None else LONGEST_BEATS[task] * 60.0 / BPM


def env_id(task: str) -> str:
    """The gymnasium id of a task family, e.g. 'three-note' -> 'pianobot/ThreeNote-v1'."""
    return "pianobot/" + "".join(part.capitalize() for part in task.split("-")) + f"-v{VERSION}"


PIECE_ID = f"pianobot/Piano-v{VERSION}"
"""The gymnasium id of the environment that plays a given piece."""


def make_env(piece=None, task: str | None = None, config=None, **kwargs):
    """The registered ids' entry point: :class:`~pianobot.env.piano.PianoEnv`, with ``piece``
    read from a file when it is a path."""
    from pianobot.env.piano import EnvConfig, PianoEnv

    if isinstance(piece, (str, os.PathLike)):
        from pianobot.music.load import load_piece

        piece = load_piece(piece)
    config = EnvConfig() if config is None else config
    longest = longest_episode(
        _longest_seconds(task) if piece is None else piece.duration,
        config.world.control_hz,
        config.lead_in,
        config.tail,
    )
    registered = longest_episode(_longest_seconds(task), **DEFAULT_STEPS)
    if longest > registered:
        warnings.warn(
            f"with this config an episode runs up to {longest} steps, past the id's max_episode_steps "
            f"{registered}: unless you gave it, pass max_episode_steps={longest} to gymnasium.make",
            stacklevel=2,
        )
    return PianoEnv(piece=piece, task=task, config=config, **kwargs)


def register_envs() -> None:
    """Register ``pianobot/Piano-v1`` and one id per task family (once)."""
    if PIECE_ID in gym.registry:
        return
    gym.register(id=PIECE_ID, entry_point=ENTRY_POINT, max_episode_steps=longest_episode(MAX_SECONDS, **DEFAULT_STEPS))
    for task in TASKS:
        gym.register(
            id=env_id(task),
            entry_point=ENTRY_POINT,
            kwargs={"task": task},
            max_episode_steps=longest_episode(_longest_seconds(task), **DEFAULT_STEPS),
        )


register_envs()
