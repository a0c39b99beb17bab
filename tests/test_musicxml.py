"""MusicXML scores in and out: notes, ties, staves as hands, tempo marks, pedal marks and fingering
marks read into a MidiSource (pianobot.music.musicxml); bad scores refused in one line; the
fingered piece written as a score and read back; a fingered score played with its own fingering."""

import json
import sys
import warnings
import zipfile
from pathlib import Path

import mido
import pytest
from conftest import assert_one_line_error, run

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music.midi_file import open_midi
from pianobot.music.midi_io import describe_tracks, read_midi, read_pedal
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Note, Piece

music21 = pytest.importorskip("music21")

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
HEAD = '<?xml version="1.0" encoding="UTF-8"?>\n'


def note(pitch, duration, kind="quarter", staff=None, finger=None, chord=False, tie=None, extra="", notations=""):
    """One <note>: ``pitch`` as 'C4' (step, octave) or 'C#4'."""
    step, alter, octave = pitch[0], 1 if pitch[1] == "#" else 0, pitch[-1]
    text = "<note>" + ("<chord/>" if chord else "") + extra
    text += (
        f"<pitch><step>{step}</step>"
        + (f"<alter>{alter}</alter>" if alter else "")
        + f"<octave>{octave}</octave></pitch>"
    )
    text += f"<duration>{duration}</duration>" + (f'<tie type="{tie}"/>' if tie else "")
    text += f"<type>{kind}</type>" + (f"<staff>{staff}</staff>" if staff else "")
    marks = notations + (f'<tied type="{tie}"/>' if tie else "")
    if finger is not None:
        marks += f"<technical><fingering>{finger}</fingering></technical>"
    return text + (f"<notations>{marks}</notations>" if marks else "") + "</note>"


def pedal(kind, staff=2):
    return f'<direction><direction-type><pedal type="{kind}" line="yes"/></direction-type><staff>{staff}</staff></direction>'


def tempo(bpm):
    return f'<direction><direction-type><words>tempo</words></direction-type><sound tempo="{bpm}"/></direction>'


def score(*parts, names=None):
    """A partwise score of ``parts`` (each a list of measure bodies)."""
    names = names or [f"Part {i + 1}" for i in range(len(parts))]
    listed = "".join(f'<score-part id="P{i + 1}"><part-name>{n}</part-name></score-part>' for i, n in enumerate(names))
    body = "".join(
        f'<part id="P{i + 1}">'
        + "".join(f'<measure number="{m + 1}">{b}</measure>' for m, b in enumerate(part))
        + "</part>"
        for i, part in enumerate(parts)
    )
    return f'{HEAD}<score-partwise version="4.0"><part-list>{listed}</part-list>{body}</score-partwise>'


PIANO_ATTRIBUTES = "<attributes><divisions>2</divisions><time><beats>4</beats><beat-type>4</beat-type></time><staves>2</staves></attributes>"
PIANO = [
    PIANO_ATTRIBUTES
    + tempo(120)
    + pedal("start")
    + note("C5", 2, staff=1, finger=1)
    + note("E5", 2, staff=1, finger="3-1")  # a substitution: its first finger
    + note("G5", 4, "half", staff=1, finger=5, tie="start")
    + "<backup><duration>8</duration></backup>"
    + note("C3", 4, "half", staff=2, finger=5)
    + note("E3", 4, "half", staff=2, chord=True)  # a chord's unfingered note
    + note("G3", 4, "half", staff=2, finger=1, chord=True)
    + pedal("change")
    + note("G3", 4, "half", staff=2, finger=1),
    tempo(60)
    + note("G5", 2, staff=1, tie="stop")
    + note("A5", 1, "eighth", staff=1, finger="x")  # no finger: dropped, said
    + note("B5", 1, "eighth", staff=1)
    + note("D5", 0, "eighth", staff=1, extra="<grace/>")  # a grace note: left out, said
    + note("C6", 4, "half", staff=1, finger=5)
    + "<backup><duration>8</duration></backup>"
    + note("C3", 8, "whole", staff=2, finger=5)
    + pedal("stop"),
]


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def piano_score(tmp_path, name="piano.musicxml"):
    return write(tmp_path / name, score(PIANO, names=["Piano"]))


