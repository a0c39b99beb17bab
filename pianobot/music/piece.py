"""Immutable notes and pieces.

A :class:`Note` is a pitch sounding from ``onset`` to ``offset`` (seconds) at a MIDI velocity,
optionally with the pianist's finger number (1 thumb ... 5 little finger) and the hand that plays
it ('right' or 'left'; None where nobody has said). A :class:`Piece` is
a sorted tuple of notes. Both are frozen and validated on construction; every transform returns
a new object and never touches the one it was called on.

Times are kept in whole milliseconds (rounded on construction). One millisecond is far below
the 50 ms control step and the 50 ms onset tolerance of the metrics, and it makes
``read(write(piece)) == piece`` exact: pianobot writes MIDI files with 1 ms ticks.
"""

from __future__ import annotations

import math
import numbers
import re
import warnings
from collections import defaultdict
from dataclasses import dataclass, field, replace
from typing import Iterable, Sequence

from pianobot.errors import PianobotError, PianobotWarning, SettingError, quote

FINGER_NAMES = {1: "thumb", 2: "index", 3: "middle", 4: "ring", 5: "little"}
HANDS = ("right", "left")
"""The hands a note can be given to; a note's ``hand`` is one of these or None (unassigned)."""
MIRROR_AXIS = 124
"""The keyboard's black and white keys lie symmetrically about D (pitch 62, and every D):
pitch ``p`` and ``MIRROR_AXIS - p`` are both white or both black, and their neighbours lie at the
same distances. A left hand's part mirrored this way is a right hand's part (see :func:`mirror_pitch`)."""
_NAMES = ("C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B")
_LETTER = {"C": 0, "D": 2, "E": 4, "F": 5, "G": 7, "A": 9, "B": 11}
TIME_RESOLUTION = 1e-3
"""Note times are rounded to this many seconds (1 ms)."""
MAX_SECONDS = 3600.0
"""The longest piece pianobot reads: every note ends within 60 minutes. It bounds what a file can
ask for (the score tensor, the simulation, the metrics grow with the piece's length), whatever
its times say; a longer piece is cut into parts (e.g. with ``load.track``) or re-timed with ``load.tempo``."""


def pitch_name(pitch: int) -> str:
    """MIDI pitch number to scientific pitch name with sharps: 60 -> 'C4', 61 -> 'C#4'."""
    return f"{_NAMES[pitch % 12]}{pitch // 12 - 1}"


def parse_pitch(name: str) -> int:
    """Scientific pitch name to MIDI number: 'C4' -> 60, 'Eb4' / 'E-4' -> 63, 'C#4' -> 61.

    Also accepts a plain MIDI number ('60').
    """
    text = name.strip()
    if re.fullmatch(r"-?[0-9]+", text):
        value = int(text) if len(text) <= 10 else 1 << 40  # far outside the range, without reading 5,000 digits
    else:
        if not text or text[0].upper() not in _LETTER:
            raise PianobotError(f"'{quote(name)}' is not a pitch: write it like C4, F#3, Bb5 or a MIDI number 0-127")
        value = _LETTER[text[0].upper()]
        # the octave is the trailing number; "-1" at the end is octave -1 (C-1 = 0), not a flat
        match = re.fullmatch(r"([#b-]*?)(-1|[0-9]{1,3})", text[1:])
        if match is None:
            raise PianobotError(f"'{quote(name)}' is not a pitch: write it like C4, F#3, Bb5 or a MIDI number 0-127")
        accidentals, octave = match.group(1), int(match.group(2))
        value += accidentals.count("#") - accidentals.count("b") - accidentals.count("-")
        value += (octave + 1) * 12
    if not 0 <= value <= 127:
        raise PianobotError(f"pitch '{quote(name)}' is outside MIDI's range 0-127 (C-1 to G9)")
    return value


def mirror_pitch(pitch: int) -> int:
    """The key at the same place on the keyboard's mirror image about D4 (62 <-> 62, C4 60 <-> E4 64,
    A0 21 <-> G7 103): a white key gives a white key and a black key a black key."""
    mirrored = MIRROR_AXIS - pitch
    if not 0 <= mirrored <= 127:
        raise PianobotError(
            f"{pitch_name(pitch)} has no mirror image in MIDI's range (pitches above {pitch_name(MIRROR_AXIS)} have none): "
            "transpose the piece down with load.transpose"
        )
    return mirrored


def _ms(seconds: float) -> float:
    return round(round(seconds / TIME_RESOLUTION) * TIME_RESOLUTION, 6)


