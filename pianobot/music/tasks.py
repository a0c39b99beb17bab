"""The paper's task families as random, fingered pieces at 60 bpm (section "Learning to Play the Piano").

- one-note: one quarter note;
- three-note: three quarter notes;
- six-note: six quarter notes (the paper's figure uses this name);
- rhythmic: three notes whose lengths are drawn from quarter, eighth and triplet eighth;
- chord: three two-note chords.

Notes lie on white keys of the default keyboard, fingered for the three-finger hand: in one
hand position the index, middle and ring fingers lie over three neighbouring white keys. A
task instance is drawn from a NumPy generator, so a seed fixes it.
"""

from __future__ import annotations

import numpy as np

from pianobot.music.instrument import KeyboardSpec
from pianobot.music.piece import Note, Piece

TASKS = ("one-note", "three-note", "six-note", "rhythmic", "chord")
BPM = 60.0
FINGERS = (2, 3, 4)


def _white_keys(keyboard: KeyboardSpec) -> list[int]:
    return [p for p in keyboard.pitches if not KeyboardSpec.is_black(p)]


def _velocity(rng: np.random.Generator) -> int:
    return int(rng.integers(40, 111))


def _melody(rng: np.random.Generator, keyboard: KeyboardSpec, beats: list[float]) -> Piece:
    whites = _white_keys(keyboard)
    notes, time = [], 0.0
    for i, length in enumerate(beats):
        if i % 3 == 0:  # a new hand position every three notes
            base = int(rng.integers(0, len(whites) - 2))
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
        notes = []
        for i in range(3):
            base = int(rng.integers(0, len(whites) - 2))
            velocity = _velocity(rng)
            notes += [Note(float(i), whites[base], i + 1.0, velocity, 2), Note(float(i), whites[base + 2], i + 1.0, velocity, 4)]
        return Piece(tuple(notes), bpm=BPM)
    raise ValueError(f"unknown task {name!r}: choose one of {', '.join(TASKS)}")
