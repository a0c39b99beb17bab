import pytest

from pianobot.errors import PianobotError
from pianobot.music.piece import Note, Piece, parse_pitch, pitch_name


def test_pitch_names_round_trip():
    for pitch in range(0, 128):
        assert parse_pitch(pitch_name(pitch)) == pitch
    assert parse_pitch("Bb3") == 58
    assert parse_pitch("E-4") == 63
    assert parse_pitch("72") == 72


@pytest.mark.parametrize("text", ["H4", "C", "", "C#x", "G10"])
def test_bad_pitch_names_are_clear_errors(text):
    with pytest.raises(PianobotError):
        parse_pitch(text)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(onset=0, pitch=128, offset=1), "0-127"),
        (dict(onset=1, pitch=60, offset=1), "end after"),
        (dict(onset=-1, pitch=60, offset=1), ">= 0"),
        (dict(onset=0, pitch=60, offset=1, velocity=0), "1-127"),
        (dict(onset=0, pitch=60, offset=1, velocity=128), "1-127"),
        (dict(onset=0, pitch=60, offset=1, finger=6), "1 (thumb) to 5"),
    ],
)
def test_note_validation_names_the_allowed_range(kwargs, words):
    with pytest.raises(PianobotError, match=words.replace("(", r"\(").replace(")", r"\)")):
        Note(**kwargs)


def test_times_are_kept_in_milliseconds():
    note = Note(0.12345, 60, 0.98765)
    assert (note.onset, note.offset) == (0.123, 0.988)


def test_notes_are_sorted_and_transforms_return_new_pieces(scale):
    shuffled = Piece(tuple(reversed(scale.notes)), bpm=60)
    assert shuffled == scale
    up = scale.transpose(2)
    assert [n.pitch for n in up] == [62, 64, 66, 67]
    assert [n.pitch for n in scale] == [60, 62, 64, 65]  # unchanged
    slow = scale.retime(2.0)
    assert slow.notes[1].onset == 2.0 and slow.notes[1].offset == 4.0 and slow.bpm == 30
    assert scale.notes[1].onset == 1.0


def test_transpose_out_of_midi_range_is_an_error(scale):
    with pytest.raises(PianobotError, match="load.transpose 70") as e:  # the setting, named for Python's callers
        scale.transpose(70)
    assert e.value.field == "load.transpose"


def test_chords_and_polyphony():
    piece = Piece((Note(0, 60, 1), Note(0, 64, 1), Note(1, 62, 2), Note(1.5, 67, 3), Note(1.5, 71, 2.5)))
    assert [len(c) for c in piece.chords()] == [2, 1, 2]
    assert piece.max_polyphony() == (3, 1.5)
    # notes that touch (one ends where the next starts) do not overlap
    assert Piece((Note(0, 60, 1), Note(1, 62, 2))).max_polyphony()[0] == 1


def test_a_note_has_a_hand_or_none():
    assert Note(0, 60, 1).hand is None  # one-hand pieces and files are unchanged
    assert Note(0, 60, 1, hand="left").hand == "left"
    with pytest.raises(PianobotError, match="'right', 'left' or None"):
        Note(0, 60, 1, hand="both")


def test_parts_and_hands_of_a_piece():
    piece = Piece((Note(0, 72, 1), Note(0, 48, 1), Note(1, 50, 2)), bpm=90).with_hands(["left", "right", "left"])
    assert [n.hand for n in piece] == ["left", "right", "left"]  # in the piece's order: 48, 72, 50
    assert piece.hands == ("right", "left")
    assert [n.pitch for n in piece.part("left")] == [48, 50] and piece.part("left").bpm == 90
    assert [n.pitch for n in piece.part("right")] == [72]
    assert len(piece.part(None)) == 0 and piece.with_hands(None).hands == ()
    assert piece.with_hands("right").hands == ("right",)
    with pytest.raises(ValueError):
        piece.with_hands(["left"])
    # hands take part in equality: a piece given to other hands is another piece
    assert piece != piece.with_hands(None)


def test_the_mirror_keeps_every_key_colour_and_place():
    from pianobot.music.instrument import KeyboardSpec
    from pianobot.music.piece import mirror_pitch
    from pianobot.sim.keyboard import KeyboardConfig, key_boxes

    assert mirror_pitch(62) == 62 and mirror_pitch(60) == 64 and mirror_pitch(21) == 103
    for pitch in range(0, 125):
        assert KeyboardSpec.is_black(mirror_pitch(pitch)) == KeyboardSpec.is_black(pitch)
        assert mirror_pitch(mirror_pitch(pitch)) == pitch
    # on a keyboard laid out symmetrically about D4 (A0-G7), a key and its mirror image lie at
    # the same distance from the middle: the left hand's geometry is the right hand's, reflected
    boxes = key_boxes(KeyboardConfig(spec=KeyboardSpec(21, 83)))
    x = {box.pitch: box.center[0] for box in boxes}
    middle = x[62]
    for pitch in range(21, 104):
        assert x[mirror_pitch(pitch)] - middle == pytest.approx(middle - x[pitch], abs=1e-9)
    with pytest.raises(PianobotError, match="no mirror image"):
        mirror_pitch(126)


def test_mirroring_a_left_hand_part_gives_a_right_hand_part():
    left = Piece((Note(0, 48, 1, finger=1, hand="left"), Note(1, 43, 2, finger=5, hand="left")))
    mirrored = left.mirror()
    assert [(n.pitch, n.finger, n.hand) for n in mirrored] == [(76, 1, "right"), (81, 5, "right")]
    assert mirrored.mirror() == left
    assert Piece((Note(0, 60, 1),)).mirror().notes[0].hand is None


@pytest.mark.parametrize("onset, offset", [(0.0, -1.797693134862316e305), (-1e300, 1.0), (float("nan"), 1.0)])
def test_times_far_out_of_range_are_one_clear_error(onset, offset):
    """A PIG file's offset of -1.8e305 s overflowed rounding to milliseconds (a traceback, found by the
    fuzz test); every such time is now said as what it is."""
    with pytest.raises(PianobotError, match="times must be"):
        Note(onset=onset, pitch=60, offset=offset)
