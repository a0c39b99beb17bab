import pytest

from pianobot.errors import PianobotError, SettingError
from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable, suggest_transpose
from pianobot.music.piece import Note, Piece

KEYS = KeyboardSpec()
HAND = HandSpec()


def test_default_keyboard_is_the_papers_two_octaves():
    assert (KEYS.lowest, KEYS.highest) == (60, 83)
    white = [p for p in KEYS.pitches if not KEYS.is_black(p)]
    assert len(white) == 14 and KEYS.count - len(white) == 10


def test_notes_outside_the_keyboard_are_named_with_a_transpose_hint():
    piece = Piece((Note(0, 48, 1, finger=2), Note(1, 50, 2, finger=3)))  # C3, D3
    with pytest.raises(PianobotError) as e:
        check_playable(piece, KEYS, HAND)
    message = str(e.value)
    assert "C3 at 0.000 s" in message and "D3 at 1.000 s" in message
    assert "load.transpose 12" in message and "keyboard.lowest" in message  # the settings; the CLI names its options
    assert e.value.fields == ("keyboard.lowest", "keyboard.count", "load.transpose")


def test_transpose_suggestion_prefers_octaves_and_fails_for_wide_pieces():
    assert suggest_transpose(Piece((Note(0, 86, 1),)), KEYS) == -12
    assert suggest_transpose(Piece((Note(0, 59, 1), Note(1, 83, 2))), KEYS) is None


def test_more_simultaneous_notes_than_fingers():
    chord = Piece(tuple(Note(0, p, 1) for p in (60, 64, 67, 72)))
    with pytest.raises(PianobotError, match="4 notes sound at once at 0.000 s .* 3 fingers"):
        check_playable(chord, KEYS, HAND)
    check_playable(chord, KEYS, HandSpec(fingers=(1, 2, 3, 4)))


@pytest.mark.parametrize("finger", [1, 5])
def test_fingers_the_hand_lacks(finger):
    piece = Piece((Note(0, 60, 1, finger=finger),))
    with pytest.raises(PianobotError, match=f"fingered {finger}"):
        check_playable(piece, KEYS, HAND)


def test_one_finger_cannot_hold_two_notes():
    piece = Piece((Note(0, 60, 2, finger=2), Note(1, 64, 2, finger=2)))
    with pytest.raises(PianobotError, match="finger 2 is asked to play E4"):
        check_playable(piece, KEYS, HAND)
    legato = Piece((Note(0, 60, 1, finger=2), Note(1, 64, 2, finger=2)))
    check_playable(legato, KEYS, HAND)


def test_empty_piece():
    with pytest.raises(PianobotError, match="no notes"):
        check_playable(Piece(()), KEYS, HAND)


def test_bad_keyboard_specs():
    with pytest.raises(PianobotError):
        KeyboardSpec(lowest=120, count=24)
    with pytest.raises(PianobotError):
        KeyboardSpec(count=0)


def test_the_keyboard_a_piece_needs_is_its_range_rounded_out_to_octaves():
    from pianobot.music.instrument import PIANO, keyboard_for
    from pianobot.music.piece import Note, Piece

    assert (PIANO.lowest, PIANO.highest, PIANO.count) == (21, 108, 88)  # A0-C8
    piece = Piece((Note(0, 50, 1), Note(0, 73, 1)))  # D3 and C#5
    assert (keyboard_for(piece).lowest, keyboard_for(piece).highest) == (48, 83)  # C3-B5
    wide = Piece((Note(0, 21, 1), Note(0, 108, 1)))  # the whole piano: its 88 keys, not C0-B8
    assert keyboard_for(wide) == PIANO


def test_a_one_hand_piece_off_the_default_keys_gets_its_own_octaves_of_at_least_as_many_keys():
    from pianobot.music.instrument import keys_for

    def piece(*pitches):
        return Piece(tuple(Note(i, p, i + 1) for i, p in enumerate(pitches)))

    assert keys_for(piece(60, 83)) == KeyboardSpec()  # on C4-B5: the default
    assert keys_for(piece(84, 91)) == KeyboardSpec(84, 24)  # C6-G6: C6-B7
    assert keys_for(piece(48, 55)) == KeyboardSpec(48, 24)  # C3-G3: C3-B4
    assert keys_for(piece(36, 91)) == KeyboardSpec(36, 60)  # wider: whole octaves C2-B6
    assert keys_for(piece(103, 108)) == KeyboardSpec(85, 24)  # at the top: 24 keys ending at C8
    assert keys_for(piece(12, 60)) == KeyboardSpec()  # a note beyond the piano: left for the reading to refuse
    assert keys_for(piece(48), KeyboardSpec(60, 36)) == KeyboardSpec(48, 36)  # as many keys as the default asked


def test_a_keyboard_past_the_piano_s_end_holds_its_notes_and_a_piano_s_refuses_them_as_the_piano_s():
    """A drill's keyboard may lie past C8 (KeyboardSpec allows it): its notes play there; notes off
    a piano keyboard that lie past the piano too are said as the piano's, not 'widen the keyboard'."""
    high = Piece((Note(0.0, 110, 1.0, 80, 2),))
    check_playable(high, KeyboardSpec(100, 24), HandSpec())
    with pytest.raises(SettingError, match=r"beyond the piano's 88 keys") as refused:
        check_playable(high, KeyboardSpec(), HandSpec())
    assert "widen the keyboard" not in str(refused.value)
