"""Notes one hand cannot reach, lent to the other hand (pianobot/pianist/lend.py)."""

import warnings

import mido

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions
from pianobot.music.piece import Note, Piece
from pianobot.perform.together import play_hands
from pianobot.pianist.assign import load_two_hands, reaches
from pianobot.pianist.lend import given, lend_if_more, lend_notes

FIVE = HandSpec((1, 2, 3, 4, 5), model="pianist")


def _right() -> list[Note]:
    """A right hand's G3 under C5 (a twelfth: no hand spans it), then D5."""
    return [
        Note(0.5, 55, 1.5, 80, 1, "right"),
        Note(0.5, 72, 1.0, 80, 5, "right"),
        Note(1.0, 74, 1.5, 80, None, "right"),
    ]


def test_a_note_the_right_hand_cannot_reach_goes_to_the_free_left_hand_and_is_played():
    assert not reaches([55, 72], "right", FIVE) and reaches([48, 55], "left", FIVE)
    piece = Piece.of(_right() + [Note(0.5, 48, 1.5, 70, None, "left")])
    lent, count = lend_if_more(piece, FIVE)
    assert count == 1
    g3 = next(n for n in lent.notes if n.pitch == 55)
    assert g3.hand == "left" and g3.finger is None  # (its written finger was the right hand's)
    assert given(lent, FIVE) == 4 and given(piece, FIVE) == 3
    assert play_hands(lent, "scripted", hand=FIVE, seed=0).report().f1 == 1.0


def test_no_note_is_lent_across_the_other_hand_nor_by_the_allegro_hand():
    crossing = Piece.of(_right() + [Note(0.5, 57, 1.5, 70, None, "left")])  # the left hand holds A3, above G3
    assert lend_notes(crossing, FIVE)[1] == 0
    free = Piece.of(_right() + [Note(0.5, 48, 1.5, 70, None, "left")])
    assert lend_notes(free, HandSpec())[1] == 1  # (it could) but the paper's hand does not lend
    assert lend_if_more(free, HandSpec()) == (free, 0)


def test_a_lent_note_the_other_hand_cannot_get_to_in_time_is_not_lent():
    # the left hand strikes C1 just before: G3, three octaves up, 0.1 s later is beyond its wrist
    far = Piece.of(_right() + [Note(0.4, 24, 0.5, 70, None, "left")])
    assert lend_notes(far, FIVE)[1] == 1
    assert lend_if_more(far, FIVE) == (far, 0)


def test_a_file_with_tracks_named_for_hands_lends_and_says_so(tmp_path):
    midi = mido.MidiFile(type=1)
    for name, notes in (("Right Hand", [55, 72]), ("Left Hand", [48])):
        events = [mido.MetaMessage("track_name", name=name)]
        events += [mido.Message("note_on", note=p, velocity=80) for p in notes]
        events += [mido.Message("note_off", note=p, time=480 if i == 0 else 0) for i, p in enumerate(notes)]
        midi.tracks.append(mido.MidiTrack(events))
    midi.save(tmp_path / "wide.mid")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PianobotWarning)
        pianist = load_two_hands(tmp_path / "wide.mid", LoadOptions(), FIVE)
        allegro = load_two_hands(tmp_path / "wide.mid", LoadOptions(), HandSpec())
    assert {n.pitch: n.hand for n in pianist.notes} == {55: "left", 72: "right", 48: "left"}
    assert {n.pitch: n.hand for n in allegro.notes} == {55: "right", 72: "right", 48: "left"}
    said = [str(w.message) for w in caught if "other hand" in str(w.message)]
    assert said == [
        "wide.mid has chords wider than one hand reaches: gave 1 of their notes to the other hand, which reaches them"
    ]
