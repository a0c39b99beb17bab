"""Errors in one layer: typer refuses an option's value outside its choices, the library names the
setting at fault by its field, and the command line names the option that sets it."""

from pathlib import Path

import pytest
import typer.main
from conftest import assert_one_line_error, midi_file, off, on, run
from typer.testing import CliRunner

from pianobot.cli import flags
from pianobot.cli.app import app
from pianobot.cli.options import READING, Controller, Learner
from pianobot.errors import SettingError
from pianobot.learn.config import LEARNERS
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.midi_io import read_midi
from pianobot.perform.controllers import CONTROLLERS

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
SONG = EXAMPLES / "one-note.mid"
runner = CliRunner()


@pytest.mark.parametrize(
    "args, option, bad",
    [
        (("play", SONG, "-o", "x.mid", "--controller", "robot"), "--controller", "robot"),
        (("play", SONG, "-o", "x.mid", "--guard", "always"), "--guard", "always"),
        (("train", SONG, "--learner", "ppo"), "--learner", "ppo"),
        (("train", SONG, "--cluster", "slurm"), "--cluster", "slurm"),
        (("train", SONG, "--device", "gpu"), "--device", "gpu"),
        (("train", SONG, "--actor", "cnn"), "--actor", "cnn"),
        (("inspect", SONG, "--hand", "middle"), "--hand", "middle"),
        (("score", SONG, SONG, "--hand", "both"), "--hand", "both"),
    ],
)
def test_a_value_outside_the_choices_is_typers_one_line_and_exit_2(args, option, bad, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    line = assert_one_line_error(run(*args), f"'{option}'", f"'{bad}'", "is not one of", "--help")
    assert "Usage" not in line


@pytest.mark.parametrize(
    "args, option",
    [
        (("play", SONG, "-o", "x.mid", "--seed", "-1"), "--seed"),
        (("train", SONG, "--seed", "-1"), "--seed"),
        (("play", SONG, "-o", "x.mid", "--phrase-notes", "0"), "--phrase-notes"),
        (("inspect", SONG, "--phrase-notes", "0"), "--phrase-notes"),
        (("train", SONG, "--phrase-notes", "0"), "--phrase-notes"),
    ],
)
def test_a_number_below_its_least_is_one_line_and_exit_2(args, option, tmp_path, monkeypatch):
    """A negative seed reached gymnasium's reset as a traceback; no phrase of 0 notes is played."""
    monkeypatch.chdir(tmp_path)
    assert_one_line_error(run(*args), f"'{option}'", "greater than or equal to")
    assert not (tmp_path / "x.mid").exists()


def test_a_warning_is_said_once_though_the_file_is_read_twice(tmp_path):
    """inspect reads a file for its tracks and again for its hands: a note that never ends was
    said twice."""
    song = midi_file(tmp_path / "open.mid", [("Piano", [(0, on(60)), (480, on(64)), (960, off(64))])])
    result = run("inspect", song)
    assert result.exit_code == 0, result.output
    lines = [line for line in result.stderr.splitlines() if "never ends" in line]
    assert lines == ["warning: track 1: C4 never ends; it ends with the track"], result.stderr


def test_a_model_store_that_is_not_there_is_one_line(tmp_path, monkeypatch):
    """A mistyped --models played the packaged policies without a word."""
    monkeypatch.chdir(tmp_path)  # (no models/ here: the default store may be absent)
    missing = tmp_path / "modles"
    assert_one_line_error(run("play", SONG, "-o", "x.mid", "--models", missing), f"--models {missing}: does not exist")
    assert_one_line_error(run("inspect", SONG, "--models", SONG), "is not a folder")
    assert not (tmp_path / "x.mid").exists()
    assert run("play", SONG, "-o", "x.mid", "--quiet").exit_code == 0  # the default store, absent: packaged policies
    assert run("play", SONG, "-o", "y.mid", "--models", missing, "--controller", "scripted").exit_code == 0
    (tmp_path / "models").write_text("not a store")  # the default store, a file: not "leave --models out"
    line = assert_one_line_error(run("play", SONG, "-o", "z.mid"), "the model store models/ here is a file")
    assert "leave --models out" not in line


def test_a_pig_file_plays_one_hand_from_its_channel(tmp_path):
    pig_file = tmp_path / "duet.txt"
    pig_file.write_text("0 0.0 0.5 C5 80 80 0 3\n1 0.0 0.5 C3 80 80 1 -3\n2 0.5 1.0 D5 80 80 0 4\n")
    for hand, pitches in (("right", [72, 74]), ("left", [48])):
        result = run("play", pig_file, "-o", tmp_path / f"{hand}.mid", "--controller", "scripted", "--hand", hand)
        assert result.exit_code == 0, result.output
        assert [n.pitch for n in read_midi(tmp_path / f"{hand}.mid").notes] == pitches
    quantized = run("play", pig_file, "-o", tmp_path / "q.mid", "--quantize", "1/16")
    assert_one_line_error(quantized, "--quantize needs a MIDI file")
    for args in (("--track", "0,1"), ("--track", "0", "--hand", "left")):  # (it was ignored: channel 0 played)
        assert_one_line_error(run("play", pig_file, "-o", tmp_path / "t.mid", *args), "--track needs a MIDI file")


def test_the_choices_come_from_the_library_and_show_in_help():
    assert [c.value for c in Controller] == list(CONTROLLERS) and [c.value for c in Learner] == list(LEARNERS)
    wide = {"COLUMNS": "250"}
    assert "<sac|scripted|random>" in runner.invoke(app, ["play", "--help"], env=wide).output
    assert "<sac|dagger>" in runner.invoke(app, ["train", "--help"], env=wide).output


def test_other_usage_errors_are_one_line_too():
    assert_one_line_error(run("plya"), "No such command", "play")
    assert_one_line_error(run("finger"), "Missing argument")
    assert_one_line_error(run("inspect", SONG, "--tempi", "60"), "No such option", "--tempi")
    assert run().exit_code == 2 and "Usage" in run().output  # no arguments: the help, as typer shows it


def test_a_library_error_names_the_field_and_the_cli_names_the_option(tmp_path):
    with pytest.raises(SettingError, match=r"^load\.tempo 5: choose a tempo between 10 and 1000 bpm$") as e:
        read_midi(SONG, bpm=5)
    assert e.value.field == "load.tempo" and "--" not in str(e.value)
    with pytest.raises(SettingError, match=r"^keyboard\.count 100: a keyboard has 1 to 88 keys$") as e:
        KeyboardSpec(count=100)
    assert e.value.field == "keyboard.count"

    line = assert_one_line_error(
        run("inspect", SONG, "--tempo", "5"), "--tempo 5.0: choose a tempo between 10 and 1000 bpm"
    )
    assert "load." not in line
    assert_one_line_error(
        run("finger", SONG, "-o", tmp_path / "f.mid", "--keys", "100"), "--keys 100: a keyboard has 1 to 88 keys"
    )
    assert_one_line_error(run("score", SONG, SONG, "--quantize", "1/0"), "--quantize 1/0: give a note value")


def test_the_flag_table_phrases_every_field_and_nothing_else():
    for field, option in flags.FLAGS.items():
        assert flags.phrase(f"give {field} 3, or {field}: x ({field})") == f"give {option} 3, or {option}: x ({option})"
    assert flags.phrase("song.load.tempo.mid and reload.tempo stay") == "song.load.tempo.mid and reload.tempo stay"
    assert flags.flag("train.unknown") == "train.unknown"


def test_the_reading_options_are_declared_once_and_offered_where_they_apply():
    commands = typer.main.get_command(app).commands
    offered = {name: {p.name for p in command.params} & set(READING) for name, command in commands.items()}
    assert offered["inspect"] == offered["play"] == offered["train"] == set(READING)
    assert offered["finger"] == set(READING) - {"fingering", "refinger"}
    assert offered["score"] == set(READING) - {"refinger", "lowest_note", "keys"}
    assert offered["export"] == set()
    help_text = runner.invoke(app, ["play", "--help"], env={"COLUMNS": "250"}).output
    assert "Reading the piece" in help_text and "Keyboard and hand" in help_text and "right|left" in help_text


def test_no_output_option_writes_over_an_input_or_another_output(tmp_path):
    """--json named like the input (or the performance, or its report) was written over it; now refused first."""
    import shutil

    song = tmp_path / "twinkle.mid"
    shutil.copy(Path(__file__).parent.parent / "examples" / "midi" / "twinkle.mid", song)
    before = song.read_bytes()
    out = tmp_path / "out.mid"
    scripted = ("--controller", "scripted")
    cases = [
        (["play", song, "-o", out, "--json", song, *scripted], "--json", "name it *.json"),
        (["play", song, "-o", out, "--json", tmp_path / "out.report.json", *scripted], "would overwrite the report"),
        (["play", song, "-o", out, "--json", tmp_path / "r.json", "--html", tmp_path / "r.json", *scripted], "--html"),
        (["score", song, song, "--json", song], "name it *.json"),
        (["inspect", song, "--json", song], "name it *.json"),
    ]
    for args, *words in cases:
        assert_one_line_error(run(*args), *words)
    assert song.read_bytes() == before and not out.exists() and not list(tmp_path.glob("*.json"))


def test_train_json_is_checked_like_the_others_and_a_hard_link_is_the_same_file(tmp_path):
    import os
    import shutil

    song = tmp_path / "twinkle.mid"
    shutil.copy(Path(__file__).parent.parent / "examples" / "midi" / "twinkle.mid", song)
    before = song.read_bytes()
    assert_one_line_error(run("train", song, "--json", song, "--models", tmp_path / "m"), "name it *.json")
    linked = tmp_path / "linked.mid"
    os.link(song, linked)  # (as another spelling of one file on a case-insensitive disk)
    assert_one_line_error(run("finger", song, "-o", linked), "would overwrite the input")
    assert song.read_bytes() == before and not (tmp_path / "m").exists()


def test_an_interrupted_train_says_how_to_go_on(capsys):
    """Ctrl-C: exit 130, and train says that the same command goes on from the checkpoints."""
    import typer

    from pianobot.cli.app import friendly

    def train():
        raise KeyboardInterrupt

    def play():
        raise KeyboardInterrupt

    for command, words in ((train, "run the same command again to go on"), (play, "")):
        with pytest.raises(typer.Exit) as stopped:
            friendly(command)()
        assert stopped.value.exit_code == 130
        said = capsys.readouterr().err.strip()
        assert said.startswith("interrupted") and words in said and ("checkpoint" in said) == bool(words)


def test_a_track_one_hand_cannot_play_is_played_by_both_and_hand_reduces_it_to_one(tmp_path):
    """One track is read as a whole file of one track: where its hand cannot play it (a four-note chord
    for three fingers), both hands play it, said in one line; --hand plays the hand's part reduced."""
    song = EXAMPLES / "minuet-performed.mid"  # (its right hand's track holds a four-note chord)
    both = run(
        "play", song, "--track", "1", "-o", tmp_path / "a.mid", "--controller", "scripted", "--hand-model", "allegro"
    )
    assert both.exit_code == 0, both.output
    assert "name every note for the right hand, which cannot reach all of its chords" in both.output
    assert {n.hand for n in read_midi(tmp_path / "a.mid").notes} == {"right", "left"}
    reduced = run("play", song, "--hand", "right", "-o", tmp_path / "b.mid", "--controller", "scripted")
    assert reduced.exit_code == 0, reduced.output


def test_one_track_holding_both_hands_is_chosen_with_track_and_played_by_both(tmp_path, monkeypatch):
    """--track names a song's piano track, both hands' notes in it (a chord two octaves wide): one hand
    cannot play it, so both hands do, as a whole file's notes; the voice is left out."""
    monkeypatch.chdir(tmp_path)
    piano = [
        (0, on(48)),
        (0, on(72)),
        (480, off(48)),
        (480, off(72)),
        (480, on(50)),
        (480, on(74)),
        (960, off(50)),
        (960, off(74)),
    ]
    midi_file(tmp_path / "song.mid", [("Voice", [(0, on(79)), (960, off(79))]), ("Piano", piano)])
    result = run("play", "song.mid", "--track", "Piano", "--controller", "scripted", "-o", "out.mid")
    assert result.exit_code == 0, result.output
    played = read_midi(tmp_path / "out.mid")
    assert sorted(n.pitch for n in played.notes) == [48, 50, 72, 74]
    assert {n.hand for n in played.notes} == {"right", "left"}


def test_a_track_without_notes_and_notes_of_no_time_are_refused_in_one_line(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    midi_file(tmp_path / "song.mid", [("Piano", [(0, on(60)), (480, off(60))]), ("Words", [])])
    assert_one_line_error(run("play", "song.mid", "--track", "0", "-o", "o.mid"), "no notes in track 0", "1 'Piano'")
    assert_one_line_error(run("play", "song.mid", "--track", "Words", "-o", "o.mid"), "no notes in track Words")
    # a tempo of 1 microsecond a beat: every note lasts under 1 ms; the file plays at a tempo given
    midi_file(tmp_path / "fast.mid", [("Piano", [(0, on(60)), (480, off(60))])], tempo_events=((0, 1),))
    assert_one_line_error(run("play", "fast.mid", "-o", "o.mid"), "every note of fast.mid lasts under 1 ms", "--tempo")
    assert run("play", "fast.mid", "--tempo", "120", "--controller", "scripted", "-o", "o.mid").exit_code == 0


def test_sigterm_unwinds_a_command_as_ctrl_c_does_and_leaves_no_temporary_file(tmp_path, capsys):
    """`kill PID` while a video is written: the command stops with exit code 143 and says so, the
    user's file is as it was and no temporary file is left beside it (SIGTERM's default would end
    the process where it stood)."""
    import os
    import signal

    import numpy as np
    import typer

    from pianobot.cli.app import friendly
    from pianobot.perform.perform import write_video

    target = tmp_path / "out.mp4"
    target.write_bytes(b"the user's video")

    class Frames(list):
        def __iter__(self):
            for i, frame in enumerate(super().__iter__()):
                if i == 3:
                    os.kill(os.getpid(), signal.SIGTERM)
                yield frame

    def play():
        write_video(Frames([np.zeros((32, 32, 3), np.uint8)] * 8), target, fps=20)

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(typer.Exit) as stopped:
        friendly(play)()
    assert stopped.value.exit_code == 143 and capsys.readouterr().err.strip().startswith("terminated")
    assert target.read_bytes() == b"the user's video" and sorted(p.name for p in tmp_path.iterdir()) == ["out.mp4"]
    assert signal.getsignal(signal.SIGTERM) == before  # (the handler is the command's alone)
