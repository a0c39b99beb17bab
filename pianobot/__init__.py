"""pianobot: teach a simulated dexterous robot hand to play the piano from real MIDI files.

The Python API (docs/api.md): the names below are imported on first use, so ``import pianobot``
stays quick (it registers the gymnasium ids ``pianobot/Piano-v1``, ``pianobot/OneNote-v1``, ...).

- :func:`load_piece` -- a ``.mid`` (or PIG) file as a validated :class:`Piece`;
- :class:`PianoEnv`, :class:`EnvConfig` -- the gymnasium environment;
- :func:`load_policy`, :func:`policy_configs` -- a stored policy and the environment it was trained in;
- :class:`ScriptedPianist` -- the hand-written pianist;
- :func:`play` -- a whole piece performed as ``pianobot play`` performs it (:func:`plan_performance`
  says who plays each stretch, :func:`perform_plan` plays a plan); a piece with both hands plays
  both, in one simulation (:func:`load_two_hands` reads a two-hand file);
- :func:`compare` -- note F1, velocity and timing errors of a performance against its score;
- :class:`Pedal`, :func:`read_pedal` -- the sustain pedal, and a file's (control change 64).
"""

from __future__ import annotations

import importlib

import pianobot.env  # noqa: F401  (registers the gymnasium ids)

__version__ = "0.1.0"

_API = {
    "Note": "pianobot.music.piece",
    "Piece": "pianobot.music.piece",
    "LoadOptions": "pianobot.music.load",
    "load_piece": "pianobot.music.load",
    "Pedal": "pianobot.music.pedal",
    "read_pedal": "pianobot.music.midi_io",
    "split_phrases": "pianobot.music.phrases",
    "compare": "pianobot.music.metrics",
    "PianoEnv": "pianobot.env.piano",
    "EnvConfig": "pianobot.env.piano",
    "ScriptedPianist": "pianobot.pianist.scripted",
    "load_policy": "pianobot.agent.policy",
    "policy_configs": "pianobot.agent.policy",
    "rollout": "pianobot.perform.rollout",
    "play": "pianobot.perform.together",
    "load_two_hands": "pianobot.pianist.assign",
    "plan_performance": "pianobot.perform.plan",
    "perform_plan": "pianobot.perform.plan",
}
__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'pianobot' has no attribute {name!r}")
