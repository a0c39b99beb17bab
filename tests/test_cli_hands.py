"""`pianobot play`, `score` and `inspect` on two-hand files: both hands by default (in one
simulation), one track per hand, the whole piece and each hand reported; `--hand` still
plays one; bad input in one line."""

import json
from pathlib import Path

import mido
import pytest
from conftest import assert_one_line_error, lyric, midi_file, off, on, run

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions, load_hands
from pianobot.music.metrics import compare
from pianobot.music.midi_io import read_midi
from pianobot.pianist.assign import load_two_hands

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"


def _track(*notes):
    """(tick, message) events of (pitch, start beat, end beat) notes, 480 ticks a beat (0.5 s at 120 bpm)."""
    return [event for p, a, b in notes for event in ((round(a * 480), on(p)), (round(b * 480), off(p)))]


RIGHT = _track((72, 0, 1), (74, 1, 2), (76, 2, 3), (77, 3, 4))
LEFT = _track((48, 0, 2), (55, 2, 4))


def _duet(path, names=("Right Hand", "Left Hand"), right=RIGHT, left=LEFT):
    return midi_file(path, [(names[0], right), (names[1], left)])


def _one_track(path, *notes):
    """A type-0 file of one unnamed track: nothing says which hand plays a note."""
    events = sorted(_track(*notes), key=lambda e: e[0])
    track, last = mido.MidiTrack(), 0
    for tick, message in events:
        track.append(message.copy(time=tick - last))
        last = tick
    midi = mido.MidiFile(type=0, ticks_per_beat=480)
    midi.tracks.append(track)
    midi.save(path)
    return path


def test_a_two_hand_file_whose_tracks_all_name_one_hand_plays_both_hands(tmp_path):
    """Both hands' notes in tracks all named for the right hand ("Piano RH" holding everything, or two
    tracks both "Right Hand") were refused: one hand's reading, "the chord C3 C5 ... more than this
    hand reaches". Where the named hand cannot reach a chord, the planner gives the hands."""
    song = _duet(tmp_path / "both-right.mid", names=("Right Hand", "Right Hand"), left=_track((48, 0, 2), (55, 2, 4)))
    args = ("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--json", tmp_path / "r.json")
    result = run(*args)
    assert result.exit_code == 0, result.output
    assert "its tracks name every note for the right hand, which cannot reach all of its chords" in " ".join(
        result.stderr.split()
    )
    text = " ".join(result.stdout.split())
    assert "left hand: 2 notes, C3-G3, assigned by the fingering planner" in text
    assert json.loads((tmp_path / "r.json").read_text())["f1"] == 1.0
    # the fingering written for that one hand is not the other hand's
    fingered = [(0, lyric("3")), *RIGHT[:2], (0, lyric("1")), (0, on(48)), (960, off(48))]
    song = midi_file(tmp_path / "fingered.mid", [("Right Hand", fingered)])
    with pytest.warns(PianobotWarning, match="gives every note a hand and a finger"):
        piece = load_two_hands(song, LoadOptions(), HandSpec(fingers=(1, 2, 3, 4, 5), model="pianist"))
    assert piece.hands == ("right", "left") and all(n.finger is None for n in piece.notes)
    # a part the named hand reaches stays that hand's: one hand, as before
    melody = midi_file(tmp_path / "melody.mid", [("Right Hand", RIGHT)])
    result = run("play", melody, "-o", tmp_path / "m.mid", "--controller", "scripted")
    assert result.exit_code == 0 and "cannot reach all of its chords" not in result.output
    assert "left hand" not in result.stdout


def test_a_file_with_tracks_named_for_hands_plays_both_hands_one_track_each(tmp_path):
    song = _duet(tmp_path / "duet.mid")
    files = ("--html", tmp_path / "r.html", "--wav", tmp_path / "both.wav", "--video", tmp_path / "both.mp4")
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", *files)
    assert result.exit_code == 0, result.output
    import subprocess

    import imageio_ffmpeg

    ffmpeg = [imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(tmp_path / "both.mp4")]
    info = subprocess.run(ffmpeg, capture_output=True, text=True).stderr
    assert "Video: h264" in info and "720x320" in info and "Audio: aac" in info  # both hands, with their sound
    import wave

    import numpy as np

    with wave.open(str(tmp_path / "both.wav")) as sound:  # the left hand's C3 (131 Hz) sounds in it
        rate, samples = sound.getframerate(), np.frombuffer(sound.readframes(sound.getnframes()), np.int16)
    spectrum = np.abs(np.fft.rfft(samples.astype(float)))
    frequencies = np.fft.rfftfreq(len(samples), 1 / rate)
    near = lambda hz: spectrum[np.abs(frequencies - hz) < 2].max()  # noqa: E731
    assert near(130.8) > 5 * near(110.0)  # C3 against A2, which nobody played (right hand alone: 0.6)
    text = " ".join(result.stdout.split())
    assert "both hands in one simulation" in text and "against the piece as read from the file" in text
    assert "right hand: 4 notes, C5-F5, named by its track" in text
    assert "left hand: 2 notes, C3-G3, named by its track" in text
    assert "whole piece" in text and "mirrored about D" in text  # the first screen's table of hands
    tracks = [t.name for t in mido.MidiFile(tmp_path / "out.mid").tracks]
    assert tracks == ["Right Hand", "Left Hand"]
    played = read_midi(tmp_path / "out.mid")
    written = load_hands(song)
    assert [(n.pitch, n.hand) for n in played.notes] == [(n.pitch, n.hand) for n in written.notes]
    assert compare(written, played).f1 == 1.0
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["performer"] == "scripted pianist (both hands in one simulation)"
    assert "one simulation" in report["hands_simulated"] and report["f1"] == 1.0
    assert set(report["hands"]) == {"right", "left"}
    left = report["hands"]["left"]
    assert left["performer"] == "scripted pianist" and left["notes"] == 2 and left["named_by_file"] == 2
    assert left["reference_notes"] == 2 and left["f1"] == 1.0 and left["left_out_or_reduced"] == []
    assert [(n["pitch"], n["hand"]) for n in report["notes"]][:2] == [("C3", "left"), ("C5", "right")]
    page = (tmp_path / "r.html").read_text()
    assert "<section id='hands'>" in page and "both hands in one simulation" in page and "left hand: 2 notes" in page
    assert "<video" in page