def read(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        source = open_midi(path)
        piece = read_midi(source)
    return source, piece, [str(w.message) for w in caught if issubclass(w.category, PianobotWarning)]


def test_a_two_staff_score_reads_as_both_hands_with_ties_fingers_tempo_and_pedal(tmp_path):
    source, piece, said = read(piano_score(tmp_path))
    assert source.path.name == "piano.musicxml"
    tracks = {t.name: t for t in describe_tracks(source) if t.notes}
    assert set(tracks) == {"Right Hand", "Left Hand"}
    right = [(pitch_onset(n), n.finger) for n in piece.part("right").notes]
    # 120 bpm in measure 1 (2 s), 60 bpm in measure 2: the tied G5 lasts 1 s + 1 s
    assert right == [((72, 0.0, 0.5), 1), ((76, 0.5, 1.0), 3), ((79, 1.0, 3.0), 5), ((81, 3.0, 3.5), None),
                     ((83, 3.5, 4.0), None), ((84, 4.0, 6.0), 5)]  # fmt: skip
    left = [(pitch_onset(n), n.finger) for n in piece.part("left").notes]
    assert left == [((48, 0.0, 1.0), 5), ((52, 0.0, 1.0), None), ((55, 0.0, 1.0), 1), ((55, 1.0, 2.0), 1),
                    ((48, 2.0, 6.0), 5)]  # fmt: skip
    assert piece.bpm == pytest.approx(120)
    assert any("1 grace note" in line for line in said)
    assert any("1 fingering mark(s) naming two fingers" in line for line in said)
    assert any("dropped 1 fingering mark" in line and "'x'" in line for line in said)
    assert all("\n" not in line and line.startswith("piano.musicxml: ") for line in said)


def pitch_onset(n):
    return (n.pitch, round(n.onset, 3), round(n.offset, 3))


def test_the_sustain_pedal_marks_are_control_change_64_on_the_right_hands_track(tmp_path):
    source, _, _ = read(piano_score(tmp_path))
    right = next(t for t in source.midi.tracks if t.name == "Right Hand")
    tick, pedal = 0, []
    for message in right:
        tick += message.time
        if message.type == "control_change" and message.control == 64:
            pedal.append((tick / source.midi.ticks_per_beat, message.value))
    # down at beat 0, a change at beat 2 (up, then down), up at the end of measure 2 (beat 8)
    assert pedal == [(0, 127), (2, 0), (2, 127), (8, 0)]
    assert {t.name: t.pedal for t in describe_tracks(source)}["Right Hand"] == 2
    # read as the pedal the foot plays: down from 0 s, changed at 1 s (120 bpm), up at 6 s (60 bpm from 2 s)
    assert read_pedal(source) == Pedal(((0.0, 1.0), (1.0, 6.0)))


def test_tempo_changes_are_set_tempo_events(tmp_path):
    source, _, _ = read(piano_score(tmp_path))
    tempos = []
    tick = 0
    for message in source.midi.tracks[0]:
        tick += message.time
        if message.type == "set_tempo":
            tempos.append((tick / source.midi.ticks_per_beat, round(mido.tempo2bpm(message.tempo))))
    assert tempos == [(0, 120), (4, 60)]


def test_a_tuplet_keeps_its_true_length(tmp_path):
    triplet = (
        "<attributes><divisions>3</divisions></attributes>"
        + "".join(
            note(p, 1, "eighth", finger=f).replace(
                "<type>",
                "<time-modification><actual-notes>3</actual-notes><normal-notes>2</normal-notes></time-modification><type>",
            )
            for p, f in (("C4", 1), ("D4", 2), ("E4", 3))
        )
        + note("F4", 3, finger=4)
    )
    _, piece, _ = read(write(tmp_path / "t.xml", score([triplet], names=["Melody"])))
    assert [n.onset for n in piece.notes] == [0, 0.167, 0.333, 0.5]  # (120 bpm, to the ms)
    assert [n.finger for n in piece.notes] == [1, 2, 3, 4]


def test_a_percussion_part_is_left_out_in_one_line_and_a_score_of_only_percussion_refused(tmp_path):
    drum = "<attributes><divisions>1</divisions></attributes><note><unpitched><display-step>C</display-step><display-octave>5</display-octave></unpitched><duration>1</duration><type>quarter</type></note>"
    melody = "<attributes><divisions>1</divisions></attributes>" + note("C4", 1, finger=2)
    _, piece, said = read(write(tmp_path / "band.musicxml", score([melody], [drum], names=["Right Hand", "Drums"])))
    assert [(n.pitch, n.finger, n.hand) for n in piece.notes] == [(60, 2, "right")]
    assert any("percussion" in line for line in said)
    with pytest.raises(PianobotError, match="no pitched notes"):
        open_midi(write(tmp_path / "drums.musicxml", score([drum])))


@pytest.mark.parametrize("named", ["inner/score.xml", "./inner/score.xml"])  # (the second was refused)
def test_a_compressed_score_is_read(tmp_path, named):
    text = score(PIANO, names=["Piano"])
    path = tmp_path / "piano.mxl"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr(
            "META-INF/container.xml",
            f'<container><rootfiles><rootfile full-path="{named}"/></rootfiles></container>',
        )
        archive.writestr("inner/score.xml", text)
        archive.writestr("inner/other.xml", "<not-this/>")  # (more than one: the container decides)
    _, piece, _ = read(path)
    _, plain, _ = read(piano_score(tmp_path))
    assert piece.notes == plain.notes


@pytest.mark.parametrize(
    "name, content, words",
    [
        ("fake.mxl", b"this is no zip file", ["fake.mxl", "not a compressed MusicXML file"]),
        ("cut.musicxml", b"<score-partwise><part-list>", ["cut.musicxml", "not well-formed XML"]),
        ("other.xml", b"<html><body>hi</body></html>", ["other.xml", "no MusicXML score", "<html>"]),
        ("empty.musicxml", score(["<attributes><divisions>1</divisions></attributes>"]).encode(), ["holds no notes"]),
        ("time.musicxml", b'<score-timewise version="4.0"></score-timewise>', ["timewise"]),
    ],
)
def test_a_bad_score_is_one_line_and_exit_2(tmp_path, name, content, words):
    (tmp_path / name).write_bytes(content)
    assert_one_line_error(run("inspect", tmp_path / name), *words)


def test_a_file_named_for_another_kind_says_what_it_holds_and_how_to_name_it(tmp_path):
    """A MIDI file named .xml or .txt, a MusicXML score named .mid, .mxl or with no suffix: one line
    that says what the file holds and the name to give it, which then reads."""
    xml = piano_score(tmp_path).read_bytes()
    midi = (Path(__file__).parent.parent / "examples" / "midi" / "one-note.mid").read_bytes()
    cases = [
        ("song.xml", midi, "holds a MIDI file", "name it song.mid"),
        ("song.txt", midi, "holds a MIDI file", "name it song.mid"),
        ("score.mid", xml, "holds a MusicXML score", "name it score.musicxml"),
        ("score.mxl", xml, "holds a MusicXML score", "name it score.musicxml"),
        ("score", xml, "holds a MusicXML score", "without a suffix", "name it score.musicxml"),
    ]
    for name, data, *words in cases:
        (tmp_path / name).write_bytes(data)
        assert_one_line_error(run("inspect", tmp_path / name), name, *words)
        renamed = tmp_path / words[-1].removeprefix("name it ")
        renamed.write_bytes(data)
        assert run("inspect", renamed).exit_code == 0
    # a file that is none of them keeps its own reason
    (tmp_path / "notes.mid").write_bytes(b"just some words")
    assert_one_line_error(run("inspect", tmp_path / "notes.mid"), "is not a MIDI file", "MThd")


def test_a_zip_without_a_score_is_one_line(tmp_path):
    path = tmp_path / "photos.mxl"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("a.png", b"png")
    assert_one_line_error(run("inspect", path), "photos.mxl", "without one MusicXML score")


def test_without_music21_a_score_is_one_line_naming_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "music21", None)
    assert_one_line_error(run("inspect", piano_score(tmp_path)), "music21", "pip install 'pianobot[musicxml]'")


