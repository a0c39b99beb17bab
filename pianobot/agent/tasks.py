"""Task families by name, as the environment takes them: a sampler that draws a fingered piece.

The paper's five families (:mod:`pianobot.music.tasks`) are fingered by construction. The
``parts`` family (:func:`draw_part`) draws one hand's whole part of a random two-hand piece, or,
given :class:`GivenParts` (``pianobot train --task parts --pieces DIR``), a share of its instances
from hands' parts of real pieces. The ``melody`` family draws a phrase with :func:`pianobot.music.melodies.random_phrase` and fingers it
with the fingering planner (:mod:`pianobot.pianist.fingering`); a phrase the planner says this
hand cannot play (it reports problems, or raises an error) is drawn again, with the next draw of
the same generator, so the environment's seed fixes every instance. The environment cannot do
this itself: the planner lies above it (docs/architecture.md). Training, evaluation and a stored
policy's manifest (:func:`pianobot.agent.policy.policy_env`) all turn a target into an
environment with :func:`make_env`.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from pianobot.env.piano import EnvConfig, PianoEnv, Sampler
from pianobot.errors import PianobotError
from pianobot.music.duets import random_duet
from pianobot.music.instrument import check_playable
from pianobot.music.melodies import MelodyKey, random_phrase
from pianobot.music.piece import HANDS, Note, Piece
from pianobot.music.tasks import FAMILIES, GIVEN_SHARE, MELODY, PARTS, TASKS, make_task
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


@dataclass(frozen=True)
class GivenParts:
    """The ``parts`` family with hands' parts given to it (``pianobot train --task parts --pieces DIR``):
    a draw is with chance ``share`` one of ``parts`` (each one hand's part of a piece, fingered, on
    the keyboard and hand of the environment that draws it, as ``pianobot play`` gives it to that
    hand's player), else the family's own instance (:func:`draw_part`). ``about`` says where the parts
    came from (the manifest keeps it); :attr:`digest` names what is drawn."""

    parts: tuple[Piece, ...]
    share: float = GIVEN_SHARE
    about: dict = field(default_factory=dict, compare=False, hash=False)
    name: str = PARTS
    """The family a policy trained on these is (its manifest's ``target``)."""

    def __post_init__(self) -> None:
        if not self.parts:
            raise ValueError("no parts given: give at least one hand's part")
        if not 0 < self.share <= 1:
            raise ValueError(f"the share of given parts must lie in (0, 1]; got {self.share}")
        if any(n.finger is None for part in self.parts for n in part.notes):
            raise ValueError("every given part must be fingered")

    @property
    def digest(self) -> str:
        """12 hex digits of the parts' notes (pitch, times in ms, velocity, finger) and the share."""
        content = [
            [(n.pitch, round(n.onset * 1000), round(n.offset * 1000), n.velocity, n.finger) for n in part.notes]
            for part in self.parts
        ]
        return hashlib.sha256(json.dumps([self.share, content]).encode()).hexdigest()[:12]


PART_SHARE = 1.0
"""The share of the ``parts`` family's instances that are a hand's whole part of a two-hand piece;
the rest are ``melody`` instances. The family's first version drew half of each, and a phrase of
at most six notes of the part (docs/training.md, "The parts task family")."""


def draw_part(rng: np.random.Generator, config: EnvConfig = EnvConfig(), given: GivenParts | None = None) -> Piece:
    """One instance of the ``parts`` family (:data:`~pianobot.music.tasks.PARTS`): with chance
    :data:`PART_SHARE` one hand's whole part of a :func:`~pianobot.music.duets.random_duet`, given to
    this hand through its window as ``pianobot play`` gives it (:mod:`pianobot.music.window`: the
    left hand's part mirrored, both moved by octaves onto the keyboard; notes that still lie off it
    are left out), starting at 0, the first one the planner fingers without problems; else a
    ``melody`` instance. Whole parts, not phrases: the general policy plays a part as one stretch,
    so it must learn to go on from where the last chord left the hand. With ``given``, first: with
    chance ``given.share`` one of its parts, each as likely (without it, no draw is spent on this)."""
    if given is not None and rng.random() < given.share:
        return given.parts[int(rng.integers(len(given.parts)))]
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


Target = Piece | str | GivenParts
"""What a policy is trained on: a phrase, a task family (its name), or the ``parts`` family with given parts."""


def make_env(target: Target, config: EnvConfig) -> PianoEnv:
    """The environment of a phrase (a Piece), or of a task family (its name, or :class:`GivenParts`,
    whose parts must be playable on ``config``'s keyboard by its hand): a fresh instance each episode."""
    if isinstance(target, GivenParts):
        for part in target.parts:
            check_playable(part, config.world.keyboard.spec, config.world.hand.spec)
        return PianoEnv(sampler=partial(draw_part, config=config, given=target), config=config)
    if isinstance(target, str):
        return PianoEnv(sampler=task_sampler(target, config), config=config)
    return PianoEnv(piece=target, config=config)
