import io
import warnings

import mido
import pytest
from conftest import lyric, midi_file, off, on

from pianobot.errors import PianobotError, PianobotWarning, SettingError
from pianobot.music.finger_text import is_fingering, looks_like_fingering, parse_finger_text
from pianobot.music.midi_file import open_midi
from pianobot.music.midi_io import describe_tracks, read_midi, track_hand, write_midi
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


def test_a_fingering_that_does_not_count_the_chords_notes_leaves_its_track_unfingered(tmp_path):
    """A figured bass of figures 1-5 ("5 3" over one note) refused the file; a list that does not
    give one finger per note is no fingering: the track's numbers are not read, said in one line."""
    events = [(0, lyric("2 3 4")), (0, on(60)), (0, on(64)), (480, off(60)), (480, off(64))]
    events += [(480, lyric("3")), (480, on(65)), (960, off(65))]
    path = midi_file(tmp_path / "f.mid", [("m", events)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    assert [n.finger for n in piece] == [None, None, None]
    (said,) = [str(w.message) for w in caught]
    assert "3 finger(s) for 2 note(s)" in said and "none of the track's numbers is read as fingering" in said


def test_numbers_outside_fingers_1_to_5_are_no_fingering(tmp_path):
    """(They refused the file once: a continuo's figured bass is such a track, see below.)"""
    path = midi_file(tmp_path / "f.mid", [("m", [(0, lyric("7")), (0, on(60)), (480, off(60))])])
    assert [n.finger for n in read_midi(path)] == [None]


def test_finger_text_parsing():
    assert parse_finger_text("3") == [3]
    assert parse_finger_text(" 2, 4 ") == [2, 4]
    assert parse_finger_text("3_1 -") == [3, None]
    assert parse_finger_text("twin-kle") is None
    assert parse_finger_text("") is None
    # a dash or a slash is no substitution here: "2-4" may be a chord's, "6/8" a meter
    for text in ("3-1", "2-4", "1/2", "6/8"):
        assert parse_finger_text(text) is None, text
    # fingering written otherwise, said; lyrics, verse numbers, meters and figures are not
    assert looks_like_fingering("(2)") and looks_like_fingering("1-3-5") and looks_like_fingering("3–1")
    for lyric_text in ("twin-", "Ah", "1.", "12", "6", "3", "2 4", "", "3/4", "6/8", "C7"):
        assert not looks_like_fingering(lyric_text), lyric_text


def test_fingering_written_otherwise_is_said_once_in_a_fingered_track(tmp_path):
    events = [(0, lyric("(2)")), (0, on(60)), (480, off(60)), (480, lyric("1-3-5")), (480, on(62)), (960, off(62))]
    events += [(960, lyric("3")), (960, on(64)), (1440, off(64))]
    verses = [(0, lyric("(2)")), (0, on(48)), (480, off(48)), (480, lyric("1-3")), (480, on(50)), (960, off(50))]
    path = midi_file(tmp_path / "f.mid", [("m", events), ("words", verses)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    assert [n.finger for n in piece if n.pitch >= 60] == [None, None, 3]
    said = [str(w.message) for w in caught if "written like fingering" in str(w.message)]
    assert len(said) == 1 and "2 text(s)" in said[0] and "'(2)' at 0.000 s" in said[0], said  # (not the lyric track's)
    assert "'3_1'" in said[0]


def test_overlapping_notes_of_one_pitch_are_resolved_with_a_warning(tmp_path):
    path = midi_file(
        tmp_path / "o.mid",
        [("a", [(0, on(60)), (960, off(60))]), ("b", [(480, on(60, 100)), (1440, off(60))])],
    )
    with pytest.warns(PianobotWarning, match="starts again"):
        piece = read_midi(path)
    assert [(n.onset, n.offset, n.velocity) for n in piece] == [(0.0, 0.5, 80), (0.5, 1.5, 100)]


def test_many_overlaps_are_said_in_one_line_per_kind(tmp_path):
    """A file with many doubled or cut notes warns once per kind, with the count and the first."""
    beats = [m for i in range(12) for m in ((480 * i, on(60)), (480 * i + 240, off(60)))]  # C4 on every beat
    long = [m for i in range(3) for m in ((1920 * i, on(72)), (1920 * i + 960, off(72)))]  # C5 for two beats
    late = [m for i in range(3) for m in ((1920 * i + 480, on(72)), (1920 * i + 1440, off(72)))]  # again a beat in
    path = midi_file(tmp_path / "d.mid", [("a", beats), ("b", beats), ("c", long), ("d", late)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    said = [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]
    assert len(said) == 2, said
    assert said[0].startswith("12 notes appear twice at once (the first: C4 at 0.000 s"), said
    assert said[1].startswith("3 notes still sound when their key starts again (the first: C5 at 0.000 s"), said
    assert sum(n.pitch == 60 for n in piece) == 12 and sum(n.pitch == 72 for n in piece) == 6


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


def one_note(tmp_path, name="one.mid", tempo=500_000, ticks_per_beat=480, delta=480):
    return midi_file(
        tmp_path / name,
        [("m", [(0, on(64)), (delta, off(64))])],
        ticks_per_beat=ticks_per_beat,
        tempo_events=((0, tempo),),
    )


def test_a_tempo_of_zero_is_refused_unless_the_piece_is_re_timed(tmp_path):
    path = one_note(tmp_path, tempo=0)
    with pytest.raises(PianobotError, match="sets a tempo of 0 .* load.tempo BPM"):
        read_midi(path)
    assert read_midi(path, bpm=60) == Piece((Note(0.0, 64, 1.0, 80),), bpm=60)


def test_extreme_tempos_and_divisions(tmp_path):
    slowest = read_midi(one_note(tmp_path, tempo=0xFFFFFF))  # 16.8 s per beat: 3.6 bpm, within 60 minutes
    assert slowest.notes[0].offset == pytest.approx(16.777, abs=1e-3) and slowest.bpm == 10
    with warnings.catch_warnings(), pytest.raises(SettingError, match="lasts under 1 ms.*load.tempo"):
        warnings.simplefilter("ignore")
        read_midi(one_note(tmp_path, tempo=1))  # a beat of 1 µs: the note lasts under 1 ms
    data = one_note(tmp_path).read_bytes()
    for division, words in ((b"\x00\x00", "0 ticks"), (b"\xe7\x28", "SMPTE")):  # 0; -25 fps x 40
        (tmp_path / "d.mid").write_bytes(data[:12] + division + data[14:])
        with pytest.raises(PianobotError, match=words):
            read_midi(tmp_path / "d.mid")


def test_many_tempo_changes_read_in_time_proportional_to_the_file(tmp_path):
    """Each tick's time is found by bisection, not by walking every tempo change before it: a
    lookup compares its tick with a handful of the 8,000 changes (the time it takes:
    ``python benchmarks/reading.py``)."""
    from pianobot.music.midi_io import _TempoMap

    compared = []

    class Tick(int):  # counts every comparison with the tick looked up (bisect's, or a walk's)
        def __lt__(self, other):
            compared.append(other)
            return int(self) < other

        def __gt__(self, other):
            compared.append(other)
            return int(self) > other

        def __le__(self, other):
            return not self.__gt__(other)

        def __ge__(self, other):
            return not self.__lt__(other)

    midi = mido.MidiFile(ticks_per_beat=480)
    midi.tracks.append(
        mido.MidiTrack(mido.MetaMessage("set_tempo", tempo=400_000 + i % 7, time=10) for i in range(8000))
    )
    tempo_map = _TempoMap(midi, tmp_path / "t.mid")
    most = 0
    times = []
    for tick in range(0, 80_000, 5):
        compared.clear()
        times.append(tempo_map.seconds(Tick(tick)))
        most = max(most, len(compared))
    assert 0 < most <= 16  # log2(8,001) is 13; walking the changes: up to 8,000
    assert times == sorted(times) and times[2] == pytest.approx(10 * 500_000 / 480 / 1e6)


def test_a_piece_longer_than_the_limit_is_refused_with_the_fix(tmp_path):
    """A 40-byte file with one delta time of 0x0FFFFFFF ticks asks for 78 hours of music."""
    huge = one_note(tmp_path, delta=0x0FFFFFFF)
    assert huge.stat().st_size < 64
    with pytest.raises(PianobotError, match="lasts 4,660 minutes.*at most 60 minutes.*cut the file.*load.tempo"):
        read_midi(huge)
    edge = one_note(tmp_path, "edge.mid", ticks_per_beat=1, delta=7199)  # ends at 3599.5 s: inside
    assert read_midi(edge).duration == 3599.5
    with pytest.raises(PianobotError, match="at most 60 minutes"):
        read_midi(edge, bpm=100)  # re-timed slower, it no longer fits


def test_the_header_must_match_the_tracks(tmp_path):
    data = one_note(tmp_path).read_bytes()  # two tracks: tempo and notes
    for count in (b"\xff\xff", b"\x00\x03"):
        (tmp_path / "h.mid").write_bytes(data[:10] + count + data[12:])
        with pytest.raises(PianobotError, match="truncated or its header does not match its tracks") as e:
            read_midi(tmp_path / "h.mid")
        assert "holds 2 complete" in str(e.value)
    (tmp_path / "h.mid").write_bytes(data[:10] + b"\x00\x01" + data[12:])
    with pytest.warns(PianobotWarning, match="header says 1 track"):
        read_midi(tmp_path / "h.mid")


def test_any_track_name_can_be_written_and_read_back(tmp_path, scale):
    from pianobot.music.midi_io import describe_tracks

    for name in ("音 fingered by pianobot", "Ünïcödé — 🎹", "plain latin-1 é"):
        path = write_midi(scale, tmp_path / "n.mid", name=name)
        assert describe_tracks(path)[0].name == name
        assert read_midi(path, track=name) == scale


def test_long_or_multi_line_texts_are_quoted_short_on_one_line(tmp_path):
    events = [(0, lyric("2")), (0, on(64)), (480, off(64)), (480, lyric("9 " * 500_000)), (480, on(65)), (960, off(65))]
    midi_file(tmp_path / "l.mid", [("m", events)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_midi(tmp_path / "l.mid")
    (said,) = [str(w.message) for w in caught if "figured bass" in str(w.message)]
    assert len(said) < 300 and "…" in said
    midi_file(tmp_path / "n.mid", [("m", [(0, lyric("2")), (0, on(64)), (480, lyric("1\n9")), (480, off(64))])])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_midi(tmp_path / "n.mid")
    (said,) = [str(w.message) for w in caught if "figured bass" in str(w.message)]
    assert "\n" not in said and "1\\n9" in said
    with pytest.raises(PianobotError) as e:
        read_midi(tmp_path / "l.mid", track="x" * 10_000)
    assert len(str(e.value)) < 400


def test_a_figured_bass_in_a_tracks_lyrics_is_no_fingering(tmp_path):
    """A continuo's figures (music21 writes them as lyrics) were read as fingers, and a "6" refused the file."""
    continuo = [(0, lyric("6")), (0, on(48)), (480, off(48)), (480, lyric("5")), (480, on(50)), (960, off(50))]
    tune = [(0, lyric("2")), (0, on(72)), (480, off(72)), (480, lyric("3")), (480, on(74)), (960, off(74))]
    path = midi_file(tmp_path / "corelli.mid", [("Violin", tune), ("Continuo", continuo)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    assert [(n.pitch, n.finger) for n in piece] == [(48, None), (72, 2), (50, None), (74, 3)]
    (said,) = [str(w.message) for w in caught]
    assert (
        said.startswith("track 2: its texts hold '6', a number that is no finger 1-5") and "none of its numbers" in said
    )
    assert parse_finger_text("6 5") == [6, 5] and not is_fingering([6, 5]) and is_fingering([1, None, 5])


def test_a_note_of_no_length_is_left_out_in_one_line_and_a_repeated_key_reads_in_either_order(tmp_path):
    """A note-on and its note-off at one tick (music21's grace notes and chord symbols) became a
    note held to the next strike of its key, said to never end."""
    grace = [(0, on(62)), (0, off(62)), (0, on(64)), (480, off(64)), (960, on(62)), (960, off(62))]
    path = midi_file(tmp_path / "grace.mid", [("m", grace)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    assert [(n.onset, n.pitch, n.offset) for n in piece] == [(0.0, 64, 0.5)]
    (said,) = [str(w.message) for w in caught]
    assert said.startswith("track 1: left out 2 note(s) of no length") and "D4 at 0.000 s" in said
    # a second note-off after the key's note-off and its next note-on at one tick ends no note
    stray = [(0, on(60)), (480, off(60)), (480, on(60)), (480, off(60)), (960, off(60))]
    path = midi_file(tmp_path / "stray.mid", [("m", stray)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert [(n.onset, n.offset) for n in read_midi(path)] == [(0.0, 0.5), (0.5, 1.0)]
    # a key struck again at the tick its first note ends: two notes, whichever message comes first
    for order in ([(480, off(60)), (480, on(60))], [(480, on(60)), (480, off(60))]):
        path = midi_file(tmp_path / "again.mid", [("m", [(0, on(60)), *order, (960, off(60))])])
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert [(n.onset, n.offset) for n in read_midi(path)] == [(0.0, 0.5), (0.5, 1.0)]


@pytest.mark.parametrize(
    "name, hand",
    [
        ("Bright Acoustic Piano", None),  # General MIDI program 2's name, as exporters write it
        ("Upright Piano", None),
        ("Copyright 2004 J. Wright", None),
        ("Bassoon", None),
        ("Flower", None),
        ("Piano RH", "right"),
        ("RightHand", "right"),
        ("PianoRight", "right"),
        ("Piano_Right", "right"),
        ("UprightPiano", None),
        ("piano_left", "left"),
        ("Right Hand", "right"),
        ("Treble", "right"),
        ("L.H.", "left"),
        ("Left hand", "left"),
        ("Acoustic Bass", "left"),
        ("Bass", "left"),
        ("Accompaniment", "left"),
    ],
)
def test_a_tracks_name_says_a_hand_by_its_words_not_parts_of_words(name, hand):
    assert track_hand(name) == hand


def test_tracks_named_for_hands_give_each_note_its_hand(tmp_path):
    path = midi_file(
        tmp_path / "two.mid",
        [
            ("Piano RH", [(0, lyric("3")), (0, on(72)), (480, off(72))]),
            ("L.H.", [(0, lyric("5 1")), (0, on(48)), (0, on(55)), (960, off(48)), (960, off(55))]),
            ("Strings", [(480, on(60)), (960, off(60))]),
        ],
    )
    piece = read_midi(path)
    assert [(n.pitch, n.hand, n.finger) for n in piece] == [
        (48, "left", 5),
        (55, "left", 1),
        (72, "right", 3),
        (60, None, None),
    ]
    assert piece.hands == ("right", "left")


def test_a_piece_with_hands_is_written_as_one_track_per_hand_and_read_back_exactly(tmp_path):
    piece = Piece(
        (
            Note(0.0, 72, 0.5, 90, 3, "right"),
            Note(0.0, 48, 1.0, 60, 5, "left"),
            Note(0.0, 55, 1.0, 62, 1, "left"),
            Note(0.5, 74, 1.0, 88, None, "right"),
            Note(0.5, 60, 0.9, 70, 2, None),  # a note nobody has given to a hand
            Note(1.0, 72, 1.5, 80, 4, "left"),  # the same key again, now the left hand's
        ),
        bpm=72,
    )
    path = write_midi(piece, tmp_path / "hands.mid")
    midi = mido.MidiFile(path)
    assert midi.type == 1
    assert [t.name for t in midi.tracks] == ["Right Hand", "Left Hand", "Unassigned"]
    assert read_midi(path) == piece
    # a piece without hands is written as before: one track, type 0
    plain = write_midi(piece.with_hands(None), tmp_path / "plain.mid")
    assert mido.MidiFile(plain).type == 0 and read_midi(plain) == piece.with_hands(None)


def test_a_one_track_files_name_is_its_title_not_a_hand(tmp_path):
    # `pianobot finger` names its track after the song: 'left fingered by pianobot' is no hand
    piece = Piece((Note(0, 60, 1, finger=2),))
    assert read_midi(write_midi(piece, tmp_path / "left.mid", name="left fingered by pianobot")) == piece
    only_right = piece.with_hands("right")  # one hand's notes with their hand: a type 1 file
    assert read_midi(write_midi(only_right, tmp_path / "right.mid")) == only_right


def test_drums_on_channel_10_are_left_out_in_one_line(tmp_path):
    """General MIDI's percussion (channel 10) was read as piano notes: a kick drum became a left hand."""
    melody = [(i * 480, on(72 + i)) for i in range(4)] + [(i * 480 + 400, off(72 + i)) for i in range(4)]
    kit = [(i * 240, on(36 if i % 2 == 0 else 42, 100, channel=9)) for i in range(8)]
    kit += [(i * 240 + 100, off(36 if i % 2 == 0 else 42, channel=9)) for i in range(8)]
    path = midi_file(tmp_path / "band.mid", [("Melody", melody), ("Drums", kit)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_midi(path)
    assert sorted(n.pitch for n in piece.notes) == [72, 73, 74, 75]
    said = [str(w.message) for w in caught if "drum" in str(w.message)]
    assert said == [
        "band.mid: left out 8 drum note(s) on MIDI channel 10 (General MIDI's percussion): they are no piano keys"
    ]
    drums = next(t for t in describe_tracks(path) if t.name == "Drums")
    assert drums.notes == 0 and drums.channels == ()  # (inspect lists the track with no piano notes)
    # a file of nothing but drums says so (it said "has no notes" after the line that left them out)
    only = midi_file(tmp_path / "kit.mid", [("Drums", kit)])
    with pytest.raises(PianobotError, match="holds only drum notes .* no piano keys"):
        read_midi(only)


def test_of_two_tempos_at_one_tick_the_later_holds_for_the_timing_and_for_what_inspect_says(tmp_path):
    """At one tick the file's later set_tempo holds; the reading sorted them by value instead, and
    inspect named the other one."""
    from pianobot.music.midi_io import tempi

    notes = [(0, on(60)), (480, off(60)), (480, on(62)), (960, off(62))]
    path = midi_file(tmp_path / "two-tempos.mid", [("Piano", notes)], tempo_events=((0, 600_000), (0, 750_000)))
    piece = read_midi(path)
    assert piece.bpm == 80 and piece.notes[1].onset == 0.75  # 750000 us a beat: 80 bpm
    assert tempi(path) == [80.0]
    other = midi_file(tmp_path / "other.mid", [("Piano", notes)], tempo_events=((0, 750_000), (0, 600_000)))
    assert read_midi(other).bpm == 100 and tempi(other) == [100.0]


def test_a_key_signature_that_names_no_key_is_no_reason_to_refuse_the_file(tmp_path):
    """Eight sharps, or mode 2, were refused as a corrupt file (mido cannot decode them); pianobot
    reads no key signature, so the notes are read, and mido reads other files as before."""
    for data in (b"\x08\x00", b"\x00\x02"):
        path = midi_file(tmp_path / "k.mid", [("m", [(0, on(60)), (480, off(60))])])
        raw = path.read_bytes()
        meta = b"\x00\xff\x59\x02" + data  # a key signature at tick 0, at the start of the last track
        start = raw.rindex(b"MTrk")
        size = int.from_bytes(raw[start + 4 : start + 8], "big") + len(meta)
        path.write_bytes(raw[:start] + b"MTrk" + size.to_bytes(4, "big") + meta + raw[start + 8 :])
        assert [n.pitch for n in read_midi(path)] == [60]
        assert "key_signature" in [m.type for m in open_midi(path).midi.tracks[-1]]
    with pytest.raises(Exception, match="sharps"):
        mido.MidiFile(file=io.BytesIO(path.read_bytes().replace(b"\x59\x02\x00\x02", b"\x59\x02\x08\x00")))


def test_a_digital_pianos_stream_of_pedal_values_counts_each_press_once(tmp_path):
    """inspect said "pressed 474 times" of a recording with 79 presses: every value of 64 or more counted."""
    values = [0, 70, 90, 127, 100, 30, 0, 80, 127, 64]
    pedal = [(i * 10, mido.Message("control_change", control=64, value=v)) for i, v in enumerate(values)]
    path = midi_file(tmp_path / "p.mid", [("Piano", [(0, on(60)), *pedal, (480, off(60))])])
    (track,) = [t for t in describe_tracks(path) if t.notes]
    assert track.pedal == 2