def fingered_two_hands() -> Piece:
    """Both hands, fingered: a melody over held chords, a triplet, a held note under moving ones."""
    right = [
        Note(i * 0.5, p, i * 0.5 + 0.5, 80, f, "right")
        for i, (p, f) in enumerate(zip((72, 74, 76, 77, 79), (1, 2, 3, 4, 5)))
    ]
    right += [
        Note(2.5 + i / 6, p, 2.5 + (i + 1) / 6, 80, f, "right") for i, (p, f) in enumerate(((77, 4), (76, 3), (74, 2)))
    ]
    left = [Note(0.0, 48, 2.0, 80, 5, "left"), Note(0.0, 55, 1.0, 80, 1, "left"), Note(1.0, 53, 2.0, 80, 2, "left")]
    left += [Note(2.0, 43, 3.0, 80, 5, "left"), Note(2.0, 50, 3.0, 80, 2, "left"), Note(2.0, 55, 3.0, 80, 1, "left")]
    return Piece(tuple(sorted(right + left, key=lambda n: (n.onset, n.pitch))), bpm=120)


@pytest.mark.parametrize("suffix", [".musicxml", ".mxl"])
def test_a_piece_written_as_a_score_reads_back_with_its_pitches_onsets_hands_and_fingers(tmp_path, suffix):
    from pianobot.music.musicxml_out import write_musicxml

    piece = fingered_two_hands()
    path = write_musicxml(piece, tmp_path / f"out{suffix}", name="two hands")
    _, back, said = read(path)
    assert said == []
    key = lambda n: (n.hand, round(n.onset, 3), n.pitch, n.finger)  # noqa: E731
    assert sorted(map(key, back.notes)) == sorted(map(key, piece.notes))
    assert sorted(round(n.offset, 3) for n in back.notes) == sorted(round(n.offset, 3) for n in piece.notes)


