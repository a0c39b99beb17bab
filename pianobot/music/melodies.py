"""Random single-voice melodies in every key: the scripted pianist's test set (pure music, no physics).

A melody is drawn from a NumPy generator, so a seed fixes it. It is written in one key (a tonic
and a major or minor scale; minor uses the harmonic minor's raised seventh now and then), moves
by repeated notes, scale steps, skips (a third) and leaps (a fourth up to an octave) within the
keyboard, in quarters, eighths, dotted quarters with their eighth, triplet eighths and halves,
with rests between phrases and notes, at 60–144 bpm, at velocities 20–127 (a phrase's dynamic
level with accents and swells around it). Notes carry no fingering: finger them with
:func:`pianobot.pianist.fingering.ensure_fingering`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from pianobot.music.instrument import KeyboardSpec
from pianobot.music.piece import Note, Piece, pitch_name

MAJOR = (0, 2, 4, 5, 7, 9, 11)
MINOR = (0, 2, 3, 5, 7, 8, 10)
TONICS = ("C", "C#", "D", "Eb", "E", "F", "F#", "G", "Ab", "A", "Bb", "B")
"""Key names by pitch class, as a musician spells them."""
BPM_RANGE = (60.0, 144.0)
VELOCITY_RANGE = (20, 127)
NOTE_RANGE = (8, 16)

# rhythm cells in beats: each is played as a group of notes
_CELLS = (
    ((1.0,), 0.30),  # quarter
    ((0.5, 0.5), 0.28),  # two eighths
    ((1.5, 0.5), 0.12),  # dotted quarter and eighth
    ((1 / 3, 1 / 3, 1 / 3), 0.12),  # triplet eighths
    ((2.0,), 0.08),  # half
    ((0.5,), 0.10),  # a single eighth (syncopation)
)
# melodic motion in scale degrees: (kind, probability)
_MOTION = (("repeat", 0.12), ("step", 0.45), ("skip", 0.23), ("leap", 0.20))


@dataclass(frozen=True)
class MelodyKey:
    """A key: the tonic's pitch class (0 = C) and whether it is minor."""

    tonic: int
    minor: bool = False

    def __post_init__(self) -> None:
        if not 0 <= self.tonic <= 11:
            raise ValueError(f"tonic {self.tonic} must be a pitch class 0-11")

    @property
    def name(self) -> str:
        return f"{TONICS[self.tonic]} {'minor' if self.minor else 'major'}"

    def pitches(self, keyboard: KeyboardSpec, raised_seventh: bool = False) -> list[int]:
        """The scale's pitches on ``keyboard``, lowest first."""
        steps = list(MINOR if self.minor else MAJOR)
        if self.minor and raised_seventh:
            steps[6] = 11
        return [p for p in keyboard.pitches if (p - self.tonic) % 12 in steps]


