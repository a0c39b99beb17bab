"""Notes one hand cannot reach, lent to the other hand (pianobot/pianist/lend.py)."""

import warnings

import mido

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions
from pianobot.music.piece import Note, Piece
from pianobot.perform.together import play_hands
from pianobot.pianist.assign import load_two_hands, reaches
from pianobot.pianist.lend import lend_if_more, lend_notes, notes_given
from pianobot.pianist.reading import read_hands

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
    assert notes_given(lent, FIVE) == 4 and notes_given(piece, FIVE) == 3
    assert play_hands(lent, "scripted", hand=FIVE, seed=0).report().f1 == 1.0


def test_no_note_is_lent_across_the_other_hand_nor_by_the_allegro_hand():
    crossing = Piece.of(_right() + [Note(0.5, 57, 1.5, 70, None, "left")])  # the left hand holds A3, above G3
    assert lend_notes(crossing, FIVE)[1] == 0
    free = Piece.of(_right() + [Note(0.5, 48, 1.5, 70, None, "left")])
    assert lend_notes(free, HandSpec())[1] == 1  # (it could) but the paper's hand does not lend
    assert lend_if_more(free, HandSpec()) == (free, 0)


def test_each_lending_is_kept_only_where_it_gives_the_hands_more_notes():
    """The left hand strikes C1 just before the first G3 under C5 (three octaves up, 0.1 s later: beyond
    its wrist), then holds C3 under the second: only the second G3 is lent; the left hand's C1 is
    kept, where lending the first too would have cost it (one lending is judged apart from another)."""
    right = _right() + [Note(2.0, 55, 3.0, 80, None, "right"), Note(2.0, 72, 3.0, 80, None, "right")]
    left = [Note(0.4, 24, 0.5, 70, None, "left"), Note(2.0, 48, 3.0, 70, None, "left")]
    piece = Piece.of(right + left)
    assert lend_notes(piece, FIVE)[1] == 2  # (both fit under the left hand at their onsets)
    lent, count = lend_if_more(piece, FIVE)
    assert count == 1
    assert [(n.onset, n.pitch) for n in lent.notes if n.hand == "left"] == [(0.4, 24), (2.0, 48), (2.0, 55)]
    assert notes_given(lent, FIVE) == notes_given(piece, FIVE) + 1


def test_the_left_hand_lends_its_top_note_up_and_no_lent_note_crosses_its_own_hand():
    left = [Note(0.5, 36, 1.5, 70, None, "left"), Note(0.5, 52, 1.5, 70, None, "left")]  # C2 under E3: a tenth
    lent, count = lend_notes(Piece.of(left + [Note(0.5, 57, 1.5, 80, None, "right")]), FIVE)
    assert count == 1 and {n.pitch: n.hand for n in lent.notes} == {36: "left", 52: "right", 57: "right"}
    # a right hand's six notes: those the hand does not keep may lie between those it keeps
    chord = [Note(0.5, p, 1.5, 80, None, "right") for p in (64, 66, 67, 68, 69, 72)]
    lent, _ = lend_notes(Piece.of(chord + [Note(2.0, 48, 2.5, 70, None, "left")]), FIVE)  # (the left hand free)
    # the hand keeps C5 A4 G#4 G4 and E4, not F#4, which lies between them: it is not lent, which would cross
    assert {n.pitch: n.hand for n in lent.notes if n.onset == 0.5}[66] == "right"


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
    # what inspect and play say of each hand: the lent note is the right hand's track's, not the planner's
    reading = read_hands(tmp_path / "wide.mid", LoadOptions(), FIVE)
    assert (
        reading.describe("left")
        == "left hand: 2 notes, C3-G3, 1 named by its track, 1 lent by the right hand (out of its reach)"
    )
    assert reading.describe("right") == "right hand: 1 note, C5-C5, named by its track"
    assert reading.to_dict("left") == {
        "notes": 2,
        "range": ["C3", "G3"],
        "named_by_file": 1,
        "lent_by_other_hand": 1,
        "assigned_by_planner": 0,
    }


def test_a_named_note_thinned_away_is_counted_for_neither_hand(tmp_path):
    """Eleven notes at once, more than two hands of five fingers hold: the reading thins one inner
    note away. Each hand's count is of the notes it plays: named, lent or assigned, nothing of the
    thinned note (which, counted, made a hand's notes more than it plays)."""
    midi = mido.MidiFile(type=1)
    for name, notes in (("Right Hand", [60, 62, 64, 65, 67, 69]), ("Left Hand", [48, 50, 52, 53, 55])):
        events = [mido.MetaMessage("track_name", name=name)]
        events += [mido.Message("note_on", note=p, velocity=80) for p in notes]
        events += [mido.Message("note_off", note=p, time=480 if i == 0 else 0) for i, p in enumerate(notes)]
        midi.tracks.append(mido.MidiTrack(events))
    midi.save(tmp_path / "eleven.mid")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        reading = read_hands(tmp_path / "eleven.mid", LoadOptions(), FIVE)
    assert len(reading.piece) == 10
    for hand in ("right", "left"):
        counts = reading.to_dict(hand)
        assert counts["named_by_file"] + counts["lent_by_other_hand"] == counts["notes"]
        assert counts["assigned_by_planner"] == 0