def test_hand_still_plays_one_hand_as_before(tmp_path):
    song = _duet(tmp_path / "duet.mid")
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--hand", "right")
    assert result.exit_code == 0, result.output
    assert "one simulation" not in result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert "hands" not in report and report["performer"] == "scripted pianist" and report["reference_notes"] == 4
    assert len(mido.MidiFile(tmp_path / "out.mid").tracks) == 1


def test_notes_one_hand_cannot_play_are_given_to_both_hands_by_the_planner(tmp_path):
    """One unnamed track, a bass under a melody two octaves apart: refused as one hand's part
    (outside its keyboard), so the fingering planner gives its notes to the two hands."""
    song = _one_track(tmp_path / "bass.mid", (72, 0, 1), (74, 1, 2), (40, 0, 2), (43, 2, 4), (76, 2, 4))
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert {h: report["hands"][h]["assigned_by_planner"] for h in report["hands"]} == {"right": 3, "left": 2}
    assert report["f1"] == 1.0


def test_a_one_hand_melody_in_one_unnamed_track_plays_as_before(tmp_path):
    song = _one_track(tmp_path / "melody.mid", (60, 0, 1), (62, 1, 2), (64, 2, 3))
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    assert "hands" not in json.loads((tmp_path / "out.report.json").read_text())


def test_what_a_hand_is_given_is_said_once_per_kind(tmp_path):
    """A left-hand chord wider than three fingers reach (--no-thumb: with the thumb the hand spans
    the octave): one line on the first screen, none twice."""
    left = _track((36, 0, 2), (48, 0, 2), (43, 2, 4))
    song = _duet(tmp_path / "wide.mid", left=left)
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--no-thumb")
    assert result.exit_code == 0, result.output
    lines = [line for line in result.output.splitlines() if "chords wider than this hand reaches" in line]
    assert len(lines) == 1 and lines[0].startswith("left out or reduced: the left hand's part"), result.output
    assert "kept their lowest notes" in lines[0]  # the written bass, not the mirror image's top
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["hands"]["left"]["given_to_the_hand"] == 2 and report["hands"]["left"]["recall"] == 2 / 3
    quiet = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet", "--no-thumb")
    assert "warning: the left hand's part has chords wider" in " ".join(quiet.stderr.split())


