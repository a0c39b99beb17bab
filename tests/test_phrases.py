import pytest

from pianobot.errors import PianobotError
from pianobot.music.phrases import split_phrases
from pianobot.music.piece import Note, Piece


def even(n, start=0.0, pitch=60):
    return [Note(start + i, pitch + i % 5, start + i + 1, 80, 2 + i % 3) for i in range(n)]


def test_phrases_cover_every_note_in_order_and_respect_the_limit():
    piece = Piece(tuple(even(20)))
    phrases = split_phrases(piece, 6)
    assert [n for p in phrases for n in p.notes] == list(piece.notes)
    assert all(len(p.notes) <= 6 for p in phrases)
    assert len(phrases) == 4  # the fewest that fit
    assert [p.index for p in phrases] == [0, 1, 2, 3]


def test_breaks_prefer_rests():
    # 8 notes; a rest after the 3rd: the split must fall there, not in the middle
    notes = even(3) + even(5, start=5.0)
    phrases = split_phrases(Piece(tuple(notes)), 6)
    assert [len(p.notes) for p in phrases] == [3, 5]


def test_breaks_prefer_long_notes():
    notes = [
        Note(0, 60, 1),
        Note(1, 62, 2),
        Note(2, 64, 5),
        Note(5, 62, 6),
        Note(6, 60, 7),
        Note(7, 62, 8),
        Note(8, 64, 9),
    ]
    assert [len(p.notes) for p in split_phrases(Piece(tuple(notes)), 6)] == [3, 4]


def test_equal_notes_split_evenly():
    assert [len(p.notes) for p in split_phrases(Piece(tuple(even(8))), 6)] == [4, 4]


def test_chords_are_never_split():
    notes = [Note(t, p, t + 1) for t in range(4) for p in (60, 64)]
    phrases = split_phrases(Piece(tuple(notes)), 3)
    assert [len(p.notes) for p in phrases] == [2, 2, 2, 2]
    with pytest.raises(PianobotError, match="chord at 0.000 s has 2 notes"):
        split_phrases(Piece(tuple(notes)), 1)


def test_hash_ignores_position_but_not_content():
    phrase = Piece(tuple(even(4)))
    repeated = Piece(tuple(even(4) + even(4, start=10.0)))
    first, second = split_phrases(repeated, 4)
    assert first.hash == second.hash == split_phrases(phrase, 4)[0].hash
    changed = [*even(3), Note(3, 60 + 3, 4, 81, 2)]
    assert split_phrases(Piece(tuple(changed)), 4)[0].hash != first.hash
    refingered = Piece(tuple(even(4))).with_fingers([2, 2, 2, 2])
    assert split_phrases(refingered, 4)[0].hash != first.hash


def test_phrase_as_a_piece_starts_at_the_lead_in():
    second = split_phrases(Piece(tuple(even(3) + even(3, start=5.0))), 3)[1]
    piece = second.piece(lead_in=0.5)
    assert piece.notes[0].onset == 0.5 and len(piece) == 3
