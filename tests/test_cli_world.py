"""The commands in a user's tool chain: JSON on standard output, scoring a part against its
source, fingering written by pretty_midi, a two-hand file read without --hand."""

import json
from pathlib import Path

import pretty_midi
from typer.testing import CliRunner

from pianobot.cli.app import app
from pianobot.music.midi_io import read_midi, write_midi
from pianobot.music.piece import Note, Piece

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_score_and_inspect_write_json_to_standard_output(tmp_path):
    song = EXAMPLES / "twinkle.mid"
    scored = run("score", song, song, "--json", "-")
    assert scored.exit_code == 0, scored.output
    assert json.loads(scored.stdout)["f1"] == 1.0 and "note F1" in scored.stderr
    assert not (Path.cwd() / "-").exists()
    inspected = run("inspect", song, "--json", "-")
    assert inspected.exit_code == 0, inspected.output
    found = json.loads(inspected.stdout)
    assert found["notes"] == 14 and found["playable"] and all(p["trained"] for p in found["phrases"])
    assert found["range"] == ["C4", "A4"] and [len(p["notes"]) for p in found["phrases"]] == [4, 5, 5]


def test_score_compares_a_transposed_one_hand_part_with_its_source(tmp_path):
    right = [Note(i * 0.5, 64 + i, i * 0.5 + 0.4, 80, 2 + i % 3) for i in range(4)]
    left = [Note(i * 0.5, 40 + i, i * 0.5 + 0.4, 70) for i in range(4)]
    source = tmp_path / "both.mid"
    write_midi(Piece(tuple(right + left), bpm=120), source)
    played = write_midi(
        Piece(tuple(Note(n.onset, n.pitch - 3, n.offset, n.velocity) for n in right), bpm=120), tmp_path / "p.mid"
    )
    plain = json.loads(run("score", played, source, "--json", "-").stdout)
    assert plain["f1"] < 0.5  # against both hands, untransposed
    result = run("score", played, source, "--hand", "right", "--transpose", "-3", "--json", "-")
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["f1"] == 1.0


def test_fingering_written_by_pretty_midi_is_read(tmp_path):
    """pretty_midi writes every lyric into the first track, away from the notes."""
    midi = pretty_midi.PrettyMIDI(initial_tempo=120)
    piano = pretty_midi.Instrument(0)
    for i, (pitch, finger) in enumerate([(60, 2), (64, 3), (67, 4)]):
        piano.notes.append(pretty_midi.Note(80, pitch, i * 0.5, i * 0.5 + 0.4))
        midi.lyrics.append(pretty_midi.Lyric(str(finger), i * 0.5))
    midi.instruments.append(piano)
    midi.write(str(tmp_path / "pm.mid"))
    for track in (None, 1):
        assert [n.finger for n in read_midi(tmp_path / "pm.mid", track=track).notes] == [2, 3, 4]


def test_a_two_hand_file_read_without_hand_plays_both_and_says_hand_plays_one(tmp_path):
    notes = [Note(i * 0.5, 72 + i, i * 0.5 + 0.4, 80) for i in range(4)] + [
        Note(i * 0.5, 36 + i, i * 0.5 + 0.4, 70) for i in range(4)
    ]
    song = write_midi(Piece(tuple(notes), bpm=120), tmp_path / "two.mid")
    result = run("inspect", song)
    text = " ".join(result.stdout.split())
    assert result.exit_code == 0 and "plays both" in text and "--hand right|left plays one" in text, result.output
    assert "left hand: 4 notes, C2-D#2, assigned by the fingering planner" in text
    assert run("inspect", song, "--hand", "right").exit_code == 0


def streams(video: Path) -> str:
    import subprocess

    import imageio_ffmpeg

    return subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-i", str(video)], capture_output=True, text=True).stderr


def play_one_note(tmp_path, *extra):
    return run("play", EXAMPLES / "one-note.mid", "-o", tmp_path / "o.mid", "--controller", "scripted", *extra)


def test_the_video_carries_the_sound(tmp_path):
    from pianobot.perform.audio import has_fluidsynth

    result = play_one_note(tmp_path, "--video", tmp_path / "v.mp4")
    assert result.exit_code == 0, result.output
    info = streams(tmp_path / "v.mp4")
    assert "Video: h264" in info and "Audio: aac" in info
    font = Path("/usr/share/sounds/sf2/TimGM6mb.sf2")
    if has_fluidsynth() and font.exists():  # `make sound` installs both
        result = play_one_note(
            tmp_path, "--video", tmp_path / "v.mp4", "--soundfont", font, "--wav", tmp_path / "s.wav"
        )
        assert result.exit_code == 0 and "FluidSynth with TimGM6mb.sf2" in result.output, result.output


def test_a_soundfont_that_cannot_be_used_is_one_line(tmp_path):
    missing = play_one_note(tmp_path, "--wav", tmp_path / "s.wav", "--soundfont", tmp_path / "none.sf2")
    assert missing.exit_code == 2 and "does not exist" in missing.stderr
    (tmp_path / "fake.sf2").write_bytes(b"not a soundfont at all")
    fake = play_one_note(tmp_path, "--wav", tmp_path / "s.wav", "--soundfont", tmp_path / "fake.sf2")
    assert fake.exit_code == 2 and "not a SoundFont 2" in fake.stderr
    assert not (tmp_path / "o.mid").exists()  # refused before playing


def test_long_tables_stop_at_100_rows_unless_all_is_asked(tmp_path):
    notes = tuple(Note(i * 0.25, 60 + (i % 5) * 2, i * 0.25 + 0.2, 80, 2 + i % 3) for i in range(150))
    song = write_midi(Piece(notes, bpm=120), tmp_path / "long.mid")
    short = run("inspect", song)
    assert short.exit_code == 0, short.output
    assert "the first 100 of 150 notes; --all shows every one" in short.output
    full = run("inspect", song, "--all")
    assert full.exit_code == 0 and "--all shows" not in full.output and " 149 " in full.output
    fingered = run("finger", song, "-o", tmp_path / "f.mid", "--all")
    assert fingered.exit_code == 0 and " 149 " in fingered.output
