import warnings

import pytest

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.midi_io import write_midi
from pianobot.music.pig import apply_fingering, read_pig, sidecar_for, write_pig


def test_pig_round_trip(tmp_path, scale):
    path = write_pig(scale, tmp_path / "s_fingering.txt")
    assert path.read_text().splitlines()[0].startswith("//Version")
    assert path.read_text().splitlines()[1].split("\t") == ["0", "0.000000", "1.000000", "C4", "70", "80", "0", "2"]
    assert read_pig(path) == scale.with_fingers([n.finger for n in scale])
    # and read as a piece on its own through the loader
    assert load_piece(path) == scale


def test_pig_hands_substitutions_and_spelled_pitches(tmp_path):
    path = tmp_path / "x.txt"
    path.write_text(
        "//Version: PianoFingering_v170101\n"
        "0\t0.0\t0.5\tBb4\t64\t80\t0\t3_1\n"
        "1\t0.0\t1.0\tC3\t64\t80\t1\t-5\n"
        "2\t0.5\t1.0\tC#5\t64\t80\t0\t+4\n"
    )
    right = read_pig(path)
    assert [(n.pitch, n.finger) for n in right] == [(70, 3), (73, 4)]
    left = read_pig(path, hand="left")
    assert [(n.pitch, n.finger) for n in left] == [(48, 5)]


@pytest.mark.parametrize(
    "line, words",
    [
        ("0\t0.0\t0.5\tC4\t64", "needs 8"),
        ("0\tzero\t0.5\tC4\t64\t80\t0\t2", "must be numbers"),
        ("0\t0.0\t0.5\tC4\t64\t80\t0\t9", "finger '9'"),
        ("0\t0.0\t0.5\tH4\t64\t80\t0\t2", "not a pitch"),
        ("0\t0.0\t0.5\tC4\t64\t80\t3\t2", "channel 3"),
    ],
)
def test_bad_pig_lines_name_the_line(tmp_path, line, words):
    path = tmp_path / "bad.txt"
    path.write_text("//Version: PianoFingering_v170101\n" + line + "\n")
    with pytest.raises(PianobotError, match=words) as e:
        read_pig(path)
    assert "line 2" in str(e.value)


def test_sidecar_is_found_next_to_the_midi_and_applied(tmp_path, scale):
    midi = write_midi(scale.without_fingering(), tmp_path / "song.mid")
    assert load_piece(midi).has_fingering is False
    write_pig(scale, sidecar_for(midi))
    assert sidecar_for(midi).name == "song_fingering.txt"
    assert load_piece(midi) == scale


def test_sidecar_replaces_embedded_fingering_with_a_warning(tmp_path, scale):
    midi = write_midi(scale, tmp_path / "song.mid")
    other = scale.with_fingers([4, 3, 2, 4])
    write_pig(other, sidecar_for(midi))
    with pytest.warns(PianobotWarning, match="replaces"):
        assert load_piece(midi) == other


def test_sidecar_that_does_not_fit_the_notes(tmp_path, scale):
    midi = write_midi(scale, tmp_path / "song.mid")
    write_pig(scale.transpose(1), tmp_path / "wrong.txt")
    with pytest.raises(PianobotError, match="has no note for C4 at 0.000 s"):
        apply_fingering(scale, tmp_path / "wrong.txt")
    with pytest.raises(PianobotError, match="does not exist"):
        load_piece(midi, LoadOptions(fingering=tmp_path / "missing.txt"))


def test_unreadable_sidecar(tmp_path, scale):
    midi = write_midi(scale, tmp_path / "song.mid")
    sidecar_for(midi).write_bytes(b"\xff\xfe\x00binary")
    with pytest.raises(PianobotError, match="cannot read fingering file"):
        load_piece(midi)


def test_sidecar_fingering_survives_retiming(tmp_path, scale):
    midi = write_midi(scale.without_fingering(), tmp_path / "song.mid")
    write_pig(scale, sidecar_for(midi))
    slow = load_piece(midi, LoadOptions(tempo=30))
    assert [n.finger for n in slow] == [2, 3, 4, 2]
    assert slow.notes[1].onset == 2.0


def test_pig_needs_every_finger(tmp_path, scale):
    with pytest.raises(PianobotError, match="needs a finger"):
        write_pig(scale.without_fingering(), tmp_path / "x.txt")


@pytest.mark.parametrize(
    "onset, offset, words",
    [
        ("nan", "0.5", "onset nan"),
        ("0", "inf", "offset inf"),
        ("-inf", "0.5", "onset -inf"),
        ("0", "1e400", "offset inf"),
        ("0", "1e12", "at most 60 minutes"),
        ("3600.5", "3601", "at most 60 minutes"),
    ],
)
def test_pig_times_must_be_finite_and_within_the_limit(tmp_path, onset, offset, words):
    """Without the bound, `score` against a note ending at 1e12 s asked for 2.27 PiB."""
    path = tmp_path / "bad.txt"
    path.write_text(f"//Version: PianoFingering_v170101\n0\t{onset}\t{offset}\tC4\t64\t80\t0\t2\n")
    with pytest.raises(PianobotError, match=words) as e:
        read_pig(path)
    assert "bad.txt line 2" in str(e.value)


