"""Two-hand pieces at the reading level (pianobot.music.load.load_hands): hands from track names,
bad input in one line."""

import re
import warnings

import pytest
from conftest import midi_file, off, on

from pianobot.errors import PianobotWarning, SettingError
from pianobot.music.load import LoadOptions, fold_into_piano, load_hands, load_piece
from pianobot.music.piece import Note, Piece
from pianobot.music.pig import write_pig
from pianobot.pianist.assign import load_two_hands


def warning_lines(read, *args):
    """``read(*args)`` and the PianobotWarning lines it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = read(*args)
    return result, [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]


def _track(*notes):
    """(tick, message) events of (pitch, start beat, end beat) notes, 480 ticks a beat."""
    return [event for p, a, b in notes for event in ((round(a * 480), on(p)), (round(b * 480), off(p)))]


def test_tracks_named_for_hands_give_a_two_hand_piece(tmp_path):
    path = midi_file(
        tmp_path / "hands.mid",
        [("Right Hand", _track((72, 0, 1), (74, 1, 2))), ("Left Hand", _track((48, 0, 2)))],
    )
    piece = load_hands(path)
    assert [(n.pitch, n.hand) for n in piece] == [(48, "left"), (72, "right"), (74, "right")]


def test_notes_beyond_the_pianos_keys_are_refused_with_the_shift_that_fits(tmp_path):
    path = midi_file(tmp_path / "high.mid", [("Right Hand", _track((110, 0, 1), (60, 1, 2)))])
    with pytest.raises(SettingError, match=r"beyond the piano's 88 keys A0-C8.*D8.*load.transpose -12") as e:
        load_hands(path)
    assert e.value.field == "load.transpose"
    assert [n.pitch for n in load_hands(path, LoadOptions(transpose=-12))] == [98, 48]


def test_notes_beyond_the_pianos_keys_no_shift_fits_are_played_octaves_in(tmp_path):
    # A#-1 and G9 lie 116 keys apart: no octave shift brings both on, so each comes the fewest octaves in,
    # the A#-1 (A#0) dropped where the file's own A#0 already sounds, and the reading says so in one line
    left, right = _track((10, 0, 1), (22, 0, 2)), _track((60, 0, 1), (127, 1, 2))
    path = midi_file(tmp_path / "wide.mid", [("Right Hand", right), ("Left Hand", left)])
    with pytest.warns(PianobotWarning) as said:
        piece = load_hands(path)
    assert sorted((n.pitch, n.onset, n.hand) for n in piece) == [
        (22, 0.0, "left"),
        (60, 0.0, "right"),
        (103, 0.5, "right"),
    ]
    lines = [str(w.message) for w in said if "beyond the piano" in str(w.message)]
    assert len(lines) == 1 and "G9 at 0.500 s as G7" in lines[0] and "1 dropped" in lines[0], lines
    # one hand's reading (load_piece) plays them so too
    assert sorted(n.pitch for n in load_piece(path)) == [22, 60, 103]
    # where a shift by octaves fits, nothing is moved: load_piece keeps the notes as written, load_hands refuses them
    high = midi_file(tmp_path / "high.mid", [("Right Hand", _track((110, 0, 1), (60, 1, 2)))])
    assert sorted(n.pitch for n in load_piece(high)) == [60, 110]
    # every folded note dropped (C-1 and C#-1 where the file's C1 and C#1 sound while they would): said so
    quiet = midi_file(
        tmp_path / "quiet.mid", [("Piano", _track((24, 1, 3), (25, 0, 4), (0, 0, 2), (1, 1, 2), (127, 0, 1)))]
    )
    with pytest.warns(PianobotWarning, match=r"no octave shift .*: played the fewest octaves in \(G9") as said:
        assert sorted(n.pitch for n in load_piece(quiet)) == [24, 25, 103]
    line = next(str(w.message) for w in said if "beyond the piano" in str(w.message))
    assert "2 dropped where a note of that key sounds while it would" in line, line
    # and where none is left to play, the line says so rather than "played"
    every = Piece((Note(0, 24, 1), Note(0, 103, 1), Note(0.5, 0, 1), Note(0.5, 127, 1)))
    with pytest.warns(PianobotWarning, match=r"brings them all on: none played, 2 dropped"):
        assert fold_into_piano(every, "every.mid") == Piece((Note(0, 24, 1), Note(0, 103, 1)))


def test_hands_that_cross_are_said_in_one_line_and_the_planner_gives_the_hands(tmp_path):
    path = midi_file(
        tmp_path / "cross.mid",
        [("Right Hand", _track((60, 0, 2))), ("Left Hand", _track((48, 0, 1), (67, 1, 2)))],
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read = load_hands(path)
    said = [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]
    assert len(said) == 1 and re.search(r"hands cross at 0.500 s: the left hand's G4 .* right hand's C4", said[0])
    assert "the fingering planner gives every note a hand" in said[0] and "load.hand right" in said[0]
    assert all(n.hand is None for n in read.notes)  # (not the file's: load_two_hands gives them)
    both = load_two_hands(path)
    assert set(both.hands) == {"right", "left"}
    for a in both.part("left").notes:  # no left-hand note at or above a right-hand note sounding with it
        assert all(a.pitch < b.pitch for b in both.part("right").notes if a.onset < b.offset and b.onset < a.offset)
    # a legato overlap (the left hand's note let go just after the right hand's starts) is no crossing
    legato = midi_file(
        tmp_path / "legato.mid",
        [("Right Hand", _track((64, 2, 3))), ("Left Hand", _track((67, 0, 2.1)))],  # 2.1 beats: 50 ms late
    )
    assert load_hands(legato).hands == ("right", "left")


def test_three_unnamed_staves_are_read_as_one_part_said_in_one_line(tmp_path):
    path = midi_file(
        tmp_path / "satb.mid",
        [("Soprano", _track((72, 0, 1))), ("Alto", _track((67, 0, 1))), ("Tenor", _track((60, 0, 1)))],
    )
    piece, lines = warning_lines(load_hands, path)
    assert lines == [
        "satb.mid has 3 tracks of notes, 3 not named for a hand: their notes are given to the hands by the fingering planner "
        "(to play some of them alone, name those with load.track)"
    ]
    assert len(piece) == 3 and piece.hands == ()


def test_one_hand_options_are_refused_and_a_two_hand_pig_file_is_read(tmp_path):
    with pytest.raises(SettingError, match="drop load.hand"):
        load_hands(tmp_path / "x.mid", LoadOptions(hand="right"))
    piece = Piece((Note(0, 72, 1, finger=3, hand="right"), Note(0, 48, 1, finger=5, hand="left")))
    path = write_pig(piece, tmp_path / "both.txt")
    assert load_hands(path) == piece


def test_a_pig_sidecar_with_both_hands_gives_the_notes_of_an_unnamed_file_their_hands(tmp_path):
    from pianobot.music.midi_io import write_midi

    written = Piece((Note(0, 72, 0.5, finger=3, hand="right"), Note(0, 48, 1, finger=5, hand="left")), bpm=120)
    path = write_midi(written.with_hands(None).without_fingering(), tmp_path / "song.mid")  # one unnamed track
    write_pig(written, tmp_path / "song_fingering.txt")
    assert load_hands(path) == written
    slow = load_hands(path, LoadOptions(tempo=60, transpose=2))  # re-timed and moved: the hands stay
    assert [(n.pitch, n.offset, n.finger, n.hand) for n in slow] == [(50, 2.0, 5, "left"), (74, 1.0, 3, "right")]


def test_a_voice_beside_the_piano_is_said_with_the_track_that_leaves_it_out(tmp_path):
    """A song's file: a voice (General MIDI program 52, a choir) and a piano track. Its notes are played
    by the hands as every track's are, but said, with the --track that plays the piano alone; a file
    of instruments none of which is a keyboard (a quartet, reduced for the hands) is not."""
    import mido

    voice = [(0, mido.Message("program_change", program=52, channel=3))] + _track((74, 0, 1))
    path = midi_file(tmp_path / "song.mid", [("Voice", voice), ("Piano", _track((48, 0, 1), (72, 0, 1)))])
    piece, lines = warning_lines(load_hands, path)
    assert len(piece) == 3
    assert lines == [
        "song.mid: track(s) 1 'Voice' (General MIDI ensemble) play no keyboard instrument, and their notes are "
        "played by the hands too; to play the keyboard's alone, name its tracks with load.track 2"
    ]
    # a chorale whose voices set voice programs ("Bass" names a hand, but sings): no keyboard, nothing said
    choir = [(0, mido.Message("program_change", program=52))]
    satb = [
        (name, choir + _track((p, 0, 1))) for name, p in (("Soprano", 72), ("Alto", 67), ("Tenor", 60), ("Bass", 48))
    ]
    assert not [
        line for line in warning_lines(load_hands, midi_file(tmp_path / "satb.mid", satb))[1] if "keyboard" in line
    ]
    # a piano beside an electric bass named "Bass" (program 33): the bass is said, by its program
    bass = [(0, mido.Message("program_change", program=33))] + _track((40, 0, 1))
    band = midi_file(tmp_path / "band.mid", [("Piano", _track((72, 0, 1))), ("Bass", bass)])
    assert [line for line in warning_lines(load_hands, band)[1] if "keyboard" in line] == [
        "band.mid: track(s) 2 'Bass' (General MIDI bass) play no keyboard instrument, and their notes are played by "
        "the hands too; to play the keyboard's alone, name its tracks with load.track 1"
    ]
    strings = [(0, mido.Message("program_change", program=40))]
    quartet = midi_file(
        tmp_path / "duo.mid", [("Violin", strings + _track((74, 0, 1))), ("Cello", strings + _track((48, 0, 1)))]
    )
    assert warning_lines(load_hands, quartet)[1] == []
