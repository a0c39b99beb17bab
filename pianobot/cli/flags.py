"""The one place that knows which option sets which setting.

The library names a setting by its field's dotted path (``load.tempo``, ``keyboard.count``,
``train.device``: see :class:`pianobot.errors.SettingError`); the command line writes the option
in its place in every error, warning and problem line it prints, so the user reads the flag they
typed: "load.tempo 0: choose a tempo between 10 and 1000 bpm" becomes "--tempo 0: choose a
tempo between 10 and 1000 bpm".
"""

from __future__ import annotations

import re

FLAGS = {
    "load.track": "--track",
    "load.tempo": "--tempo",
    "load.transpose": "--transpose",
    "load.fingering": "--fingering",
    "load.hand": "--hand",
    "load.split": "--split",
    "load.quantize": "--quantize",
    "load.refinger": "--refinger",
    "load.pedal": "--pedal",
    "keyboard.lowest": "--lowest-note",
    "keyboard.count": "--keys",
    "hand.fingers": "--thumb",
    "hand.model": "--hand-model",
    "phrases.max_notes": "--phrase-notes",
    "jobs.force": "--force",
    "train.device": "--device",
    "train.finish": "--finish",
    "train.dagger.round_steps": "--round-steps",
    "train.dagger.learning_rate": "--dagger-learning-rate",
    "store.models": "--models",
    "general.path": "--general-policy",
    "play.controller": "--controller",
    "play.general": "--policy none",
    "play.fallback": "--policy",
    "train.env.tactile": "--tactile/--no-tactile",
    "train.env.actuated": "--joints",
    "train.env.world.control": "--control",
    "train.env.world.keyboard.spec": "--lowest-note/--keys",
    "train.env.world.hand.spec": "--thumb",
    "train.env.reward.kind": "--reward",
    "train.env.reward.fingering_gate": "--fingering-gate/--no-fingering-gate",
    "train.sac.actor": "--actor",
    "train.sac.exploration_steps": "--exploration-steps",
    "train.steps": "--steps",
    "train.learner": "--learner",
    "train.pieces": "--pieces",
    "train.sac": "the agent's network settings (SACConfig)",
}
"""Setting (its dotted field path) -> the option that sets it. Training fields are ``train.``
and their path in :class:`~pianobot.learn.config.TrainConfig` (``train.env.world.control``), or
what ``pianobot train`` takes beside it (``train.pieces``: :func:`pianobot.learn.jobs.given_parts`)."""

_FIELD = re.compile(
    r"(?<![\w.])(" + "|".join(re.escape(f) for f in sorted(FLAGS, key=len, reverse=True)) + r")(?![\w.])"
)


def flag(field: str) -> str:
    """The option that sets ``field`` (the field itself where no option does)."""
    return FLAGS.get(field, field)


def phrase(text: object) -> str:
    """A library message as the command line says it: each setting it names as its option."""
    return _FIELD.sub(lambda match: FLAGS[match.group(1)], str(text))
