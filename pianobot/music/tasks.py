"""The paper's task families as random, fingered pieces at 60 bpm (section "Learning to Play the Piano").

- one-note: one quarter note;
- three-note: three quarter notes;
- six-note: six quarter notes (the paper's figure uses this name);
- rhythmic: three notes whose lengths are drawn from quarter, eighth and triplet eighth;
- chord: three two-note chords.

Notes lie on white keys of the default keyboard, fingered for the three-finger hand: in one
hand position the index, middle and ring fingers lie over three neighbouring white keys, and
the hand moves at most :data:`MAX_SHIFT` white keys from one position to the next (a jump
across the whole keyboard between two legato notes is beyond what a 0.5 s score lookahead
lets a hand prepare). A task instance is drawn from a NumPy generator, so a seed fixes it.

Our ``melody`` family (random one-hand phrases in every key, :data:`MELODY`) and ``parts`` family
(:data:`PARTS`) need the fingering planner, so :mod:`pianobot.agent.tasks` draws them; this module
only names them.
"""

from __future__ import annotations

import numpy as np

from pianobot.music.instrument import KeyboardSpec
from pianobot.music.piece import Note, Piece

TASKS = ("one-note", "three-note", "six-note", "rhythmic", "chord")
"""The paper's task families, drawn by :func:`make_task`."""
MELODY = "melody"
"""Our family of realistic one-hand phrases (:func:`pianobot.music.melodies.random_phrase`). Its
instances are fingered by the fingering planner, which lies above the environment, so they are
drawn by :mod:`pianobot.agent.tasks` and handed to the environment as a sampler."""
PARTS = "parts"
"""Our family of one hand's parts as two-hand music gives them: a random two-hand piece's right or
left hand, whole (:mod:`pianobot.music.duets`: a melody, a melody over a held lower voice, a bass
line, broken or block chords, a held note under a moving voice), the left hand's mirrored onto the right's keys. Drawn, like
``melody``, by :mod:`pianobot.agent.tasks`."""
FAMILIES = TASKS + (MELODY, PARTS)
"""Every task family ``pianobot train --task`` trains on."""
VERSIONS = {PARTS: 3}
"""The version of each family whose instances changed meaning (a family not named is at version 1):
``parts`` 2 draws one hand's whole part, where 1 drew a phrase of at most six notes of it or a
melody phrase; 3 draws from five textures, the fifth a right hand in two voices (``right-voices``). A policy folder's key names a version after the first
(:func:`pianobot.agent.store.task_key`), so that a store keeps each version's policies apart."""
GIVEN_SHARE = 0.5
"""The share of a ``parts`` run's instances that are hands' parts of the files it is given
(``pianobot train --task parts --pieces DIR``, :class:`pianobot.agent.tasks.GivenParts`): the share
the packaged thumb's policy was trained with (models/README.md)."""
BPM = 60.0
FINGERS = (2, 3, 4)
MAX_SHIFT = 4
"""Most white keys the hand position moves between consecutive positions."""


def _white_keys(keyboard: KeyboardSpec) -> list[int]:
    return [p for p in keyboard.pitches if not KeyboardSpec.is_black(p)]


def _velocity(rng: np.random.Generator) -> int:
    return int(rng.integers(40, 111))


def _position(rng: np.random.Generator, count: int, previous: int | None) -> int:
    """Index of the white key under the index finger: anywhere at first, then near the previous one."""
    if previous is None:
        return int(rng.integers(0, count - 2))
    return int(rng.integers(max(0, previous - MAX_SHIFT), min(count - 3, previous + MAX_SHIFT) + 1))


def _melody(rng: np.random.Generator, keyboard: KeyboardSpec, beats: list[float]) -> Piece:
    whites = _white_keys(keyboard)
    notes, time, base = [], 0.0, None
    for i, length in enumerate(beats):
        if i % 3 == 0:  # a new hand position every three notes
            base = _position(rng, len(whites), base)
        slot = int(rng.integers(0, 3))
        duration = length * 60.0 / BPM
        notes.append(Note(time, whites[base + slot], time + duration, _velocity(rng), FINGERS[slot]))
        time += duration
    return Piece(tuple(notes), bpm=BPM)


def make_task(name: str, rng: np.random.Generator, keyboard: KeyboardSpec = KeyboardSpec()) -> Piece:
    """One random instance of a task family."""
    if name == "one-note":
        return _melody(rng, keyboard, [1.0])
    if name == "three-note":
        return _melody(rng, keyboard, [1.0] * 3)
    if name == "six-note":
        return _melody(rng, keyboard, [1.0] * 6)
    if name == "rhythmic":
        return _melody(rng, keyboard, [float(rng.choice([1.0, 0.5, 1.0 / 3.0])) for _ in range(3)])
    if name == "chord":
        whites = _white_keys(keyboard)
        notes, base = [], None
        for i in range(3):
            base = _position(rng, len(whites), base)
            velocity = _velocity(rng)
            notes += [
                Note(float(i), whites[base], i + 1.0, velocity, 2),
                Note(float(i), whites[base + 2], i + 1.0, velocity, 4),
            ]
        return Piece(tuple(notes), bpm=BPM)
    raise ValueError(f"unknown task {name!r}: choose one of {', '.join(TASKS)}")
