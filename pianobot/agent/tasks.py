"""Task families by name, as the environment takes them: a sampler that draws a fingered piece.

The paper's five families (:mod:`pianobot.music.tasks`) are fingered by construction. The
``parts`` family (:func:`draw_part`) draws one hand's whole part of a random two-hand piece. The ``melody`` family draws a phrase with :func:`pianobot.music.melodies.random_phrase` and fingers it
with the fingering planner (:mod:`pianobot.pianist.fingering`); a phrase the planner says this
hand cannot play (it reports problems, or raises an error) is drawn again, with the next draw of
the same generator, so the environment's seed fixes every instance. The environment cannot do
this itself: the planner lies above it (docs/architecture.md). Training, evaluation and a stored
policy's manifest (:func:`pianobot.agent.policy.policy_env`) all turn a target into an
environment with :func:`make_env`.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from pianobot.env.piano import EnvConfig, PianoEnv, Sampler
from pianobot.errors import PianobotError
from pianobot.music.duets import random_duet
from pianobot.music.instrument import check_playable
from pianobot.music.melodies import MelodyKey, random_phrase
from pianobot.music.piece import HANDS, Note, Piece
from pianobot.music.tasks import FAMILIES, MELODY, PARTS, TASKS, make_task
from pianobot.music.window import window_for
from pianobot.pianist.fingering import plan_fingering

MAX_DRAWS = 1_000
"""Draws of the ``melody`` family before giving up (the planner turns down about 1 in 8: docs/training.md)."""


def draw_melody(rng: np.random.Generator, config: EnvConfig = EnvConfig(), key: MelodyKey | None = None) -> Piece:
    """One instance of the ``melody`` family for the keyboard and hand of ``config``: the first
    :func:`~pianobot.music.melodies.random_phrase` from ``rng`` (in ``key``, else any) that the
    planner fingers without problems."""
    keyboard, hand = config.world.keyboard, config.world.hand
    for _ in range(MAX_DRAWS):
        phrase = random_phrase(rng, keyboard.spec, key)
        try:
            check_playable(phrase, keyboard.spec, hand.spec)
            plan = plan_fingering(phrase, keyboard, hand)
        except PianobotError:  # a chord wider than the hand, notes it cannot get to
            continue
        if not plan.problems:  # no note faster than this hand can play it
            return plan.piece
    raise PianobotError(
        f"no melody phrase in {MAX_DRAWS} draws that this hand can play on {keyboard.spec.describe()}: "
        "widen the keyboard or give the hand more fingers"
    )


PART_SHARE = 1.0
"""The share of the ``parts`` family's instances that are a hand's whole part of a two-hand piece;
the rest are ``melody`` instances. The family's first version drew half of each, and a phrase of
at most six notes of the part (docs/training.md, "The parts task family")."""


def draw_part(rng: np.random.Generator, config: EnvConfig = EnvConfig()) -> Piece:
    """One instance of the ``parts`` family (:data:`~pianobot.music.tasks.PARTS`): with chance
    :data:`PART_SHARE` one hand's whole part of a :func:`~pianobot.music.duets.random_duet`, given to
    this hand through its window as ``pianobot play`` gives it (:mod:`pianobot.music.window`: the
    left hand's part mirrored, both moved by octaves onto the keyboard; notes that still lie off it
    are left out), starting at 0, the first one the planner fingers without problems; else a
    ``melody`` instance. Whole parts, not phrases: the general policy plays a part as one stretch,
    so it must learn to go on from where the last chord left the hand."""
    if rng.random() >= PART_SHARE:
        return draw_melody(rng, config)
    keyboard, hand = config.world.keyboard, config.world.hand
    for _ in range(MAX_DRAWS):
        side = HANDS[int(rng.integers(len(HANDS)))]
        part = random_duet(rng).part(side)
        window = window_for(part, side, keyboard.spec)
        inside = [Note(n.onset, window.inward(n.pitch), n.offset, n.velocity) for n in part.notes]
        inside = [n for n in inside if n.pitch in keyboard.spec]
        if not inside:
            continue
        phrase = Piece(tuple(inside), bpm=part.bpm).shift(-inside[0].onset)
        try:
            check_playable(phrase, keyboard.spec, hand.spec)
            plan = plan_fingering(phrase, keyboard, hand)
            check_playable(plan.piece, keyboard.spec, hand.spec)  # no finger asked for two notes at once
        except PianobotError:  # a chord wider than the hand, notes it cannot get to
            continue
        if not plan.problems:
            return plan.piece
    raise PianobotError(
        f"no hand part in {MAX_DRAWS} draws that this hand can play on {keyboard.spec.describe()}: "
        "widen the keyboard or give the hand more fingers"
    )


def task_sampler(name: str, config: EnvConfig = EnvConfig()) -> Sampler:
    """The sampler of the task family ``name`` (one of :data:`~pianobot.music.tasks.FAMILIES`)
    in the environment ``config`` describes: a function from a generator to a fingered piece."""
    if name == MELODY:
        return partial(draw_melody, config=config)
    if name == PARTS:
        return partial(draw_part, config=config)
    if name in TASKS:
        return partial(make_task, name, keyboard=config.world.keyboard.spec)
    raise ValueError(f"unknown task {name!r}: choose one of {', '.join(FAMILIES)}")


def make_env(target: Piece | str, config: EnvConfig) -> PianoEnv:
    """The environment of a phrase (a Piece), or of a task family (its name): a fresh instance each episode."""
    if isinstance(target, str):
        return PianoEnv(sampler=task_sampler(target, config), config=config)
    return PianoEnv(piece=target, config=config)