def test_onsets_off_the_grid_move_to_the_nearest_sixteenth_or_triplet(tmp_path):
    from pianobot.music.musicxml_out import write_musicxml

    played = Piece((Note(0.0, 60, 0.4, 80, 1), Note(0.52, 62, 0.9, 80, 2), Note(1.13, 64, 1.6, 80, 3)), bpm=120)
    _, back, _ = read(write_musicxml(played, tmp_path / "played.musicxml"))
    step = 60 / 120 / 8  # half the largest gap between grid lines (a sixteenth), in seconds
    assert [n.pitch for n in back.notes] == [60, 62, 64]
    assert all(abs(a.onset - b.onset) <= step for a, b in zip(back.notes, played.notes))


def test_finger_writes_a_score_with_the_planned_fingering(tmp_path):
    song = EXAMPLES / "ode-to-joy.mid"
    result = run("finger", song, "-o", tmp_path / "planned.mid", "--hand-model", "pianist")
    assert result.exit_code == 0, result.output
    result = run("finger", song, "-o", tmp_path / "planned.musicxml", "--hand-model", "pianist")
    assert result.exit_code == 0, result.output
    assert "planned.musicxml" in result.output
    midi, score_ = read_midi(tmp_path / "planned.mid"), read(tmp_path / "planned.musicxml")[1]
    assert [(n.pitch, n.finger) for n in score_.notes] == [(n.pitch, n.finger) for n in midi.notes]
    assert [n.onset for n in score_.notes] == pytest.approx([n.onset for n in midi.notes], abs=0.002)