def test_a_nan_in_a_sidecar_is_one_clear_error(tmp_path, scale):
    midi = write_midi(scale, tmp_path / "song.mid")
    sidecar_for(midi).write_text("//Version: PianoFingering_v170101\n0\tnan\t1\tC4\t64\t80\t0\t2\n")
    with pytest.raises(PianobotError, match="song_fingering.txt line 2: note C4 has onset nan"):
        load_piece(midi)


def test_long_texts_in_pig_files_are_quoted_short(tmp_path):
    path = tmp_path / "long.txt"
    path.write_text("//Version: PianoFingering_v170101\n0\t0\t1\t" + "Q" * 100_000 + "\t64\t80\t0\t2\n")
    with pytest.raises(PianobotError, match="not a pitch") as e:
        read_pig(path)
    assert len(str(e.value)) < 300 and "…" in str(e.value)


def test_sidecar_matching_takes_the_nearest_unused_note_quickly(tmp_path):
    """Matching looks only at PIG notes of the same pitch near the onset (not every note for every
    note): the lines of Python it runs grow as the notes do, not as their square (the time it takes:
    ``python benchmarks/reading.py``)."""
    import sys

    from pianobot.music.piece import Note, Piece

    def lines_run(notes: int) -> int:
        piece = Piece(tuple(Note(i * 0.1, 60 + i % 12, i * 0.1 + 0.1, 80, 2 + i % 3) for i in range(notes)))
        write_pig(piece, tmp_path / f"{notes}.txt")
        unfingered, count = piece.without_fingering(), [0]

        def trace(frame, event, arg):  # every line of Python it runs, in pig.py and below
            if event == "line":
                count[0] += 1
            return trace

        tracing = sys.gettrace()  # a coverage run's, say
        sys.settrace(trace)
        try:
            matched = apply_fingering(unfingered, tmp_path / f"{notes}.txt")
        finally:
            sys.settrace(tracing)
        assert matched == piece
        return count[0]

    small, large = lines_run(1_000), lines_run(4_000)
    assert large / small < 5  # four times the notes, four times the work; every note against every note: 16
    near = Piece((Note(0.0, 60, 0.5, 80), Note(0.01, 60, 0.5, 80)))
    write_pig(Piece((Note(0.02, 60, 0.5, 80, 3), Note(0.0, 60, 0.5, 80, 2))), tmp_path / "near.txt")
    assert [n.finger for n in apply_fingering(near, tmp_path / "near.txt")] == [2, 3]


def test_pig_with_both_hands_reads_and_writes_each_notes_hand(tmp_path):
    path = tmp_path / "both.txt"
    path.write_text(
        "//Version: PianoFingering_v170101\n"
        "0\t0.0\t0.5\tBb4\t64\t80\t0\t3_1\n"
        "1\t0.0\t1.0\tC3\t64\t80\t1\t-5\n"
        "2\t0.5\t1.0\tC#5\t64\t80\t0\t+4\n"
    )
    both = read_pig(path, hand=None)
    assert [(n.pitch, n.finger, n.hand) for n in both] == [(48, 5, "left"), (70, 3, "right"), (73, 4, "right")]
    written = write_pig(both, tmp_path / "again.txt")
    columns = [line.split("\t") for line in written.read_text().splitlines()[1:]]
    assert [(c[3], c[6], c[7]) for c in columns] == [("C3", "1", "-5"), ("A#4", "0", "3"), ("C#5", "0", "4")]
    assert read_pig(written, hand=None) == both
    assert read_pig(written, hand="left") == both.part("left").with_hands(None)  # one hand's part, as before


def test_a_key_written_twice_at_once_sounds_once_as_in_a_midi_file(tmp_path):
    """Both hands' G3 at one onset, and C5 struck again while it sounds, were kept as written: a
    reference no player can sound (note F1 at most 7/9)."""
    rows = [
        (0.0, 1.0, "C5", 0, "1"),
        (0.5, 1.0, "C5", 0, "2"),
        (1.0, 1.5, "G3", 0, "1"),
        (1.0, 1.5, "G3", 1, "-1"),
    ]
    text = "//Version: PianoFingering_v170101\n" + "".join(
        f"{i}\t{a}\t{b}\t{p}\t64\t80\t{c}\t{f}\n" for i, (a, b, p, c, f) in enumerate(rows)
    )
    (tmp_path / "twice.txt").write_text(text)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        piece = read_pig(tmp_path / "twice.txt", hand=None)
    assert [(n.pitch, n.onset, n.offset) for n in piece] == [(72, 0.0, 0.5), (72, 0.5, 1.0), (55, 1.0, 1.5)]
    said = " ".join(str(w.message) for w in caught)
    assert "G3 at 1.000 s appears twice at once" in said and "C5 starts again at 0.500 s" in said
