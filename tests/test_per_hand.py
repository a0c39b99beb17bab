"""Scoring a two-hand performance as a whole and hand by hand (pianobot.music.per_hand)."""

import pytest

from pianobot.music.metrics import compare
from pianobot.music.per_hand import compare_hands
from pianobot.music.piece import Note, Piece


def _reference():
    right = [Note(i * 0.5, 72 + i, i * 0.5 + 0.4, 80, 2 + i % 3, "right") for i in range(4)]
    left = [Note(i * 1.0, 48 - i, i * 1.0 + 0.9, 60, 4 - i % 2, "left") for i in range(2)]
    return Piece.of([*right, *left])


def test_each_hand_is_scored_on_its_own_notes():
    reference = _reference()
    # the right hand plays everything with the right fingers; the left hand misses its second
    # note, plays its first with a wrong finger, and adds a note near its part
    played = [n for n in reference.part("right").with_hands(None)]
    first = reference.part("left").notes[0]
    played += [Note(first.onset, first.pitch, first.offset, 60, 2), Note(1.5, 45, 1.9, 60, 3)]
    report = compare_hands(reference, Piece.of(played))
    assert report.whole == compare(reference, Piece.of(played))  # the whole piece as metrics.compare scores it
    right, left = report.hands["right"], report.hands["left"]
    assert (right.f1, right.matched_notes, right.played_notes) == (1.0, 4, 4)
    assert (left.reference_notes, left.matched_notes, left.played_notes) == (2, 1, 2)  # the extra counts for the left
    assert left.precision == pytest.approx(0.5) and left.recall == pytest.approx(0.5)
    assert report.fingering_accuracy() == {"right": 1.0, "left": 0.0}


def test_a_piece_without_hands_has_only_the_whole_report():
    reference = _reference().with_hands(None)
    report = compare_hands(reference, reference)
    assert report.hands == {} and report.whole.f1 == 1.0
