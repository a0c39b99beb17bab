import warnings

import mido
import pytest
from conftest import lyric, midi_file, off, on

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.midi_io import parse_finger_text, read_midi, write_midi
from pianobot.music.piece import Note, Piece


def test_write_read_round_trip_keeps_notes_velocities_and_fingers(tmp_path, scale):
    path = write_midi(scale, tmp_path / "a.mid")
    assert read_midi(path) == scale


def test_round_trip_with_chords_partial_fingering_and_odd_times(tmp_path):
    piece = Piece(
        (
            Note(0.0, 60, 0.5, 30, 2),
            Note(0.0, 64, 0.5, 99, 4),
            Note(0.333, 62, 0.901, 127, None),
            Note(0.7, 67, 1.234, 1, 3),
            Note(1.5, 60, 2.0, 64, None),
            Note(1.5, 72, 2.0, 64, 4),
        ),
        bpm=93,
    )
    assert read_midi(write_midi(piece, tmp_path / "b.mid")) == piece


def test_tempo_map_is_respected(tmp_path):
    # 480 ticks per beat; 120 bpm for the first beat, then 60 bpm
    path = midi_file(
        tmp_path / "t.mid",
        [("melody", [(0, on(60)), (480, off(60)), (480, on(62)), (960, off(62)), (960, on(64)), (1440, off(64))])],
        tempo_events=((0, 500_000), (480, 1_000_000)),
    )
    piece = read_midi(path)
    assert [(n.onset, n.offset) for n in piece] == [(0.0, 0.5), (0.5, 1.5), (1.5, 2.5)]
    assert piece.bpm == 120
    # --tempo re-times at a constant tempo, ignoring the map
    slow = read_midi(path, bpm=60)
    assert [(n.onset, n.offset) for n in slow] == [(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)]


def test_tracks_are_merged_or_chosen_by_index_or_name(tmp_path):
    path = midi_file(
        tmp_path / "two.mid",
        [
            ("Right", [(0, on(72)), (480, off(72))]),
            ("Left", [(0, on(48, channel=1)), (960, off(48, channel=1))]),
        ],
    )
    assert [n.pitch for n in read_midi(path)] == [48, 72]
    assert [n.pitch for n in read_midi(path, track="1")] == [72]
    assert [n.pitch for n in read_midi(path, track="left")] == [48]
    with pytest.raises(PianobotError, match="no track 'bass'.*1 'Right', 2 'Left'"):
        read_midi(path, track="bass")


def test_fingering_from_lyrics_with_chord_rule(tmp_path):
    path = midi_file(
        tmp_path / "f.mid",
        [
            (
                "m",
                [
                    (0, lyric("4 2")),
                    (0, on(67)),
                    (0, on(60)),
                    (480, off(60)),
                    (480, off(67)),
                    (480, mido.MetaMessage("text", text="la")),
                    (480, on(62)),
                    (960, off(62)),
                ],
            )
        ],
    )
    piece = read_midi(path)
    # fingers are listed lowest pitch first, whatever order the note-ons come in
    assert [(n.pitch, n.finger) for n in piece] == [(60, 4), (67, 2), (62, None)]


def test_fingering_count_must_match_the_chord(tmp_path):
    path = midi_file(
        tmp_path / "f.mid", [("m", [(0, lyric("2 3 4")), (0, on(60)), (0, on(64)), (480, off(60)), (480, off(64))])]
    )
    with pytest.raises(PianobotError, match="3 finger\\(s\\) for 2 note\\(s\\).*lowest pitch first"):
        read_midi(path)


def test_finger_numbers_outside_1_to_5_are_errors(tmp_path):
    path = midi_file(tmp_path / "f.mid", [("m", [(0, lyric("7")), (0, on(60)), (480, off(60))])])
    with pytest.raises(PianobotError, match="finger 7"):
        read_midi(path)


def test_finger_text_parsing():
    assert parse_finger_text("3") == [3]
    assert parse_finger_text(" 2, 4 ") == [2, 4]
    assert parse_finger_text("3_1 -") == [3, None]
    assert parse_finger_text("twin-kle") is None
    assert parse_finger_text("") is None


def test_overlapping_notes_of_one_pitch_are_resolved_with_a_warning(tmp_path):
    path = midi_file(
        tmp_path / "o.mid",
        [("a", [(0, on(60)), (960, off(60))]), ("b", [(480, on(60, 100)), (1440, off(60))])],
    )
    with pytest.warns(PianobotWarning, match="starts again"):
        piece = read_midi(path)
    assert [(n.onset, n.offset, n.velocity) for n in piece] == [(0.0, 0.5, 80), (0.5, 1.5, 100)]


def test_retriggered_note_in_one_track_is_cut_with_a_warning(tmp_path):
    """Legato on a repeated note: the first note-off ends the first note, the second the second."""
    path = midi_file(tmp_path / "r.mid", [("a", [(0, on(60)), (240, on(60)), (480, off(60)), (600, off(60))])])
    with pytest.warns(PianobotWarning):
        piece = read_midi(path)
    assert [(n.onset, n.offset) for n in piece] == [(0.0, 0.25), (0.25, 0.625)]


def test_note_off_and_note_on_at_the_same_tick_keep_both_notes(tmp_path):
    path = midi_file(tmp_path / "s.mid", [("a", [(0, on(60)), (480, on(60)), (480, off(60)), (960, off(60))])])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        piece = read_midi(path)
    assert [(n.onset, n.offset) for n in piece] == [(0.0, 0.5), (0.5, 1.0)]


@pytest.mark.parametrize(
    "content, words",
    [
        (b"", "not a MIDI file"),
        (b"hello world", "not a MIDI file"),
        (b"MThd\x00\x00\x00\x06\x00\x01\x00\x02", "not a readable MIDI file"),
    ],
)
def test_files_that_are_not_midi(tmp_path, content, words):
    path = tmp_path / "bad.mid"
    path.write_bytes(content)
    with pytest.raises(PianobotError, match=words):
        read_midi(path)


def test_truncated_file(tmp_path, scale):
    data = (write_midi(scale, tmp_path / "full.mid")).read_bytes()
    path = tmp_path / "cut.mid"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(PianobotError, match="truncated or corrupt"):
        read_midi(path)


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(PianobotError, match="no such file"):
        read_midi(tmp_path / "nope.mid")
    with pytest.raises(PianobotError, match="is a folder"):
        read_midi(tmp_path)


def test_writing_is_atomic_and_never_leaves_partial_files(tmp_path, scale):
    target = tmp_path / "keep.mid"
    target.write_bytes(b"precious")
    with pytest.raises(PianobotError):
        write_midi(scale, tmp_path / "missing-folder" / "x.mid")
    write_midi(scale, target)
    assert read_midi(target) == scale
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.mid"]