def test_finger_refuses_another_suffix_naming_the_score_ones(tmp_path):
    line = assert_one_line_error(run("finger", EXAMPLES / "ode-to-joy.mid", "-o", tmp_path / "x.txt"), "*.musicxml")
    assert "MIDI file" in line


def test_a_fingered_score_plays_with_its_own_fingering(tmp_path):
    """Issue 59's done-when: a score rendered from a fingered .mid (not read elsewhere in these tests),
    played by the five-fingered pianist: every note with the score's finger, note F1 >= 0.95 against the .mid."""
    from pianobot.music.musicxml_out import write_musicxml

    midi = EXAMPLES / "c-major-scale.mid"
    score_path = write_musicxml(read_midi(midi), tmp_path / "scale.musicxml", name="scale")
    played = tmp_path / "played.mid"
    args = ["--hand-model", "pianist", "--controller", "scripted", "--json", tmp_path / "r.json"]
    result = run("play", score_path, "-o", played, *args)
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["fingering_accuracy"] == 1.0
    result = run("score", played, midi, "--json", tmp_path / "s.json")
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "s.json").read_text())["f1"] >= 0.95


def test_a_two_staff_score_with_a_few_marks_plays_both_hands_with_them(tmp_path):
    """Both hands of a score that marks some notes only, as pianists mark them: the pianist's hand
    plays every mark (fingering accuracy over the marked notes 1.0), the planner fingering the rest."""
    from pianobot.music.musicxml_out import write_musicxml

    # (not the planner's own choice: index first, the thumb under at F, the left hand from its ring finger)
    right = [(72, 2), (74, None), (76, 4), (77, 1), (79, None), (77, 1), (76, None), (74, None), (72, 2)]
    left = [(48, 4), (52, None), (55, 1), (53, 2), (52, None), (48, 4)]
    notes = [Note(0.4 * i, p, 0.4 * i + 0.4, 80, f, "right") for i, (p, f) in enumerate(right)]
    notes += [Note(0.6 * i, p, 0.6 * i + 0.6, 70, f, "left") for i, (p, f) in enumerate(left)]
    path = write_musicxml(Piece.of(notes, bpm=150), tmp_path / "marked.musicxml", name="marked")
    played = tmp_path / "played.mid"
    args = ["--hand-model", "pianist", "--controller", "scripted", "--json", tmp_path / "r.json"]
    result = run("play", path, "-o", played, *args)
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["f1"] >= 0.95 and report["fingering_accuracy"] == 1.0


