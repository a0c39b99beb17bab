"""Both hands of a piece, each played by the one simulated hand pianobot has today.

Until the simulator holds two hands over one keyboard, a two-hand piece is performed hand by
hand: each hand's part in a simulation of its own, and what the two keyboards sounded merged into
one performance, scored against the whole piece as written. What that leaves out, and says: the
hands never meet (no collision, no key shared between them), and each hand plays on a keyboard
of its own.

Each part becomes a part for the simulated hand, a right hand, in two steps that keep every key's
colour and every distance between keys:

1. the left hand's part is mirrored about D (:meth:`~pianobot.music.piece.Piece.mirror`): the
   mirror image of a left hand is a right hand with the same finger numbers;
2. the part is moved by whole octaves onto the keyboard its player knows (:class:`Window`): the
   general policy's 24 keys, or, for the scripted pianist, the part's own range rounded out to
   octaves.

Notes outside the window are left out, and the part is then reduced to what the hand can play
(:func:`~pianobot.pianist.reduce.reduce_part`), each kind of change said in one warning line; the
figures are always against the piece as written, so what was left out counts as missed.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import thin_chords
from pianobot.music.metrics import Report, compare
from pianobot.music.piece import HANDS, Note, Piece
from pianobot.music.window import Window, window_for
from pianobot.perform.plan import Performance, play
from pianobot.pianist.fingering import ensure_fingering
from pianobot.pianist.reduce import reduce_part


@dataclass(frozen=True)
class HandPerformance:
    """One hand's part as its simulation played it."""

    hand: str
    window: Window
    part: Piece
    """What the simulated hand was given: mirrored, moved, reduced and fingered, starting at ``start``."""
    start: float
    """Seconds by which the part was moved earlier (its first onset in the piece)."""
    left_out: int
    """Written notes outside the window."""
    performance: Performance

    @property
    def played(self) -> Piece:
        """What this hand sounded, back at the written pitches and times, each note with its hand."""
        notes = [
            replace(n, pitch=self.window.outward(n.pitch), hand=self.hand)
            for n in self.performance.played.shift(self.start).notes
        ]
        return Piece(tuple(notes), bpm=self.part.bpm)


@dataclass(frozen=True)
class HandsPerformance:
    """A two-hand piece performed hand by hand (the module's notes)."""

    piece: Piece
    """The piece as written, every note with its hand: what the figures are against."""
    hands: tuple[HandPerformance, ...]
    """Right hand first."""
    played: Piece = field(init=False)
    """What both keyboards sounded, as one piece at the written pitches, each note with its hand."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "played", Piece(tuple(n for h in self.hands for n in h.played.notes), self.piece.bpm))

    def report(self, hand: str | None = None) -> Report:
        """The figures for the whole piece, or for ``hand``'s part (against its written notes)."""
        if hand is None:
            return compare(self.piece, self.played)
        return compare(self.piece.part(hand), self.played.part(hand))


def prepare_part(
    piece: Piece, hand: str, keyboard: KeyboardSpec | None, fingers: HandSpec
) -> tuple[Window, Piece, float, int]:
    """``hand``'s part of ``piece`` as the simulated hand is given it: (window, part, start, notes
    left out). Each kind of change is one :class:`PianobotWarning`."""
    part = piece.part(hand)
    window = window_for(part, hand, keyboard)
    inside = [n for n in part.notes if window.inward(n.pitch) in window.keyboard]
    left_out = len(part) - len(inside)
    if left_out:
        warnings.warn(
            PianobotWarning(
                f"the {hand} hand's part spans more than the {window.keyboard.count} keys its player knows: "
                f"left out {left_out} note(s) outside them"
            )
        )
    if not inside:
        raise PianobotError(f"none of the {hand} hand's notes fits the keyboard its player knows")
    moved = Piece(tuple(Note(n.onset, window.inward(n.pitch), n.offset, n.velocity) for n in inside), bpm=piece.bpm)
    start = moved.notes[0].onset
    moved, dropped = thin_chords(moved.shift(-start), len(fingers.fingers))
    if dropped:
        warnings.warn(
            PianobotWarning(
                f"the {hand} hand's part has chords of more than {len(fingers.fingers)} notes: "
                f"kept the highest {len(fingers.fingers)}, dropped {dropped} note(s)"
            )
        )
    reduced = reduce_part(moved, window.keyboard, fingers, f"the {hand} hand's part").piece
    fingered, _ = ensure_fingering(reduced, window.keyboard, fingers, refinger=True)
    return window, fingered, start, left_out


def play_hands(
    piece: Piece,
    controller: str = "sac",
    models: Path | str | None = None,
    seed: int = 0,
    hand: HandSpec | None = None,
) -> HandsPerformance:
    """Perform ``piece``, every note of which has a hand, hand by hand (the module's notes):
    ``controller`` 'sac' (the general policy, or policies trained for the part) or 'scripted',
    ``models`` the model store, ``seed`` the hand start of every simulation."""
    if any(n.hand is None for n in piece.notes):
        raise PianobotError("every note needs a hand to play both hands: give the piece's notes a hand first")
    if controller not in ("sac", "scripted"):
        raise PianobotError(f"controller {controller!r}: both hands are played by 'sac' or 'scripted'")
    fingers = hand or HandSpec()
    keyboard = KeyboardSpec() if controller == "sac" else None
    done = []
    for name in (h for h in HANDS if h in piece.hands):
        window, part, start, left_out = prepare_part(piece, name, keyboard, fingers)
        performance = play(part, controller, models, seed=seed, keyboard=window.keyboard, hand=fingers)
        done.append(HandPerformance(name, window, part, start, left_out, performance))
    return HandsPerformance(piece, tuple(done))