@dataclass(frozen=True)
class Note:
    """One note: MIDI pitch 0-127, onset < offset in seconds, velocity 1-127, finger 1-5 or None,
    hand 'right', 'left' or None."""

    onset: float
    """Seconds from the start of the piece."""
    pitch: int
    offset: float
    """Seconds from the start of the piece; after the onset."""
    velocity: int = 80
    finger: int | None = None
    """1 thumb to 5 little finger; None where the file says nothing."""
    hand: str | None = None
    """'right' or 'left': the hand that plays the note; None where nothing says (a one-hand piece)."""

    def __post_init__(self) -> None:
        if not isinstance(self.pitch, int) or not 0 <= self.pitch <= 127:
            raise PianobotError(f"pitch {self.pitch!r} is outside MIDI's range 0-127")
        for name in ("onset", "offset"):
            value = getattr(self, name)
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise PianobotError(
                    f"note {pitch_name(self.pitch)} has {name} {value!r}: times must be finite numbers of seconds"
                )
            if value < -MAX_SECONDS:  # (far before the start: no rounding to milliseconds holds it)
                raise PianobotError(f"note {pitch_name(self.pitch)} has {name} {value:.3g} s: times must be >= 0")
            if value > MAX_SECONDS:
                raise PianobotError(
                    f"note {pitch_name(self.pitch)} has {name} {value:.3f} s, after {MAX_SECONDS / 60:.0f} minutes: "
                    f"pianobot reads pieces of at most {MAX_SECONDS / 60:.0f} minutes; cut the piece into parts"
                )
        object.__setattr__(self, "onset", _ms(self.onset))
        object.__setattr__(self, "offset", _ms(self.offset))
        if self.onset < 0:
            raise PianobotError(f"note {pitch_name(self.pitch)} starts at {self.onset} s: onsets must be >= 0")
        if self.offset <= self.onset:
            raise PianobotError(
                f"note {pitch_name(self.pitch)} at {self.onset:.3f} s ends at {self.offset:.3f} s: "
                "a note must end after it starts (it must last at least 1 ms)"
            )
        if not isinstance(self.velocity, int) or not 1 <= self.velocity <= 127:
            raise PianobotError(
                f"note {pitch_name(self.pitch)} at {self.onset:.3f} s has velocity {self.velocity!r}: "
                "velocities are whole numbers 1-127"
            )
        if self.finger is not None and (not isinstance(self.finger, int) or not 1 <= self.finger <= 5):
            raise PianobotError(
                f"note {pitch_name(self.pitch)} at {self.onset:.3f} s has finger {self.finger!r}: "
                "fingers are numbered 1 (thumb) to 5 (little finger)"
            )
        if self.hand is not None and self.hand not in HANDS:
            raise PianobotError(
                f"note {pitch_name(self.pitch)} at {self.onset:.3f} s has hand {self.hand!r}: "
                "a note's hand is 'right', 'left' or None"
            )

    @property
    def duration(self) -> float:
        return round(self.offset - self.onset, 6)

    @property
    def name(self) -> str:
        return pitch_name(self.pitch)

    def describe(self) -> str:
        """Short human description used in error messages: 'E4 at 1.500 s'."""
        return f"{self.name} at {self.onset:.3f} s"


def _sort_key(n: Note) -> tuple:
    return (n.onset, n.pitch, n.offset, n.velocity, n.finger or 0, n.hand or "")


