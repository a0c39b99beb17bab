"""One hand's part of a recording, reduced to what the robot hand can play (``--hand``).

A human player's right hand holds octaves and wide chords, keeps a note down while the melody
leaps away, and plays ornaments faster than the robot's hand can move. Read with ``--hand``
(:func:`load_for_hand`, which ``play``, ``train``, ``inspect``, ``finger`` and ``score`` use),
such a part is reduced rather than refused. Chord by chord in time order (chords as
:func:`pianobot.music.load.thin_chords` left them), the fingering planner
(:class:`~pianobot.pianist.fingering.Planner`, the one place that knows what the hand can
reach and how fast) is asked whether the hand can play the chord after what has been kept so
far; where it cannot, the top voice (the melody) is kept and what blocks it goes:

1. **Too wide.** A chord that no hand position reaches keeps its top note and, from the top
   down, each lower note that still fits under the hand with it; the others are dropped.
2. **Held too long.** The planner keeps a held note under the hand until the next chord starts:
   a note still held when a later chord starts ends there (as does a note whose key is struck
   again).
3. **Held in the way.** When notes held from the previous chord keep the hand from the next
   one (a note held under a leap, fingertips that would cross), they end where it starts, the
   lowest first, until the hand gets there; if it still cannot, that chord's lower notes are
   dropped, the lowest first.
4. **Too fast.** *Grace notes* (single notes of at most :data:`GRACE` s, each leading into the
   next chord within :data:`GRACE` s) that the hand cannot play in time before their main chord
   are played as fast as it can instead of dropped: spread evenly before the main chord, which
   keeps its onset, at the smallest spacing (in :data:`SHIFT_STEP` s steps) that gives the hand
   time, taking at most :data:`GRACE_ROOM` of the time since the chord before them. Otherwise,
   and for grace notes that no spacing helps, a chord the hand cannot reach in time loses its
   lower notes, the lowest first, then the chord before it does; where two single notes still
   follow too fast (a run), the shorter of the two is dropped (the later one when they are
   equal).

Each kind of change is reported in one warning line with its count. A part that the hand can
play as it is comes back unchanged.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Sequence

import numpy as np

from pianobot.errors import PianobotWarning, SettingError
from pianobot.music.instrument import PIANO, HandSpec, KeyboardSpec, beyond_piano
from pianobot.music.load import LoadOptions, load_part
from pianobot.music.piece import Note, Piece, pitch_name
from pianobot.pianist.fingering import Planner, Reach
from pianobot.sim.hand import hand_config
from pianobot.sim.keyboard import KeyboardConfig

GRACE = 0.15
"""A single note this short (s) that leads into the next chord within this long is a grace note."""
GRACE_ROOM = 0.75
"""Grace notes take at most this share of the time since the chord before them."""
SHIFT_STEP = 0.01
"""Grace notes move earlier in steps of this many seconds."""
RECENT = 3
"""Kept chords whose notes may still sound at a new onset (rule 2 ends those of earlier ones)."""


@dataclass(frozen=True)
class Reduction:
    """The reduced part and what was changed, counted in notes."""

    piece: Piece
    wide: int = 0
    """Lower notes dropped from chords no hand position reaches (rule 1)."""
    held: int = 0
    """Held notes that now end earlier (rules 2 and 3)."""
    blocked: int = 0
    """Lower notes dropped from chords the hand cannot get to from the notes before (rule 3)."""
    graces: int = 0
    """Grace notes moved earlier (rule 4)."""
    fast: int = 0
    """Notes dropped because they come faster than the hand can move (rule 4)."""
    shift: float = 0.0
    """The largest move of a grace note (s)."""

    def messages(self, part: str) -> list[str]:
        """One line per kind of change, for ``part`` (e.g. "the right hand's part")."""
        lines = []
        if self.wide:
            lines.append(
                f"{part} has chords wider than this hand reaches: kept their top notes, dropped {self.wide} lower note(s)"
            )
        if self.held:
            lines.append(
                f"{part} holds notes this hand cannot keep down (under a leap, or past the next notes): "
                f"{self.held} held note(s) now end earlier"
            )
        if self.blocked:
            lines.append(
                f"{part} has chords this hand cannot get to from the notes before them: dropped {self.blocked} lower note(s)"
            )
        if self.graces:
            lines.append(
                f"{part} has grace notes faster than this hand moves: played {self.graces} of them as fast as it can "
                f"(up to {self.shift * 1000:.0f} ms earlier)"
            )
        if self.fast:
            lines.append(
                f"{part} has notes faster than this hand can move: dropped {self.fast} note(s) "
                "(lower notes of chords first, then the shorter note of a fast pair)"
            )
        return lines


def reduce_part(piece: Piece, keyboard: KeyboardSpec, hand: HandSpec, part: str = "the part") -> Reduction:
    """``piece`` reduced to what ``hand`` can play on ``keyboard`` by the rules in the module's
    notes; each kind of change is reported in one :class:`PianobotWarning` naming ``part``.
    A piece with notes off the keyboard or more notes at once than the hand has fingers is
    returned as it is, for :func:`~pianobot.music.instrument.check_playable` to explain."""
    if any(n.pitch not in keyboard for n in piece.notes) or any(len(c) > len(hand.fingers) for c in piece.chords()):
        return Reduction(piece)
    reduction = _Reducer(Planner(KeyboardConfig(spec=keyboard), hand_config(hand))).run(piece)
    for line in reduction.messages(part):
        warnings.warn(PianobotWarning(line))
    return reduction


def load_for_hand(
    path: str | Path, options: LoadOptions, keyboard: KeyboardSpec, hand: HandSpec, fit: bool = True
) -> Piece:
    """:func:`~pianobot.music.load.load_part`; with ``options.hand``, the part is also reduced to
    what ``hand`` can play on ``keyboard`` (:func:`reduce_part`, one warning per kind of change)
    and, with ``fit``, a part wider than ``keyboard`` is refused in one line naming a keyboard that
    holds it (``score``, which plays nothing and has no keyboard options, reads it as it is).
    Without it, a piece is read as it is, and the fingering planner refuses what the hand cannot play."""
    piece = load_part(path, options, hand)
    if options.hand is None:
        return piece
    if said := beyond_piano(piece, options.transpose):  # (no keyboard named could hold them: a shift does)
        raise SettingError(f"the {options.hand} hand's part has {said}", "load.transpose")
    low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
    if fit and high - low >= keyboard.count:  # (no transposition fits it: say what keyboard does)
        lowest = max(low // 12 * 12, PIANO.lowest)
        count = min((high - lowest) // 12 * 12 + 12, PIANO.highest - lowest + 1)
        raise SettingError(
            f"the {options.hand} hand's part spans {pitch_name(low)}-{pitch_name(high)}, more keys than the keyboard "
            f"{keyboard.describe()}: widen the keyboard, e.g. keyboard.lowest {pitch_name(lowest)} keyboard.count {count}",
            "keyboard.lowest",
            "keyboard.count",
        )
    return reduce_part(piece, keyboard, hand, f"the {options.hand} hand's part").piece


def is_grace(chords: Sequence[Sequence[Note]], i: int) -> bool:
    """Whether chord ``i`` is a grace note: a single note of at most :data:`GRACE` s that leads
    into the next chord within :data:`GRACE` s."""
    if len(chords[i]) != 1 or i + 1 >= len(chords):
        return False
    note = chords[i][0]
    return note.offset - note.onset <= GRACE + 1e-9 and chords[i + 1][0].onset - note.onset <= GRACE + 1e-9


class _Reducer:
    """The rules, applied chord by chord: ``kept`` (the chords kept so far, each by pitch) and
    ``costs`` (the planner's costs of every state after each of them) grow together."""

    def __init__(self, planner: Planner):
        self.planner = planner
        self.kept: list[list[Note]] = []
        self.costs: list[np.ndarray] = []
        self.counts = dict(wide=0, held=0, blocked=0, graces=0, fast=0)
        self.shift = 0.0

    def run(self, piece: Piece) -> Reduction:
        chords = [self.fit(sorted(chord, key=lambda n: n.pitch)) for chord in piece.chords()]
        i = 0
        while i < len(chords):
            main = i
            while is_grace(chords, main):
                main += 1
            if main > i:
                self.graced(chords[i:main], chords[main])
            else:
                self.add(chords[i])
            i = main + 1
        notes = sorted((n for chord in self.kept for n in chord), key=lambda n: (n.onset, n.pitch))
        return Reduction(Piece(tuple(notes), bpm=piece.bpm), **self.counts, shift=self.shift)

    def after(self, i: int) -> Reach:
        """Where the hand can be after kept chord ``i`` (whose held notes may since have been shortened)."""
        return Reach(tuple(self.kept[i]), self.costs[i])

    # -- rule 1 --------------------------------------------------------------------------------
    def fit(self, chord: list[Note]) -> list[Note]:
        """The top note, and from the top down each lower note that still fits under the hand."""
        if self.planner.place(chord).possible:
            return chord
        kept = [chord[-1]]
        for note in reversed(chord[:-1]):
            if self.planner.place([note, *kept]).possible:
                kept.insert(0, note)
        self.counts["wide"] += len(chord) - len(kept)
        return kept

    # -- rules 2 to 4: one chord after the others ------------------------------------------
    def add(self, chord: list[Note], strict: bool = False) -> bool:
        """Keep ``chord`` (or what of it the hand can play) after the chords kept so far. With
        ``strict``, only if the hand gets there in time without dropping a note for speed:
        False, and then the kept chords may have changed (see :meth:`attempt`)."""
        chord = list(chord)
        onset, pitches = chord[0].onset, {n.pitch for n in chord}
        recent = self.kept[-RECENT:]  # (every earlier note ended before: rule 2 when they were kept)
        for i, earlier in enumerate(recent):  # rule 2, and a key struck again is let go first
            for note in [n for n in earlier if n.offset > onset]:
                if i < len(recent) - 1 or note.pitch in pitches:
                    self.end_at(note, onset)
        while self.kept:
            self.follow(chord)
            timed = self.planner.follow(self.after(-1), chord, in_time=True)
            if timed.possible:
                self.kept.append(chord)
                self.costs.append(timed.cost)
                return True
            if strict:
                return False
            self.counts["fast"] += 1
            if len(chord) > 1:  # rule 4: the chord's lower notes, the lowest first
                del chord[0]
            elif len(self.kept[-1]) > 1:  # then those of the chord before it
                self.drop_lowest_before()
            elif chord[0].offset - onset <= self.kept[-1][0].offset - self.kept[-1][0].onset:
                return True  # two single notes: the shorter one goes, here the later one
            else:
                self.kept.pop()
                self.costs.pop()
        self.kept.append(chord)
        self.costs.append(self.planner.place(chord).cost)
        return True

    def follow(self, chord: list[Note]) -> None:
        """Rule 3: end the held notes of the last kept chord that keep the hand from ``chord``,
        the lowest first, then drop ``chord``'s lower notes (in place) while it still cannot."""
        onset = chord[0].onset
        reach = self.planner.follow(self.after(-1), chord)
        for note in sorted((n for n in self.kept[-1] if n.offset > onset), key=lambda n: n.pitch):
            if reach.possible:
                break
            self.end_at(note, onset)
            reach = self.planner.follow(self.after(-1), chord)
        while not reach.possible and len(chord) > 1:
            del chord[0]
            self.counts["blocked"] += 1
            reach = self.planner.follow(self.after(-1), chord)

    def end_at(self, note: Note, onset: float) -> None:
        """Shorten a kept note (of the last few chords) so that it ends at ``onset``."""
        for chord in self.kept[-RECENT:]:
            for i, n in enumerate(chord):
                if n is note:
                    chord[i] = replace(n, offset=onset)
        self.counts["held"] += 1

    def drop_lowest_before(self) -> None:
        """Drop the lowest note of the last kept chord, and work out again where the hand can be after it."""
        del self.kept[-1][0]
        if len(self.kept) == 1:
            self.costs[-1] = self.planner.place(self.kept[-1]).cost
            return
        timed = self.planner.follow(self.after(-2), self.kept[-1], in_time=True)
        self.costs[-1] = (timed if timed.possible else self.planner.follow(self.after(-2), self.kept[-1])).cost

    # -- rule 4 for grace notes --------------------------------------------------------------
    def graced(self, graces: list[list[Note]], main: list[Note]) -> None:
        """Grace notes and their main chord: as written where the hand has time for them, else
        spread evenly before the main chord, the least that gives the hand time; where no
        spread does, chord by chord like any other notes."""
        if self.attempt([*graces, main]):
            return
        end, count = main[0].onset, len(graces)
        start = self.kept[-1][0].onset if self.kept else 0.0
        first = (end - graces[0][0].onset) / count
        for spacing in np.arange(first + SHIFT_STEP, GRACE_ROOM * (end - start) / count + 1e-9, SHIFT_STEP):
            moved = [
                [replace(g[0], onset=end - (count - k) * spacing, offset=end - (count - k - 1) * spacing)]
                for k, g in enumerate(graces)
            ]
            if self.attempt([*moved, main]):
                self.counts["graces"] += count
                self.shift = max(self.shift, max(g[0].onset - m[0].onset for g, m in zip(graces, moved)))
                return
        for chord in [*graces, main]:
            self.add(chord)

    def attempt(self, chords: list[list[Note]]) -> bool:
        """Keep ``chords`` if the hand gets to each in time (rules 2 and 3 may apply); else change nothing."""
        saved = [list(c) for c in self.kept], list(self.costs), dict(self.counts)
        if all(self.add(chord, strict=True) for chord in chords):
            return True
        self.kept, self.costs, self.counts = saved
        return False