def test_both_hands_take_their_thumbs_where_they_keep_more_notes(tmp_path):
    """A right-hand chord of four notes: three fingers keep three of them, the thumb the fourth.
    By default both hands take their thumbs, said in one line, and every note plays; --no-thumb
    plays with three fingers (six notes) and says nothing; a file three fingers play whole keeps them.
    (The Allegro-like hand's rule: named with --hand-model allegro, as both hands are otherwise the pianist's.)"""
    right = _track((72, 0, 2), (76, 0, 2), (79, 0, 2), (84, 0, 2), (81, 2, 4))
    song = _duet(tmp_path / "four.mid", right=right)
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert result.exit_code == 0, result.output
    lines = [line for line in " ".join(result.output.split()).split("warning: ") if "thumbs" in line]
    assert len(lines) == 1 and lines[0].startswith(
        "four.mid: both hands play with their thumbs too: they are given 7 of the notes, three fingers 6 "
        "(--no-thumb plays with three)"
    ), result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["f1"] == 1.0 and report["hands"]["right"]["given_to_the_hand"] == 5
    assert report["hands"]["right"]["fingers"] == report["hands"]["left"]["fingers"] == [1, 2, 3, 4]
    assert report["hands"]["right"]["played_as"].endswith(", with its thumb")
    three = run("play", song, "-o", tmp_path / "three.mid", "--controller", "scripted", "--no-thumb")
    assert three.exit_code == 0, three.output
    assert "thumbs" not in three.output
    three = json.loads((tmp_path / "three.report.json").read_text())["hands"]["right"]
    assert three["given_to_the_hand"] == 4 and three["fingers"] == [2, 3, 4]
    inspected = " ".join(run("inspect", song, "--hand-model", "allegro").output.split())
    assert "both hands play with their thumbs too: they are given 7 of the notes, three fingers 6" in inspected
    whole = _duet(tmp_path / "whole.mid")  # every note given to three fingers: they keep playing
    result = run("play", whole, "-o", tmp_path / "w.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert "thumbs" not in result.output
    assert json.loads((tmp_path / "w.report.json").read_text())["hands"]["left"]["fingers"] == [2, 3, 4]


def test_track_names_the_staves_both_hands_play(tmp_path):
    """A song's voice over two piano staves: --track picks the staves (by indices, or by the name
    they share), the hands play them, the voice is left out; one track is one hand's part."""
    voice = _track((79, 0, 4))
    song = midi_file(tmp_path / "song.mid", [("Voice", voice), ("Piano", RIGHT), ("Piano", LEFT)])
    for track in ("2,3", "Piano"):
        result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--track", track)
        assert result.exit_code == 0, result.output
        assert "both hands" in result.stdout and "right hand: 4 notes, C5-F5" in " ".join(result.stdout.split())
        played = read_midi(tmp_path / "out.mid")
        assert sorted(n.pitch for n in played.notes) == [48, 55, 72, 74, 76, 77]  # (the voice's G5 left out)
    one = run("play", song, "-o", tmp_path / "one.mid", "--controller", "scripted", "--track", "3")
    assert one.exit_code == 0, one.output
    assert "both hands" not in one.stdout and [n.pitch for n in read_midi(tmp_path / "one.mid").notes] == [48, 55]
    assert_one_line_error(run("inspect", song, "--track", "2,9"), "no track '9' (in '2,9')", "separate them with")
    named = midi_file(tmp_path / "named.mid", [("Voice", voice), ("Piano, right", RIGHT), ("Piano, left", LEFT)])
    right = run("play", named, "-o", tmp_path / "r.mid", "--controller", "scripted", "--track", "Piano, right")
    assert right.exit_code == 0, right.output  # (a name with a comma, as a whole)
    assert [n.pitch for n in read_midi(tmp_path / "r.mid").notes] == [72, 74, 76, 77]


def test_inspect_of_one_hand_says_how_many_of_its_notes_the_hand_is_given(tmp_path):
    """A chord wider than the hand reaches loses its lower note: the summary counted only what the
    hand is given (2 notes) and said nothing of the part's 3."""
    song = _duet(tmp_path / "wide.mid", right=_track((60, 0, 1), (79, 0, 1), (72, 1, 2)))
    result = run("inspect", song, "--hand", "right")
    assert result.exit_code == 0, result.output
    text = " ".join(result.stdout.split())
    assert "2 notes," in text and "the right hand's part has 3 notes: the hand is given 2 of them" in text
    whole = run("inspect", _duet(tmp_path / "fits.mid"), "--hand", "right")
    assert "the hand is given" not in whole.stdout


def test_what_both_hands_cannot_do_yet_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":0")  # (as on a desktop: the two hands are what --gui refuses)
    song = _duet(tmp_path / "duet.mid")
    for extra, words in (
        (("--gui",), ("--gui", "shows one hand so far", "--hand right", "--video")),
        (("--controller", "random"), ("'random'", "'scripted'")),
    ):
        assert_one_line_error(run("play", song, "-o", tmp_path / "out.mid", *extra), *words)
    assert not (tmp_path / "out.mid").exists()


# -- bad input (issue 35, item 8) ------------------------------------------------------------------
def test_hands_that_cross_are_one_line_and_the_planner_gives_the_hands(tmp_path):
    song = _duet(tmp_path / "cross.mid", left=_track((48, 0, 2), (79, 2, 4)))
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    said = [line for line in result.stderr.splitlines() if "the hands cross" in line]
    assert len(said) == 1 and "at 1.000 s" in said[0] and "--hand right" in said[0], result.stderr
    text = " ".join(result.stdout.split())
    assert "left hand: 1 note, C3-C3, assigned by the fingering planner" in text, text  # G5 went to the right hand
    assert json.loads((tmp_path / "out.report.json").read_text())["f1"] == 1.0


