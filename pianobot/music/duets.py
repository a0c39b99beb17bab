"""Random two-hand pieces: a melody in the right hand over an accompaniment in the left (seeded;
pure music, no physics).

The right hand plays a random melody (:func:`pianobot.music.melodies.random_melody`) over C4–B5;
the left hand accompanies it in the same key below C4 (from F#1 up), bar by bar, on
a cadence (I, IV or ii, V, I, and again), in one of five textures drawn per piece:

- ``bass``: a bass line, one note a beat, on the chord's root, fifth or a step towards the next root;
- ``broken``: the chord broken in eighths, root, fifth, third, fifth (an Alberti bass);
- ``block``: the chord (root, third, fifth) held for two beats, on beats one and three;
- ``voices``: a held root with a moving voice above it, a quarter a beat (two voices in one hand);
- ``right-voices``: the bass line under a right hand in two voices: each half bar, a tone of the
  bar's chord held under the melody (:func:`_lower_voice`), where the melody stays a minor third
  to a fifth above it (where it does not, that half bar has none: about a sixth of these pieces
  have no lower voice at all).

Adding a texture changes what every seed draws (the textures are drawn from, and taken in turn
by, their number): ``right-voices`` came with the third version of the ``parts`` task family
(:data:`pianobot.music.tasks.VERSIONS`), and seeds drew other pieces before it.

Every note carries its hand; none carries a finger (the planner fingers each hand).
"""

from __future__ import annotations

import numpy as np

from pianobot.music.instrument import KeyboardSpec
from pianobot.music.melodies import MelodyKey, random_melody
from pianobot.music.piece import Note, Piece

TEXTURES = ("bass", "broken", "block", "voices", "right-voices")
RIGHT_KEYS = KeyboardSpec(60, 24)
"""Where the melody lies: C4–B5."""
LEFT_KEYS = KeyboardSpec(36, 24)
"""The accompaniment's octaves: its tonic is the key's in C2's octave, or the octave below from F#."""
OCTAVE = 12
LOWER_VOICE = (3, 7)
"""The right hand's lower voice lies at least a minor third below every melody note it sounds
under, and the melody at most a fifth above it (within the three fingers' reach)."""
LOWER_VOICE_FLOOR = 55
"""The lowest note of the right hand's lower voice (G3), and always above the piece's bass: the
hands never share a key or cross."""
BPM_RANGE = (60.0, 120.0)
BEATS_PER_BAR = 4
_CADENCES = ((0, 3, 4, 0), (0, 1, 4, 0), (0, 5, 3, 4))
"""Scale degrees of the bars' chords (0 = I, 1 = ii, 3 = IV, 4 = V, 5 = vi), repeated."""


def _triad(key: MelodyKey, degree: int) -> tuple[int, int, int]:
    """Root, third and fifth of the triad on ``degree``, counted from the tonic between F#1 and F2."""
    tonic = LEFT_KEYS.lowest + key.tonic - (OCTAVE if key.tonic >= 6 else 0)
    scale = [p for p in key.pitches(KeyboardSpec(tonic, 2 * OCTAVE))]
    return scale[degree], scale[degree + 2], scale[degree + 4]


def _bar(texture: str, chord: tuple[int, int, int], next_root: int, start: float, beat: float, velocity: int):
    root, third, fifth = chord
    if texture == "bass":
        step = next_root - 1 if next_root > root else next_root + 1
        line = (root, fifth, third if abs(third - step) > 2 else root, step)
        return [Note(start + i * beat, p, start + (i + 0.95) * beat, velocity) for i, p in enumerate(line)]
    if texture == "broken":
        pattern = (root, fifth, third, fifth) * 2
        return [Note(start + i * beat / 2, p, start + (i + 0.95) * beat / 2, velocity) for i, p in enumerate(pattern)]
    if texture == "block":
        return [
            Note(start + half * 2 * beat, p, start + (half + 0.95) * 2 * beat, velocity)
            for half in range(2)
            for p in (root, third, fifth)
        ]
    held = [Note(start, root, start + 3.95 * beat, velocity)]
    voice = (third, fifth, third + 12 if third + 12 <= LEFT_KEYS.highest else fifth, fifth)
    return held + [Note(start + i * beat, p, start + (i + 0.95) * beat, velocity) for i, p in enumerate(voice)]


def _lower_voice(
    melody: list[Note], chord: tuple[int, int, int], start: float, end: float, velocity: int, floor: int
) -> list[Note]:
    """The right hand's lower voice from ``start`` to ``end`` (a half bar): the highest tone of
    ``chord`` (any octave, not below ``floor``) at least a minor third under every melody note
    sounding then, held through, if the melody stays within a fifth above it; else none."""
    above = [n.pitch for n in melody if n.onset < end and n.offset > start]
    if not above:
        return []
    under, over = LOWER_VOICE
    tones = [p for p in range(floor, min(above) - under + 1) if any((p - c) % OCTAVE == 0 for c in chord)]
    if not tones or max(above) - tones[-1] > over:
        return []
    return [Note(start, tones[-1], start + 0.95 * (end - start), velocity)]


def random_duet(rng: np.random.Generator, texture: str | None = None, bpm: float | None = None) -> Piece:
    """One random two-hand piece (the module's notes); ``texture`` and ``bpm`` are drawn when None."""
    key = MelodyKey(int(rng.integers(12)), bool(rng.random() < 0.3))
    texture = texture or str(rng.choice(TEXTURES))
    if texture not in TEXTURES:
        raise ValueError(f"texture {texture!r}: choose one of {', '.join(TEXTURES)}")
    bpm = float(bpm if bpm is not None else round(rng.uniform(*BPM_RANGE)))
    melody = random_melody(rng, RIGHT_KEYS, key, bpm=bpm)
    beat = 60.0 / bpm
    bars = max(1, int(np.ceil(melody.duration / (beat * BEATS_PER_BAR))))
    cadence = _CADENCES[int(rng.integers(len(_CADENCES)))]
    velocity = int(rng.integers(40, 90))
    left: list[Note] = []
    chords = [_triad(key, cadence[bar % len(cadence)]) for bar in range(bars + 1)]
    for bar in range(bars):
        accompaniment = "bass" if texture == "right-voices" else texture
        left += _bar(accompaniment, chords[bar], chords[bar + 1][0], bar * BEATS_PER_BAR * beat, beat, velocity)
    lower: list[Note] = []
    if texture == "right-voices":
        floor = max(LOWER_VOICE_FLOOR, max(n.pitch for n in left) + 1)
        half = BEATS_PER_BAR * beat / 2
        for bar in range(bars):
            for t in (2 * bar * half, (2 * bar + 1) * half):
                lower += _lower_voice(list(melody.notes), chords[bar], t, t + half, velocity, floor)
    right = [Note(n.onset, n.pitch, n.offset, n.velocity, hand="right") for n in (*melody.notes, *lower)]
    return Piece(tuple(right + [Note(n.onset, n.pitch, n.offset, n.velocity, hand="left") for n in left]), bpm=bpm)


def duet_set(seed: int, count: int) -> list[tuple[str, Piece]]:
    """``count`` random two-hand pieces from ``seed``, the textures in turn, each named for what it is."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        texture = TEXTURES[i % len(TEXTURES)]
        piece = random_duet(rng, texture)
        out.append((f"duet {seed}-{i} ({texture}, {piece.bpm:.0f} bpm)", piece))
    return out