@dataclass(frozen=True)
class Piece:
    """A sorted, immutable sequence of notes.

    ``bpm`` is the nominal tempo (beats per minute) used when the piece is written to MIDI; it
    does not take part in equality, since the notes' times already say everything about timing.
    """

    notes: tuple[Note, ...]
    bpm: float = field(default=120.0, compare=False)

    def __post_init__(self) -> None:
        for note in self.notes:
            if not isinstance(note, Note):
                raise TypeError(f"Piece takes Note objects, got {type(note).__name__}")
        notes = tuple(sorted(self.notes, key=_sort_key))
        object.__setattr__(self, "notes", notes)
        if not 10 <= self.bpm <= 1000:
            raise PianobotError(f"tempo {self.bpm} bpm is out of range: use 10-1000 bpm")

    # -- views ---------------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.notes)

    def __iter__(self):
        return iter(self.notes)

    @property
    def duration(self) -> float:
        """Time from 0 to the last offset, in seconds."""
        return max((n.offset for n in self.notes), default=0.0)

    @property
    def has_fingering(self) -> bool:
        """True when every note has a finger."""
        return bool(self.notes) and all(n.finger is not None for n in self.notes)

    @property
    def hands(self) -> tuple[str, ...]:
        """The hands that have notes, right before left; () for a piece whose notes have no hand."""
        present = {n.hand for n in self.notes}
        return tuple(h for h in HANDS if h in present)

    def part(self, hand: str | None) -> "Piece":
        """The notes given to ``hand`` ('right', 'left', or None for the unassigned ones)."""
        if hand is not None and hand not in HANDS:
            raise PianobotError(f"hand {hand!r}: choose 'right', 'left' or None")
        return Piece(tuple(n for n in self.notes if n.hand == hand), bpm=self.bpm)

    def chords(self) -> list[tuple[Note, ...]]:
        """Notes grouped by equal onset (a melody note is a chord of one), in time order."""
        groups: list[list[Note]] = []
        for note in self.notes:
            if groups and groups[-1][0].onset == note.onset:
                groups[-1].append(note)
            else:
                groups.append([note])
        return [tuple(g) for g in groups]

    def max_polyphony(self) -> tuple[int, float]:
        """Largest number of notes sounding at once, and the first time it happens."""
        events = sorted([(n.onset, 1) for n in self.notes] + [(n.offset, -1) for n in self.notes])
        best, when, now = 0, 0.0, 0
        for time, change in events:  # offsets (-1) sort before onsets (+1) at equal times
            now += change
            if now > best:
                best, when = now, time
        return best, when

    # -- transforms (all return new pieces) ---------------------------------------------
    def transpose(self, semitones: int) -> "Piece":
        """The same piece shifted by ``semitones`` (positive is up)."""
        if semitones == 0:
            return self
        out = []
        for n in self.notes:
            if not 0 <= n.pitch + semitones <= 127:
                raise SettingError(
                    f"load.transpose {semitones} moves {n.describe()} outside MIDI's range 0-127: use a smaller shift",
                    "load.transpose",
                )
            out.append(replace(n, pitch=n.pitch + semitones))
        return Piece(tuple(out), bpm=self.bpm)

    def retime(self, factor: float) -> "Piece":
        """Every time multiplied by ``factor`` (2.0 plays twice as slowly)."""
        if factor <= 0:
            raise PianobotError(f"time factor {factor} must be positive")
        return Piece(
            tuple(replace(n, onset=n.onset * factor, offset=n.offset * factor) for n in self.notes),
            bpm=self.bpm / factor,
        )

    def shift(self, seconds: float) -> "Piece":
        """Every time moved by ``seconds`` (the result must not start before 0)."""
        return Piece(
            tuple(replace(n, onset=n.onset + seconds, offset=n.offset + seconds) for n in self.notes),
            bpm=self.bpm,
        )

    def with_fingers(self, fingers: Sequence[int | None]) -> "Piece":
        """The same notes (in this piece's order) with the given fingers."""
        if len(fingers) != len(self.notes):
            raise ValueError(f"{len(fingers)} fingers for {len(self.notes)} notes")
        return Piece(tuple(replace(n, finger=f) for n, f in zip(self.notes, fingers)), bpm=self.bpm)

    def without_fingering(self) -> "Piece":
        return self.with_fingers([None] * len(self.notes))

    def with_hands(self, hands: Sequence[str | None] | str | None) -> "Piece":
        """The same notes with the given hands: one per note (in this piece's order), or one for all."""
        if hands is None or isinstance(hands, str):
            hands = [hands] * len(self.notes)
        if len(hands) != len(self.notes):
            raise ValueError(f"{len(hands)} hands for {len(self.notes)} notes")
        return Piece(tuple(replace(n, hand=h) for n, h in zip(self.notes, hands)), bpm=self.bpm)

    def mirror(self) -> "Piece":
        """The piece on the keyboard's mirror image about D (:func:`mirror_pitch`): low becomes high,
        every key keeps its colour, fingers stay, and the hands swap, so a left hand's part becomes a
        part for a right hand (and back again: ``piece.mirror().mirror() == piece``)."""
        swap = {"right": "left", "left": "right", None: None}
        return Piece(
            tuple(replace(n, pitch=mirror_pitch(n.pitch), hand=swap[n.hand]) for n in self.notes), bpm=self.bpm
        )

    @staticmethod
    def of(notes: Iterable[Note], bpm: float = 120.0) -> "Piece":
        return Piece(tuple(notes), bpm=bpm)


def resolve_overlaps(notes: list[Note]) -> list[Note]:
    """One key cannot sound twice at once: cut an earlier note where the same pitch starts again.
    Said in one warning per kind, with the first of them (a file may hold hundreds)."""
    by_pitch: dict[int, list[Note]] = defaultdict(list)
    doubled: list[Note] = []
    cut: list[tuple[Note, Note]] = []
    for note in sorted(notes, key=lambda n: (n.onset, n.pitch, -n.velocity)):
        previous = by_pitch[note.pitch][-1] if by_pitch[note.pitch] else None
        if previous is not None and note.onset < previous.offset:
            if note.onset == previous.onset:
                doubled.append(note)
                if note.offset > previous.offset:
                    by_pitch[note.pitch][-1] = replace(previous, offset=note.offset)
                continue
            cut.append((previous, note))
            by_pitch[note.pitch][-1] = replace(previous, offset=note.onset)
        by_pitch[note.pitch].append(note)
    if doubled:
        first = doubled[0].describe()
        warnings.warn(
            PianobotWarning(
                f"{first} appears twice at once; the louder one is kept"
                if len(doubled) == 1
                else f"{len(doubled)} notes appear twice at once (the first: {first}); the louder of each is kept"
            )
        )
    if cut:
        previous, note = cut[0]
        first = f"{previous.describe()} still sounds when {note.name} starts again at {note.onset:.3f} s"
        warnings.warn(
            PianobotWarning(
                f"{first}; the earlier note now ends there"
                if len(cut) == 1
                else f"{len(cut)} notes still sound when their key starts again (the first: {first}); each now ends there"
            )
        )
    return [n for group in by_pitch.values() for n in group]