def test_notes_beyond_the_pianos_keys_are_one_line_named_or_not(tmp_path):
    named = _duet(tmp_path / "named.mid", right=_track((110, 0, 1), (72, 1, 2)))
    unnamed = _one_track(tmp_path / "unnamed.mid", (110, 0, 1), (72, 1, 2), (40, 0, 2))
    for song in (named, unnamed):
        result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted")
        assert_one_line_error(result, "beyond the piano's 88 keys", "--transpose -12")
    # the octaves it suggests count a transposition already given in
    low = _one_track(tmp_path / "low.mid", (21, 0, 1), (33, 1, 2))
    assert_one_line_error(run("inspect", low, "--transpose", "-12"), "beyond the piano's 88 keys", "--transpose 0")
    # one hand's part that a shift fits is refused so too, not sent to widen a keyboard past the piano
    line = assert_one_line_error(
        run("play", named, "--hand", "right", "-o", tmp_path / "out.mid"),
        "beyond the piano's 88 keys",
        "--transpose -12",
    )
    assert "widen the keyboard" not in line
    # notes no shift fits (C-1 and G9 lie 127 keys apart) are played the fewest octaves in, said in one line
    lowest_and_highest = _one_track(tmp_path / "ends.mid", (0, 0, 1), (127, 1, 2))
    result = run("play", lowest_and_highest, "-o", tmp_path / "out.mid", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    said = [line for line in result.stderr.splitlines() if "beyond the piano" in line]
    assert len(said) == 1 and "C-1 at 0.000 s as C1, G9 at 0.500 s as G7" in said[0], result.stderr
    assert json.loads((tmp_path / "out.report.json").read_text())["reference_notes"] == 2


def test_more_notes_at_once_than_two_hands_have_fingers_are_thinned_in_one_line(tmp_path):
    chord = _track(*((p, 0, 2) for p in (36, 40, 43, 48, 52, 55, 60, 64, 67)), (72, 2, 4))
    song = midi_file(tmp_path / "nine.mid", [("Piano", chord)])
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet", "--no-thumb")
    assert result.exit_code == 0, result.output
    said = [line for line in result.stderr.splitlines() if "more than two hands of 3 fingers" in line]
    assert len(said) == 1 and "dropped 3 inner note(s)" in said[0], result.stderr
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert report["reference_notes"] == 7  # the piece as both hands can hold it
    # by default the Allegro-like hands take their thumbs, which hold eight of the nine
    result = run(
        "play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet", "--hand-model", "allegro"
    )
    said = [line for line in result.stderr.splitlines() if "more than two hands of 4 fingers" in line]
    assert len(said) == 1 and "dropped 1 inner note(s)" in said[0], result.stderr


def test_three_staves_are_given_to_the_hands_by_the_planner_said_in_one_line(tmp_path):
    song = midi_file(
        tmp_path / "staves.mid",
        [("Soprano", _track((76, 0, 2))), ("Alto", _track((67, 0, 2))), ("Tenor", _track((43, 0, 2)))],
    )
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet")
    assert result.exit_code == 0, result.output
    said = [line for line in result.stderr.splitlines() if "tracks of notes" in line]
    assert len(said) == 1 and "given to the hands by the fingering planner" in said[0], result.stderr


def test_score_gives_the_whole_piece_and_each_hand_with_its_fingering(tmp_path):
    from pianobot.music.midi_io import write_midi
    from pianobot.music.piece import Note, Piece

    right = [Note(0.5 * i, p, 0.5 * i + 0.4, 80, f, "right") for i, (p, f) in enumerate([(72, 2), (74, 3), (76, 4)])]
    left = [Note(0.0, 48, 0.9, 80, 3, "left"), Note(1.0, 43, 1.4, 80, 4, "left")]
    reference = write_midi(Piece((*right, *left)), tmp_path / "song.mid")
    wrong = Piece((*right, left[0], Note(1.0, 43, 1.4, 80, 2, "left")))  # the left hand's last finger wrong
    played = write_midi(wrong.with_hands(None), tmp_path / "out.mid")  # (no track names: hands from the reference)
    result = run("score", played, reference, "--json", tmp_path / "s.json", "--html", tmp_path / "s.html")
    assert result.exit_code == 0, result.output
    page = (tmp_path / "s.html").read_text()
    assert "<section id='hands'>" in page and "<td>left hand</td><td>2 of 2, 0 extra</td>" in page
    scores = json.loads((tmp_path / "s.json").read_text())
    assert scores["f1"] == 1.0 and scores["fingering_accuracy"] == 4 / 5
    assert {h: scores["hands"][h]["fingering_accuracy"] for h in ("right", "left")} == {"right": 1.0, "left": 0.5}
    assert scores["hands"]["left"]["reference_notes"] == 2
    assert "left hand" in result.stdout and "0.500" in result.stdout
    one = json.loads(run("score", played, reference, "--hand", "right", "--json", "-").stdout)
    assert "hands" not in one and one["reference_notes"] == 3


def test_inspect_shows_each_hand_in_plays_words(tmp_path):
    named = _duet(tmp_path / "duet.mid")
    result = run("inspect", named, "--json", tmp_path / "i.json")
    assert result.exit_code == 0, result.output
    text = " ".join(result.stdout.split())
    assert "right hand: 4 notes, C5-F5, named by its track" in text and "--hand right|left" in text
    assert "both hands in one simulation" in text
    found = json.loads((tmp_path / "i.json").read_text())
    assert found["hands"]["left"] == {
        "notes": 2,
        "range": ["C3", "G3"],
        "named_by_file": 2,
        "lent_by_other_hand": 0,
        "assigned_by_planner": 0,
    }
    unnamed = _one_track(tmp_path / "bass.mid", (72, 0, 1), (74, 1, 2), (40, 0, 2), (43, 2, 4), (76, 2, 4))
    text = " ".join(run("inspect", unnamed).stdout.split())
    assert "left hand: 2 notes, E2-G2, assigned by the fingering planner" in text
    # what play says of the same file, in the same words
    played = run("play", unnamed, "-o", tmp_path / "o.mid", "--controller", "scripted")
    assert "left hand: 2 notes, E2-G2, assigned by the fingering planner" in " ".join(played.stdout.split())
    crossing = _duet(tmp_path / "cross.mid", left=_track((48, 0, 2), (79, 2, 4)))
    text = " ".join(run("inspect", crossing).stdout.split())
    assert "left hand: 1 note, C3-C3, assigned by the fingering planner" in text, text


# -- the two-hand examples (issue 35, item 7) ----------------------------------------------------------
def _play_example_with_both_hands(name, tmp_path) -> float:
    """`pianobot play EXAMPLE --controller scripted` (both hands by default), then `pianobot score`;
    returns note F1 against the original file as read (not against a reduction), which score agrees with."""
    from pianobot.music.load import load_piece

    song, out = EXAMPLES / f"{name}.mid", tmp_path / "out.mid"
    played = run("play", song, "-o", out, "--controller", "scripted", "--quiet")
    assert played.exit_code == 0, played.output
    scored = run("score", out, song, "--json", tmp_path / "s.json", "--no-notes")
    assert scored.exit_code == 0, scored.output
    scores = json.loads((tmp_path / "s.json").read_text())
    assert set(scores["hands"]) == {"right", "left"}
    original = compare(load_piece(song), read_midi(out))
    assert original.reference_notes == scores["reference_notes"] and abs(original.f1 - scores["f1"]) < 1e-9
    return original.f1


def test_a_two_hand_example_plays_both_hands_end_to_end(tmp_path):
    """Ode to Joy over a bass line (tracks named for the hands), about 10 s."""
    assert _play_example_with_both_hands("ode-to-joy-performed", tmp_path) >= 0.95


@pytest.mark.slow
@pytest.mark.parametrize(
    "name", ["chorale-performed", "prelude-performed", "minuet-performed", "twinkle-performed", "nocturne-performed"]
)
def test_the_scripted_pianist_plays_every_two_hand_example_nearly_whole(name, tmp_path):
    """With the pianist's hands (a two-hand file's default): 0.990-1.000 when written (issue 57 asks
    0.99); two notes more missed on any of them fail."""
    assert _play_example_with_both_hands(name, tmp_path) >= 0.985


def test_the_keyboard_options_name_the_keys_each_hand_plays_on(tmp_path):
    song = _duet(tmp_path / "duet.mid")
    args = ("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet")
    report = tmp_path / "out.report.json"
    assert run(*args).exit_code == 0
    default = json.loads(report.read_text())["hands"]
    assert default["right"]["played_as"] == "on C5-B5 (12 keys), the pianist hand"  # the part's own octaves
    assert run(*args, "--lowest-note", "C3", "--keys", "36").exit_code == 0
    hands = json.loads(report.read_text())["hands"]
    assert hands["right"]["played_as"] == "on C3-B5 (36 keys), the pianist hand"
    assert (
        hands["left"]["played_as"] == "mirrored about D, on F2-E5 (36 keys), the pianist hand"
    )  # its mirror image's keys
    assert hands["left"]["f1"] == 1.0


def test_a_pig_file_with_both_hands_channels_plays_both_hands(tmp_path):
    from pianobot.music.piece import Note, Piece
    from pianobot.music.pig import write_pig

    right = [Note(0.5 * i, p, 0.5 * i + 0.4, 80, f, "right") for i, (p, f) in enumerate([(72, 2), (74, 3)])]
    song = write_pig(Piece((*right, Note(0.0, 48, 0.9, 80, 2, "left"))), tmp_path / "duet.txt")
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    assert "left hand: 1 note, C3-C3, named by the PIG channel" in " ".join(result.stdout.split())
    assert json.loads((tmp_path / "out.report.json").read_text())["hands"]["left"]["f1"] == 1.0


def test_finger_writes_each_hands_fingering_one_track_each(tmp_path):
    song = _duet(tmp_path / "duet.mid")
    result = run("finger", song, "-o", tmp_path / "fingered.mid")
    assert result.exit_code == 0, result.output
    fingered = read_midi(tmp_path / "fingered.mid")
    assert fingered.hands == ("right", "left") and fingered.has_fingering
    assert all(n.finger in (1, 2, 3, 4, 5) for n in fingered.notes)  # (the pianist's hands: a two-hand file's)
    assert [(n.pitch, n.hand) for n in fingered.notes] == [(n.pitch, n.hand) for n in load_hands(song).notes]
    text = " ".join(result.stdout.split())
    assert (
        "left hand, fingers 1 (thumb), 2 (index), 3 (middle), 4 (ring), 5 (little) of the pianist hand: wrist" in text
    )
    assert "one track per hand" in text
    allegro = run("finger", song, "-o", tmp_path / "allegro.mid", "--hand-model", "allegro")
    assert allegro.exit_code == 0, allegro.output
    assert all(n.finger in (2, 3, 4) for n in read_midi(tmp_path / "allegro.mid").notes)
    assert "left hand, fingers 2 (index), 3 (middle), 4 (ring): wrist travel" in " ".join(allegro.stdout.split())


def test_both_hands_play_the_packaged_parts_policy_unless_policy_names_another(tmp_path):
    """Both hands with the general policies: by default each hand has the packaged left hand's
    policy (`task-parts`), a melody as a right hand in two voices; --policy left=DIR names the left's
    (and right=DIR the right's); a hand named where there is none, a folder without a policy and
    a controller that plays every phrase itself are refused in one line."""
    from pianobot.agent.general import PACKAGED

    song, models = _duet(tmp_path / "duet.mid"), tmp_path / "models"
    models.mkdir()
    result = run("play", song, "-o", tmp_path / "out.mid", "--models", models, "--json", tmp_path / "r.json", "-q")
    assert result.exit_code == 0, result.output
    hands = json.loads((tmp_path / "r.json").read_text())["hands"]
    assert "task-parts-" in hands["right"]["performer"] and "task-parts-" in hands["left"]["performer"]
    # a right hand in two voices (a note held under the melody) too
    voices = _duet(tmp_path / "voices.mid", right=_track((67, 0, 4), (72, 0, 1), (74, 1, 2), (76, 2, 3), (74, 3, 4)))
    result = run("play", voices, "-o", tmp_path / "v.mid", "--models", models, "--json", tmp_path / "v.json", "-q")
    assert result.exit_code == 0, result.output
    hands = json.loads((tmp_path / "v.json").read_text())["hands"]
    assert "task-parts-" in hands["right"]["performer"] and "task-parts-" in hands["left"]["performer"]
    melody = next(PACKAGED.glob("task-melody-*"))
    named = ("--policy", f"left={melody}", "--json", tmp_path / "two.json", "-q")
    result = run("play", song, "-o", tmp_path / "two.mid", "--models", models, *named)
    assert result.exit_code == 0, result.output
    hands = json.loads((tmp_path / "two.json").read_text())["hands"]
    assert "task-melody-" in hands["left"]["performer"] and "task-parts-" not in hands["left"]["performer"]
    assert "task-parts-" in hands["right"]["performer"]
    one_hand = midi_file(tmp_path / "one.mid", [("Right Hand", RIGHT)])
    named = ("--policy", f"right={melody}", "--json", tmp_path / "right.json", "-q")
    result = run("play", song, "-o", tmp_path / "right.mid", "--models", models, *named)
    assert result.exit_code == 0, result.output
    hands = json.loads((tmp_path / "right.json").read_text())["hands"]
    assert "task-melody-" in hands["right"]["performer"] and "task-parts-" in hands["left"]["performer"]
    one_hand = midi_file(tmp_path / "one.mid", [("Right Hand", RIGHT)])
    refused = run("play", one_hand, "-o", tmp_path / "x.mid", "--policy", f"left={melody}")
    assert_one_line_error(refused, "plays one hand")
    refused = run("play", song, "-o", tmp_path / "x.mid", "--controller", "scripted", "--policy", str(melody))
    assert_one_line_error(refused, "--controller scripted")
    refused = run("play", song, "-o", tmp_path / "x.mid", "--policy", f"left={models}")  # a folder without a policy
    assert_one_line_error(refused, "--policy", "not a trained policy folder")
    refused = run("play", song, "-o", tmp_path / "x.mid", "--policy", f"middle={melody}")
    assert_one_line_error(refused, "--policy", "right=DIR,left=DIR")
    refused = run("play", song, "-o", tmp_path / "x.mid", "--policy", f"left={melody},left={melody}")
    assert_one_line_error(refused, "--policy", "once")
    refused = run(
        "play", song, "-o", tmp_path / "x.mid", "--policy", f"right={melody},{melody}"
    )  # a part without a hand
    assert_one_line_error(refused, "--policy", "right=DIR,left=DIR")


def test_the_parts_policy_plays_through_the_hold_guard_unless_told(tmp_path):
    """By default the packaged parts policy (a `--task parts` one) plays through the hold guard, a
    melody policy named for the left hand alone; --guard hold guards both, --guard none neither.
    The left hand holds C3 and G3 for two beats each: the guard's teacher held them."""
    from pianobot.agent.general import PACKAGED

    song = _duet(tmp_path / "duet.mid")
    (tmp_path / "empty").mkdir()  # an empty model store
    melody = ("--policy", f"left={next(PACKAGED.glob('task-melody-*'))}")
    expected = {
        (): (True, True),
        melody: (True, False),
        (*melody, "--guard", "hold"): (True, True),
        ("--guard", "none"): (False, False),
    }
    for flags, (right, left) in expected.items():
        result = run("play", song, "-o", tmp_path / "out.mid", "--models", tmp_path / "empty", *flags)
        assert result.exit_code == 0, result.output
        hands = json.loads((tmp_path / "out.report.json").read_text())["hands"]
        assert hands["right"]["performer"].startswith("general policy task-parts")
        family = "task-melody" if melody[1] in flags else "task-parts"
        assert hands["left"]["performer"].startswith(f"general policy {family}")
        assert [hands[h]["hold_guard"]["on"] for h in ("right", "left")] == [right, left]
        assert [hands[h]["performer"].endswith("through the hold guard") for h in ("right", "left")] == [right, left]
        assert (hands["left"]["hold_guard"]["held_finger_steps"] > 10) is left


def test_one_hand_of_a_part_wider_than_the_keyboard_names_the_keyboard_that_fits(tmp_path):
    """--hand right of a part wider than the keyboard: with no keys named it plays on the part's own
    octaves, said in one line; with too few keys named, the error says which keyboard plays it (not
    to take one hand, which was asked already), and that keyboard does."""
    song = _duet(tmp_path / "wide.mid", right=_track((67, 0, 1), (99, 1, 2)))  # G4 and D#7
    out = tmp_path / "out.mid"
    own = run("play", song, "--hand", "right", "-o", out, "--controller", "scripted")
    assert own.exit_code == 0 and "played on C4-B7 (48 keys)" in " ".join(own.output.split()), own.output
    line = assert_one_line_error(
        run("play", song, "--hand", "right", "--keys", "30", "-o", out, "--controller", "scripted"),
        "the right hand's part spans G4-D#7",
        "--lowest-note C4 --keys 48",
    )
    assert "--hand" not in line
    fits = run(
        "play", song, "--hand", "right", "--lowest-note", "C4", "--keys", "48", "-o", out, "--controller", "scripted"
    )
    assert fits.exit_code == 0, fits.output


def test_a_melody_that_only_needs_transposing_stays_one_hands(tmp_path):
    """One line of notes above the default keys is one hand's, played on its own octaves (said in
    one line), rather than shared between two hands; with keys named, the error says which
    --transpose plays it."""
    song = _one_track(tmp_path / "high.mid", *((p, i, i + 1) for i, p in enumerate((72, 76, 79, 84, 88, 91, 95))))
    own = run("inspect", song)
    text = " ".join(own.output.split())
    assert own.exit_code == 0 and "played on C5-B6 (24 keys)" in text and "right hand" not in text, text
    line = assert_one_line_error(run("inspect", song, "--keys", "25"), "outside the keyboard C4-C6", "--transpose -12")
    named = run("inspect", song, "--keys", "24")  # the default keys, named: as named
    assert_one_line_error(named, "outside the keyboard C4-B5", "--transpose -12")
    assert "hand" not in line.split("outside")[0]
    assert run("inspect", song, "--transpose", "-12").exit_code == 0


def test_score_of_one_hand_of_a_wide_part_scores_it(tmp_path):
    """score has no keyboard options: --hand right of a part wider than the keyboard is scored as
    written (play refuses it, naming the keyboard that fits)."""
    song = _duet(tmp_path / "wide.mid", right=_track((67, 0, 1), (99, 4, 5)))
    played = run(
        "play",
        song,
        "--hand",
        "right",
        "--lowest-note",
        "C4",
        "--keys",
        "48",
        "-o",
        tmp_path / "p.mid",
        "--controller",
        "scripted",
    )
    assert played.exit_code == 0, played.output
    scored = run("score", tmp_path / "p.mid", song, "--hand", "right", "--json", tmp_path / "s.json")
    assert scored.exit_code == 0, scored.output
    assert json.loads((tmp_path / "s.json").read_text())["f1"] == 1.0


def test_a_one_hand_file_with_chords_is_fingered_once(tmp_path, monkeypatch):
    """Asking whether one hand plays an unfingered file with chords plans its fingering; reading it
    for that hand then reuses the plan rather than planning the same notes again (with no hand model
    named, the pianist's one hand is asked too: one plan more)."""
    from pianobot.pianist import fingering

    calls = []
    planner = fingering.plan_fingering
    monkeypatch.setattr(fingering, "plan_fingering", lambda *a, **k: calls.append(1) or planner(*a, **k))
    fingering._plan.cache_clear()
    song = _one_track(tmp_path / "chords.mid", (60, 0, 1), (64, 0, 1), (62, 1, 2), (65, 1, 2), (64, 2, 3), (67, 2, 3))
    result = run("inspect", song, "--hand-model", "allegro")
    assert result.exit_code == 0, result.output
    assert "playable" in result.stdout and len(calls) == 1, (calls, result.output)
    fingering._plan.cache_clear()
    result = run("inspect", song)
    assert result.exit_code == 0 and "playable" in result.stdout and len(calls) == 3, (calls, result.output)


def test_a_two_hand_files_own_fingering_is_said_to_be_replaced_by_the_planners(tmp_path):
    """Both hands are fingered by the planner (the robot's fingers, the hands kept apart): a file's own
    fingering was dropped without a word; now it is said once, with how to play one hand as fingered."""
    from conftest import lyric

    right = RIGHT + [(round(beat * 480), lyric("3")) for beat in range(4)]
    song = _duet(tmp_path / "fingered.mid", right=right)
    quiet = run(
        "play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet", "--hand-model", "allegro"
    )
    assert quiet.exit_code == 0, quiet.output
    said = " ".join(quiet.stderr.split())
    assert said.count("fingering (4 of 6 notes) is not used with both hands") == 1, said
    pianist = run("play", song, "-o", tmp_path / "pianist.mid", "--controller", "scripted", "--quiet")
    assert (
        pianist.exit_code == 0 and "is not used" not in pianist.stderr
    )  # (a human's marks: the pianist's hands keep them)
    assert "--hand right or --hand left" in said
    plain = run("play", _duet(tmp_path / "plain.mid"), "-o", tmp_path / "p.mid", "--controller", "scripted", "-q")
    assert "is not used with both hands" not in plain.stderr


def test_finger_says_when_the_fingered_file_holds_fewer_notes_than_the_piece(tmp_path):
    left = _track((36, 0, 2), (48, 0, 2), (43, 2, 4))  # a chord wider than three fingers reach: one note goes
    song = _duet(tmp_path / "wide.mid", left=left)
    result = run("finger", song, "-o", tmp_path / "fingered.mid", "--no-thumb")
    assert result.exit_code == 0, result.output
    assert "(one track per hand; 6 of 7 notes, the others reduced away: the warnings say why)" in " ".join(
        result.output.split()
    )
    assert len(read_midi(tmp_path / "fingered.mid").notes) == 6
    # by default the Allegro-like hands take their thumbs, which span the octave: every note, one for a thumb
    thumbs = run("finger", song, "-o", tmp_path / "thumbs.mid", "--hand-model", "allegro")
    assert "both hands play with their thumbs too" in " ".join(thumbs.output.split()), thumbs.output
    fingered = read_midi(tmp_path / "thumbs.mid").notes
    assert len(fingered) == 7 and any(n.finger == 1 for n in fingered)
    whole = run(
        "finger", _duet(tmp_path / "plain.mid"), "-o", tmp_path / "plain-fingered.mid", "--hand-model", "allegro"
    )
    assert "reduced away" not in whole.output


def test_score_of_one_hands_part_off_the_default_keys_reduces_it_as_play_did(tmp_path):
    """play --hand chose the part's own octaves and reduced it there; score reduced it on the default
    keys (where nothing is reduced), so a note play had rightly left out counted as missed."""
    right = _track((84, 0, 1), (91, 0, 1), (100, 0, 1), (86, 1, 2), (88, 2, 3))  # C6 G6 E7: wider than the hand
    song = _duet(tmp_path / "high.mid", right=right)
    out = tmp_path / "out.mid"
    played = run("play", song, "--hand", "right", "-o", out, "--controller", "scripted")
    assert played.exit_code == 0, played.output
    report = json.loads(out.with_suffix(".report.json").read_text())
    scored = run("score", out, song, "--hand", "right", "--json", tmp_path / "s.json")
    assert scored.exit_code == 0, scored.output
    again = json.loads((tmp_path / "s.json").read_text())
    assert again["reference_notes"] == report["reference_notes"] == 4 and again["f1"] == report["f1"]


def test_the_thumbs_count_a_chord_note_three_fingers_reading_thinned(tmp_path):
    """A seven-note chord: read for three fingers (six on two hands) one inner note is thinned
    away before any hand is given it; the hands with their thumbs keep all seven, so they play
    with them (the Allegro-like hand's rule)."""
    chord = _track(*[(p, 0, 2) for p in (48, 52, 55, 60, 64, 67, 72)], (74, 2, 4), (45, 2, 4))
    song = midi_file(tmp_path / "seven.mid", [("Piano", chord)])
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--hand-model", "allegro")
    assert result.exit_code == 0, result.output
    assert "both hands play with their thumbs too: they are given 9 of the notes, three fingers 8" in " ".join(
        result.output.split()
    )
    assert json.loads((tmp_path / "out.report.json").read_text())["f1"] == 1.0


def test_score_reads_the_hands_with_the_fingers_play_chose_whatever_keys_play_named(tmp_path):
    """Hands given by the planner, which splits the notes differently for three fingers and for
    hands with thumbs: play on named keys and score (which names none) read them alike."""
    notes = _track(
        (66, 0, 2), (67, 0, 2), (79, 0, 2), *[(p, 2, 4) for p in (41, 48, 50, 53, 57)],
        *[(p, 4, 6) for p in (65, 66, 70, 71, 74, 78)], *[(p, 6, 8) for p in (46, 48, 50, 53)],
    )  # fmt: skip
    song = midi_file(tmp_path / "chords.mid", [("Piano", notes)])
    played = tmp_path / "out.mid"
    result = run("play", song, "-o", played, "--controller", "scripted", "--lowest-note", "C3", "--keys", "12")
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "out.report.json").read_text())
    scored = run("score", played, song, "--json", tmp_path / "score.json")
    assert scored.exit_code == 0, scored.output
    figures = json.loads((tmp_path / "score.json").read_text())
    assert figures["f1"] == report["f1"]
    for hand in ("right", "left"):
        assert figures["hands"][hand]["f1"] == report["hands"][hand]["f1"], hand


