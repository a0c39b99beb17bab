"""A two-hand performance scored as a whole and hand by hand.

:func:`compare_hands` scores the whole piece with :func:`pianobot.music.metrics.compare`, then
each hand's part of the reference (its notes with that :attr:`~pianobot.music.piece.Note.hand`)
against the played notes that belong to it, with the same function: so every figure of a
:class:`~pianobot.music.metrics.Report` (note F1, key-press F1, velocity, timing, fingering
accuracy) exists for each hand too.

Which played notes belong to a hand: a played note matched to a reference note belongs to that
note's hand; an extra note (matched to none) to its own hand where it has one, else to the hand
of the nearest reference note (in semitones, a second of time counting as an octave).
"""

from __future__ import annotations

from dataclasses import dataclass

from pianobot.music.metrics import Report, compare
from pianobot.music.piece import Note, Piece

SECOND_IN_SEMITONES = 12.0
"""For an extra note's hand: one second between onsets counts as far as this many semitones."""


@dataclass(frozen=True)
class HandsReport:
    """The whole piece's report and one per hand that the reference gives notes to."""

    whole: Report
    hands: dict[str, Report]
    """'right' and 'left' (those the reference has) to that hand's report."""

    def fingering_accuracy(self) -> dict[str, float | None]:
        """Each hand's share of matched, fingered notes played with the reference's finger."""
        return {hand: report.fingering_accuracy for hand, report in self.hands.items()}


def _nearest_hand(note: Note, reference: Piece) -> str | None:
    handed = [n for n in reference.notes if n.hand is not None]
    if not handed:
        return None
    nearest = min(handed, key=lambda n: abs(n.pitch - note.pitch) + SECOND_IN_SEMITONES * abs(n.onset - note.onset))
    return nearest.hand


def played_hands(reference: Piece, played: Piece, whole: Report) -> Piece:
    """``played`` with each note's hand as the module's notes say, from ``whole`` (``compare(reference, played)``)."""
    hands: dict[Note, str | None] = {}  # (a piece never holds two equal notes: one key, one onset)
    for row in whole.rows:
        if row.played is None:
            continue
        if row.reference is not None:
            hand = row.reference.hand
        else:
            hand = row.played.hand or _nearest_hand(row.played, reference)
        hands[row.played] = hand
    return played.with_hands([hands.get(n) for n in played.notes])


def compare_hands(reference: Piece, played: Piece, **options) -> HandsReport:
    """``played`` scored against ``reference`` as a whole and for each hand of the reference;
    ``options`` (onset_tolerance, control_hz) go to :func:`~pianobot.music.metrics.compare`."""
    whole = compare(reference, played, **options)
    if not reference.hands:
        return HandsReport(whole, {})
    split = played_hands(reference, played, whole)
    return HandsReport(
        whole,
        {hand: compare(reference.part(hand), split.part(hand), **options) for hand in reference.hands},
    )
