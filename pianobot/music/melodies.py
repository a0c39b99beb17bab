"""Random single-voice melodies in every key: the scripted pianist's test set (pure music, no physics).

A melody is drawn from a NumPy generator, so a seed fixes it. It is written in one key (a tonic
and a major or minor scale; minor uses the harmonic minor's raised seventh now and then), moves
by repeated notes, scale steps, skips (a third) and leaps (a fourth up to an octave) within the
keyboard, in quarters, eighths, dotted quarters with their eighth, triplet eighths and halves,
with rests between phrases and notes, at 60–144 bpm, at velocities 20–127 (a phrase's dynamic
level with accents and swells around it). Notes carry no fingering: finger them with
:func:`pianobot.pianist.fingering.ensure_fingering`.

Keyword options widen or narrow the draw: ``velocities`` (the dynamics' range), ``chords``
(two-note chords), ``max_notes`` (a bound on the notes in all) and ``slurs`` (legato groups:
notes written to last until the next one sounds); :func:`random_phrase` uses the first three to
draw the phrases of the ``melody`` task family, :func:`articulation_set` the last for the test of
how long the pianist holds its notes. Left at their defaults they draw
exactly the melodies they always drew, so every seed keeps its melody.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from pianobot.music.instrument import KeyboardSpec
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.piece import Note, Piece, pitch_name

MAJOR = (0, 2, 4, 5, 7, 9, 11)
MINOR = (0, 2, 3, 5, 7, 8, 10)
TONICS = ("C", "C#", "D", "Eb", "E", "F", "F#", "G", "Ab", "A", "Bb", "B")
"""Key names by pitch class, as a musician spells them."""
BPM_RANGE = (60.0, 144.0)
VELOCITY_RANGE = (20, 127)
NOTE_RANGE = (8, 16)
CHORD_INTERVALS = ((2, 0.5), (3, 0.25), (4, 0.25))
"""The second note of a two-note chord: scale degrees above the melody's (a third, fourth or
fifth; below it where the keyboard ends), with their probabilities."""

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
    *,
    velocities: tuple[int, int] = VELOCITY_RANGE,
    chords: float = 0.0,
    max_notes: int | None = None,
    slurs: float = 0.0,
) -> Piece:
    """One random melody (see the module docstring); ``key``, ``notes`` (onsets) and ``bpm`` are
    drawn when None. ``velocities``: the (lowest, highest) velocity of its dynamics. ``chords``:
    the chance that a note gets a second note with it (:data:`CHORD_INTERVALS`), a two-note chord,
    while the melody holds fewer than ``max_notes`` notes in all (None: no bound on chords).
    ``slurs``: the chance that a note begins a slur (:func:`_slurred`)."""
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

    # dynamics: a level per phrase of 4-8 notes, accents and swells around it, within the velocity range
    low, high = velocities
    dynamics = []
    level = float(rng.uniform(low, high))
    swell = 0.0
    for i in range(count):
        if i > 0 and rng.random() < 0.18:
            level = float(rng.uniform(low, high))
            swell = float(rng.uniform(-6, 6))
        velocity = level + swell * (i % 8) + rng.normal(0, 6)
        if rng.random() < 0.12:
            velocity += float(rng.uniform(15, 35))  # an accent
        dynamics.append(int(np.clip(round(velocity), low, high)))

    # articulation: legato, normal or staccato, as a fraction of the time to the next onset
    out, time = [], 0.0
    for pitch, length, rest, velocity in zip(pitches, lengths, rests, dynamics):
        duration = length * beat
        fraction = float(rng.choice([0.95, 0.8, 0.5], p=[0.4, 0.45, 0.15]))
        out.append(Note(time, pitch, time + max(duration * fraction, 0.06), velocity))
        time += duration + rest * beat
    if slurs > 0:  # drawn after everything else, so that slurs=0 keeps every seed's melody
        out = _slurred(rng, out, rests, slurs)
    if chords > 0:  # the same
        out = _with_chords(rng, out, degrees, scale, chords, max_notes)
    return Piece(tuple(out), bpm=bpm)


SLUR_NOTES = (2, 8)
"""Fewest and most notes under one slur."""
REPEAT_FRACTION = 0.9
"""A repeated note under a slur lasts this fraction of the time to its repeat (the key must rise to sound again)."""


def _slurred(rng: np.random.Generator, melody: list[Note], rests: list[float], chance: float) -> list[Note]:
    """The melody with slurs: each note not yet under one begins a slur of :data:`SLUR_NOTES` notes
    with probability ``chance``; a slurred note lasts until the next onset (a repeated one
    :data:`REPEAT_FRACTION` of that); a rest (``rests``: beats after each note) ends the slur."""
    out, left = list(melody), 0
    for i, note in enumerate(melody[:-1]):
        if left == 0 and rng.random() < chance:
            left = int(rng.integers(SLUR_NOTES[0], SLUR_NOTES[1] + 1)) - 1
        if left == 0:
            continue
        left -= 1
        if rests[i] > 0:
            left = 0
            continue
        following = melody[i + 1]
        gap = following.onset - note.onset
        length = gap * (REPEAT_FRACTION if following.pitch == note.pitch else 1.0)
        out[i] = Note(note.onset, note.pitch, note.onset + length, note.velocity)
    return out


def _with_chords(
    rng: np.random.Generator, melody: list[Note], degrees: list[int], scale: list[int], chance: float, most: int | None
) -> list[Note]:
    """The melody with a second note (:data:`CHORD_INTERVALS`) sounding with some of its notes."""
    steps, weights = zip(*CHORD_INTERVALS)
    out = list(melody)
    for note, degree in zip(melody, degrees):
        if most is not None and len(out) >= most:
            break
        if rng.random() >= chance:
            continue
        step = int(rng.choice(steps, p=np.array(weights) / sum(weights)))
        other = degree + step if degree + step < len(scale) else degree - step
        out.append(Note(note.onset, scale[other], note.offset, note.velocity))
    return out


PHRASE_VELOCITY_RANGE = (30, 120)
"""Velocities of the ``melody`` task family's phrases."""
PHRASE_CHORDS = 0.25
"""The ``melody`` task family's chance that a note gets a second note with it (a two-note chord)."""


def random_phrase(
    rng: np.random.Generator,
    keyboard: KeyboardSpec = KeyboardSpec(),
    key: MelodyKey | None = None,
    max_notes: int = DEFAULT_MAX_NOTES,
) -> Piece:
    """One phrase of the ``melody`` task family (docs/training.md, "The melody task family"): a
    :func:`random_melody` of 1 to ``max_notes`` onsets (uniform), with two-note chords
    (:data:`PHRASE_CHORDS`) while it holds fewer than ``max_notes`` notes, at velocities
    :data:`PHRASE_VELOCITY_RANGE`; the key (``key``, else any of the 24), tempo, motion, rhythm and
    rests as :func:`random_melody` draws them. Unfingered, like every melody here."""
    onsets = int(rng.integers(1, max_notes + 1))
    return random_melody(
        rng,
        keyboard,
        key,
        notes=onsets,
        velocities=PHRASE_VELOCITY_RANGE,
        chords=PHRASE_CHORDS,
        max_notes=max_notes,
    )


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