def _fingered_chord(start, end, pitches, fingers):
    """A chord's events, its fingering as a lyric at its onset."""
    return [(start, lyric(fingers)), *((start, on(p)) for p in pitches), *((end, off(p)) for p in pitches)]


def test_a_file_fingered_for_one_hand_that_no_hand_spans_is_both_hands_fingered_anew(tmp_path):
    """An octave chord marked 1 2 3 5 for one hand, as a score marks it for a human hand: the
    pianist's hand spans a sixth, so no fingering of one hand plays it. It was played as written by
    one hand (the little finger striking beside C5, nothing said); both hands now play it, their
    fingering planned anew (the file's is one hand's), said in one line."""
    events = _fingered_chord(0, 480, (60, 64, 67), "1 3 5")
    events += _fingered_chord(480, 960, (60, 64, 67, 72), "1 2 3 5")
    song = midi_file(tmp_path / "octave.mid", [("Piano", events)])
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted")
    assert result.exit_code == 0, result.output
    said = " ".join(result.stderr.split())
    assert "one hand cannot play it (the chord C4 E4 G4 C5 at 0.500 s spans" in said, said
    assert "given to both hands and fingered anew (its fingering is one hand's)" in said, said
    report = json.loads((tmp_path / "out.report.json").read_text())
    assert set(report["hands"]) == {"right", "left"} and report["f1"] == 1.0
    # a fingering with a finger twice in one chord is both hands': kept where they play it
    both = _fingered_chord(0, 480, (60, 64, 67, 69, 72, 76), "5 3 1 1 3 5")
    result = run(
        "play",
        midi_file(tmp_path / "two.mid", [("Piano", both)]),
        "-o",
        tmp_path / "two_out.mid",
        "--controller",
        "scripted",
    )
    assert result.exit_code == 0 and "fingered anew" not in result.stderr, result.output
    notes = json.loads((tmp_path / "two_out.report.json").read_text())["notes"]
    assert {n["pitch"]: n["played_finger"] for n in notes} == {"C4": 5, "E4": 3, "G4": 1, "A4": 1, "C5": 3, "E5": 5}
    # a chord one hand spans keeps its marks and its one hand
    inside = _fingered_chord(0, 480, (60, 64, 67), "1 3 5")
    one = run("inspect", midi_file(tmp_path / "fifth.mid", [("Piano", inside)]))
    assert one.exit_code == 0 and "`pianobot play` plays both" not in " ".join(one.stdout.split())
    assert "3/3 notes fingered in the file" in " ".join(one.stdout.split())