def random_melody(
    rng: np.random.Generator,
    keyboard: KeyboardSpec = KeyboardSpec(),
    key: MelodyKey | None = None,
    notes: int | None = None,
    bpm: float | None = None,
) -> Piece:
    """One random single-voice melody (see the module docstring); ``key``, ``notes`` and ``bpm`` are drawn when None."""
    if key is None:
        key = MelodyKey(int(rng.integers(0, 12)), bool(rng.random() < 0.4))
    count = int(rng.integers(NOTE_RANGE[0], NOTE_RANGE[1] + 1)) if notes is None else notes
    bpm = float(round(rng.uniform(*BPM_RANGE))) if bpm is None else bpm
    beat = 60.0 / bpm
    scale = key.pitches(keyboard)
    if len(scale) < 8:
        raise ValueError(f"the keyboard {keyboard.describe()} is too small for a melody: give it an octave at least")

    # pitches: a walk over scale degrees, starting on a note of the tonic chord
    chord_tones = [i for i, p in enumerate(scale) if (p - key.tonic) % 12 in (0, 3, 4, 7)]
    degree = int(rng.choice(chord_tones))
    degrees = [degree]
    kinds, weights = zip(*_MOTION)
    while len(degrees) < count:
        kind = rng.choice(kinds, p=np.array(weights) / sum(weights))
        size = {"repeat": 0, "step": 1, "skip": 2, "leap": int(rng.integers(3, 8))}[str(kind)]
        direction = 1 if rng.random() < 0.5 else -1
        if not 0 <= degree + direction * size < len(scale):
            direction = -direction
        if 0 <= degree + direction * size < len(scale):
            degree += direction * size
            degrees.append(degree)
    pitches = []
    for d in degrees:
        pitch = scale[d]
        if key.minor and (pitch - key.tonic) % 12 == 10 and rng.random() < 0.5:  # harmonic minor's leading note
            pitch += 1 if pitch + 1 in keyboard else 0
        pitches.append(pitch)

    # rhythm: cells of beats, with a rest now and then
    cells, cell_weights = zip(*_CELLS)
    lengths: list[float] = []
    rests: list[float] = []  # the rest after each note (beats)
    while len(lengths) < count:
        cell = cells[int(rng.choice(len(cells), p=np.array(cell_weights) / sum(cell_weights)))]
        for length in cell[: count - len(lengths)]:
            lengths.append(length)
            rests.append(0.0)
        if rng.random() < 0.15:
            rests[-1] = float(rng.choice([0.5, 1.0]))

    # dynamics: a level per phrase of 4-8 notes, accents and swells around it, within 20-127
    low, high = VELOCITY_RANGE
    velocities = []
    level = float(rng.uniform(low, high))
    swell = 0.0
    for i in range(count):
        if i > 0 and rng.random() < 0.18:
            level = float(rng.uniform(low, high))
            swell = float(rng.uniform(-6, 6))
        velocity = level + swell * (i % 8) + rng.normal(0, 6)
        if rng.random() < 0.12:
            velocity += float(rng.uniform(15, 35))  # an accent
        velocities.append(int(np.clip(round(velocity), low, high)))

    # articulation: legato, normal or staccato, as a fraction of the time to the next onset
    out, time = [], 0.0
    for pitch, length, rest, velocity in zip(pitches, lengths, rests, velocities):
        duration = length * beat
        fraction = float(rng.choice([0.95, 0.8, 0.5], p=[0.4, 0.45, 0.15]))
        out.append(Note(time, pitch, time + max(duration * fraction, 0.06), velocity))
        time += duration + rest * beat
    return Piece(tuple(out), bpm=bpm)


def describe(piece: Piece) -> str:
    """One line: notes, tempo and pitch range, for tables and test ids."""
    low = min(n.pitch for n in piece.notes)
    high = max(n.pitch for n in piece.notes)
    return f"{len(piece)} notes at {piece.bpm:g} bpm, {pitch_name(low)}-{pitch_name(high)}"


@dataclass(frozen=True)
class SetMelody:
    """One melody of a test set: its key, its index in that key, the seed that drew it, and the piece."""

    key: MelodyKey
    index: int
    seed: tuple[int, int, int]
    """The generator's seed: (tonic, index, draw); draw counts the melodies ``accept`` turned down."""
    piece: Piece


def melody_set(
    per_key: int,
    accept: Callable[[Piece], Piece | None] = lambda piece: piece,
    keyboard: KeyboardSpec = KeyboardSpec(),
    max_draws: int = 50,
) -> list[SetMelody]:
    """``per_key`` melodies in each of the 12 keys (major and minor in turn), drawn with fixed seeds.

    ``accept`` returns the piece to keep (e.g. fingered), or None to draw again with the next
    seed (e.g. when the fingering planner says the hand cannot play it at that tempo)."""
    out = []
    for tonic in range(12):
        for index in range(per_key):
            key = MelodyKey(tonic, minor=(tonic + index) % 2 == 1)
            for draw in range(max_draws):
                kept = accept(random_melody(np.random.default_rng([tonic, index, draw]), keyboard, key))
                if kept is not None:
                    out.append(SetMelody(key, index, (tonic, index, draw), kept))
                    break
            else:
                raise RuntimeError(f"no acceptable melody in {key.name} after {max_draws} draws")
    return out