def test_a_finger_the_hand_lacks_is_said_in_one_line(tmp_path):
    melody = "<attributes><divisions>1</divisions></attributes>" + note("C4", 1, finger=2) + note("D4", 1, finger=5)
    path = write(tmp_path / "five.musicxml", score([melody], names=["Right Hand"]))
    result = run("play", path, "-o", tmp_path / "out.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert_one_line_error(result, "fingered 5", "--hand-model pianist")
    # no hand model named: the pianist's hand plays the file's fingering as written
    result = run("play", path, "-o", tmp_path / "out.mid", "--controller", "scripted", "--json", tmp_path / "r.json")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["f1"] == 1.0 and report["fingering_accuracy"] == 1.0


def _one_staff(pitches, extra=""):
    attributes = (
        "<attributes><divisions>2</divisions><time><beats>4</beats><beat-type>4</beat-type></time></attributes>"
    )
    return [attributes + extra + "".join(note(p, 2) for p in pitches)]


def test_parts_of_one_name_are_parts_of_their_own_not_one_pianos_staves(tmp_path):
    """Four parts all named "Voice" (music21 gives them their name as their id) were read as one
    piano's staves: the soprano named the right hand, the alto the left, the rest staves 3 and 4."""
    satb = [_one_staff(p) for p in (["E5", "F5"], ["C5", "D5"], ["G4", "A4"], ["C3", "D3"])]
    source, piece, _ = read(write(tmp_path / "satb.musicxml", score(*satb, names=["Voice"] * 4)))
    assert [(t.name, t.notes) for t in describe_tracks(source) if t.notes] == [("Voice", 2)] * 4
    assert piece.hands == ()
    # a piano's two staves are still its hands beside them
    both = score(_one_staff(["G5", "A5"]), PIANO, names=["Piano", "Piano"])
    tracks = [t.name for t in describe_tracks(read(write(tmp_path / "both.musicxml", both))[0]) if t.notes]
    assert tracks == ["Piano", "Right Hand", "Left Hand"]


def test_a_transposing_instruments_part_sounds_where_it_sounds(tmp_path):
    """A B-flat clarinet's written D5 sounds C5 (it was read at the written pitch, a tone high)."""
    clarinet = "<transpose><diatonic>-1</diatonic><chromatic>-2</chromatic></transpose>"
    part = _one_staff(["D5", "E5"])
    part[0] = part[0].replace("</attributes>", clarinet + "</attributes>")
    _, piece, _ = read(write(tmp_path / "clarinet.musicxml", score(part, names=["Clarinet in Bb"])))
    assert [n.pitch for n in piece] == [72, 74]


def test_a_one_staff_parts_pedal_is_read_whatever_music21_calls_the_part(tmp_path):
    part = _one_staff(["C4", "D4"], extra=pedal("start", staff=1))
    source, _, _ = read(write(tmp_path / "pedal.musicxml", score(part, names=["Piano"])))
    assert read_pedal(source).spans[:1] == ((0.0, 1.0),)  # down from the start to the end of the notes


def test_a_tempo_mark_beyond_what_midi_holds_is_read_at_the_nearest_and_said(tmp_path):
    """A mark of 1 quarter a minute (a "rit." written as a tempo) raised a traceback: MIDI's tempo
    field holds no beat that long. Marks outside 10-1000 are read at the nearest end, said once."""
    attributes = (
        "<attributes><divisions>2</divisions><time><beats>2</beats><beat-type>4</beat-type></time></attributes>"
    )
    part = [attributes + tempo(1) + note("C4", 2) + note("D4", 2), tempo(100000) + note("E4", 2) + note("F4", 2)]
    _, piece, said = read(write(tmp_path / "slow.musicxml", score(part, names=["Piano"])))
    assert [round(n.onset, 3) for n in piece] == [0.0, 6.0, 12.0, 12.06]  # 10 bpm, then 1000
    (line,) = [line for line in said if "tempo" in line]
    assert "read 2 tempo mark(s) outside 10-1000" in line and "(such as 1)" in line
    # a two-staff part's one mark (each staff repeats it to music21) is one
    piano = [
        PIANO_ATTRIBUTES
        + tempo(1)
        + note("C5", 2, staff=1)
        + "<backup><duration>2</duration></backup>"
        + note("C3", 2, staff=2)
    ]
    _, _, said = read(write(tmp_path / "piano.musicxml", score(piano, names=["Piano"])))
    assert any("read 1 tempo mark(s)" in line for line in said), said


def test_cue_notes_are_silent_and_keep_the_others_in_time(tmp_path):
    """A <cue/> note (another part's, printed small) was read as a note to play."""
    cue = note("G5", 2, extra="<cue/>")
    part = _one_staff(["C5"])
    part[0] += cue + note("D5", 2) + note("E5", 2, chord=True, extra="<cue/>") + note("F5", 2)
    _, piece, said = read(write(tmp_path / "cue.musicxml", score(part, names=["Piano"])))
    assert [(n.pitch, round(n.onset, 3)) for n in piece] == [(72, 0.0), (74, 1.0), (77, 1.5)]
    assert any("left out 2 cue note(s)" in line for line in said)


def test_a_da_capo_is_said_not_taken(tmp_path):
    part = _one_staff(
        ["C5", "D5"],
        extra='<direction><direction-type><words>D.C.</words></direction-type><sound dacapo="yes"/></direction>',
    )
    _, piece, said = read(write(tmp_path / "dc.musicxml", score(part, names=["Piano"])))
    assert len(piece) == 2 and any("are not expanded" in line for line in said)


def test_repeats_and_endings_are_written_out_with_the_pedal_marks_in_them(tmp_path):
    """|: C5 D5 | 1. E5 F5 :| 2. G5 A5 | plays C5 D5 E5 F5 C5 D5 G5 A5, as a pianist plays it (it was
    played once as written: the first and second endings back to back); a pedal mark in the repeated
    measure is pressed on each pass. A da capo is still said and not taken (the test above)."""
    attributes = (
        "<attributes><divisions>2</divisions><time><beats>2</beats><beat-type>4</beat-type></time></attributes>"
    )
    forward = '<barline location="left"><repeat direction="forward"/></barline>'
    pedal = '<direction><direction-type><pedal type="start"/></direction-type></direction>'
    up = '<direction><direction-type><pedal type="stop"/></direction-type></direction>'
    first = '<barline location="left"><ending number="1" type="start"/></barline>'
    back = '<barline location="right"><ending number="1" type="stop"/><repeat direction="backward"/></barline>'
    second = '<barline location="left"><ending number="2" type="start"/></barline>'
    end = '<barline location="right"><ending number="2" type="discontinue"/></barline>'
    part = [
        attributes + forward + pedal + note("C5", 2) + note("D5", 2) + up,
        first + note("E5", 2) + note("F5", 2) + back,
        second + note("G5", 2) + note("A5", 2) + end,
    ]
    source, piece, said = read(write(tmp_path / "repeats.musicxml", score(part, names=["Piano"])))
    assert [n.pitch for n in piece] == [72, 74, 76, 77, 72, 74, 79, 81]
    assert [n.onset for n in piece] == [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5]
    assert any("repeats are played as a pianist plays them" in line for line in said), said
    downs = [round(t, 3) for t, down in read_pedal(source).changes() if down]
    assert downs == [0.0, 2.0]


def test_a_note_with_two_fingering_marks_is_read_by_its_first_and_said(tmp_path):
    """Two <fingering> marks on one note (a substitution written as two marks: 3 strikes, then 2
    holds) were read by the first and nothing said; an alternate mark is still dropped unsaid."""
    marks = "<technical><fingering>3</fingering><fingering>2</fingering></technical>"
    alternate = '<technical><fingering>4</fingering><fingering alternate="yes">1</fingering></technical>'
    part = _one_staff([])
    part[0] += note("C5", 2, notations=marks) + note("D5", 2, notations=alternate) + note("E5", 2, finger=5)
    _, piece, said = read(write(tmp_path / "two.musicxml", score(part, names=["Piano"])))
    assert [n.finger for n in piece] == [3, 4, 5]
    assert [line for line in said if "two fingering marks" in line] == [
        "two.musicxml: 1 note(s) with two fingering marks read by their first (a substitution's striking finger)"
    ]


def test_repeats_with_a_da_capo_written_as_words_are_played_once_as_written(tmp_path):
    """music21 takes a "D.C. al Fine" written as words; pianobot takes no jump, so such a score's
    repeats are not written out either: played once, as written, said."""
    attributes = (
        "<attributes><divisions>2</divisions><time><beats>2</beats><beat-type>4</beat-type></time></attributes>"
    )
    forward = '<barline location="left"><repeat direction="forward"/></barline>'
    back = '<barline location="right"><repeat direction="backward"/></barline>'
    words = "<direction><direction-type><words>D.C. al Fine</words></direction-type></direction>"
    part = [attributes + forward + note("C5", 2) + note("D5", 2) + back, note("E5", 2) + note("F5", 2) + words]
    _, piece, said = read(write(tmp_path / "dc.musicxml", score(part, names=["Piano"])))
    assert [n.pitch for n in piece] == [72, 74, 76, 77]
    assert any("are not expanded: it is played once, as written" in line for line in said), said
