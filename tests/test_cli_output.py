"""What the commands print, as a new user reads it: help at 80 columns, flags shown as flags,
tables whole in files and pipes, warnings before the error that stopped a command, `play --json`,
`--notes N` and `--quiet`, the first screen of figures, the sound notice (issue 36)."""

import io
import json
import re
from dataclasses import replace
from pathlib import Path

import mido
import pytest
import typer.main
from conftest import run
from typer.testing import CliRunner

from pianobot.cli.app import app
from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
ROOT = Path(__file__).parent.parent
COMMANDS = sorted(typer.main.get_command(app).commands)


@pytest.mark.parametrize("command", COMMANDS)
def test_help_is_whole_at_80_columns(command):
    """Every line fits, no description is cut ('…'), and each option's help is there word for word."""
    result = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    assert all(len(line) <= 80 for line in result.output.splitlines()), result.output
    assert "…" not in result.output
    words = " ".join(result.output.split())
    for param in typer.main.get_command(app).commands[command].params:
        if param.help and not getattr(param, "hidden", False):  # (a hidden option's help is not shown)
            assert " ".join(param.help.split()) in words.replace("- ", "-"), param.help


def test_play_help_fits_on_one_screen():
    """`play --help` fits a terminal of 62 rows at 80 columns: who plays is one --policy and how
    the scripted pianist helps one --guard, not six options explained by each other's special cases."""
    lines = CliRunner().invoke(app, ["play", "--help"], env={"COLUMNS": "80"}).output.splitlines()
    assert len(lines) <= 62, "\n".join(lines)
    options = " ".join(lines)
    assert "--policy" in options and "--guard <auto|hold|wrist|both|none>" in options
    assert not any(old in options for old in ("--general-policy", "--left-policy", "--fallback", "-guard /"))


def test_boolean_options_are_shown_and_parsed_as_flags(tmp_path):
    help_text = CliRunner().invoke(app, ["play", "--help"], env={"COLUMNS": "80"}).output
    assert "<bool>" not in help_text
    assert "--thumb / --no-thumb" in help_text and "--refinger / --no-refinger" in help_text
    assert "Reading the piece:" in help_text and "Keyboard and hand:" in help_text  # the panels, as sections
    thumb = write_midi(Piece((Note(0, 60, 1, 80, 1),)), tmp_path / "thumb.mid")
    assert run("inspect", thumb, "--thumb").exit_code == 0
    assert run("inspect", thumb, "--thumb", "--no-thumb").exit_code == 2  # the last one given wins


def test_tables_written_to_a_pipe_keep_their_words_whole(monkeypatch):
    """Rich assumes 80 columns where the output is not a terminal, and breaks a table's words
    ('genera/l'); pianobot's consoles there are as wide as what they print."""
    from pianobot.cli import display
    from pianobot.cli.terminal import Terminal

    monkeypatch.delenv("COLUMNS", raising=False)

    class Job:
        key, phrases, folder = "0123456789abcdef", [0, 1, 2], Path("models") / ("0123456789abcdef-" + "f" * 16)

    manifest = {"start": {"path": "x"}, "steps": 12000, "evaluation": {"step": 8000, "f1": 1.0, "velocity_mae": 2.5}}
    console = Terminal(file=io.StringIO())
    console.print(display.training_table([(Job, manifest)]))
    text = console.file.getvalue()
    assert "velocity MAE" in text and "general" in text and str(Job.folder) in text, text
    result = run("score", EXAMPLES / "twinkle.mid", EXAMPLES / "twinkle.mid", "--all", "--no-notes")
    assert "velocity-aware note F1 (mir_eval)" in result.output  # one line, not folded at 80 columns


def test_the_training_table_says_why_a_run_stored_no_policy():
    """A phrase whose run kept its start is the general policy's to play; a task family trained on
    from --general-policy that never beat it says so (the start is no general policy of the store's)."""
    from pianobot.cli import display
    from pianobot.cli.terminal import Terminal
    from pianobot.learn.jobs import PhraseJob

    kept = {"start": {"path": "x"}, "steps": 40000, "kept": "start", "evaluation": {"step": 0, "f1": 0.96}}
    phrase = PhraseJob("0123456789abcdef", Piece((Note(0, 60, 1, 80, 1),)), Path("m") / "p", [0])
    task = PhraseJob("task-melody", "melody", Path("m") / "task-melody-0", [0])
    console = Terminal(file=io.StringIO())
    console.print(display.training_table([(phrase, kept), (task, kept), (task, {**kept, "kept": "trained"})]))
    text = console.file.getvalue()
    assert "none: the general policy plays it" in text and "none: its start policy played best" in text
    assert text.count("none:") == 2 and str(Path("m") / "task-melody-0") in text


def test_warnings_come_before_the_error_that_stopped_the_command(tmp_path):
    """A repaired overlap warns; a note below the keyboard stops the command: the error is the last line."""
    midi = mido.MidiFile(type=1)
    for start in (0, 240):  # the same key struck twice at once, in two tracks
        midi.tracks.append(
            mido.MidiTrack(
                [mido.Message("note_on", note=60, velocity=80, time=start), mido.Message("note_off", note=60, time=480)]
            )
        )
    midi.tracks.append(
        # C0, below the piano too: not a left hand's note (F#1 would make a two-hand file, played by both hands)
        mido.MidiTrack([mido.Message("note_on", note=12, velocity=80), mido.Message("note_off", note=12, time=480)])
    )
    midi.save(tmp_path / "low.mid")
    result = run("inspect", tmp_path / "low.mid")
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith("error: ") and "beyond the piano's 88 keys" in lines[-1], lines
    assert lines[:-1] and all(line.startswith("warning: ") for line in lines[:-1]), lines


def two_tracks(path, names: tuple[str, str]):
    """A type 1 file of two tracks named ``names``, one note each (C5, D3)."""
    midi = mido.MidiFile(type=1)
    for name, pitch in zip(names, (72, 50)):
        midi.tracks.append(
            mido.MidiTrack(
                [
                    mido.MetaMessage("track_name", name=name),
                    mido.Message("note_on", note=pitch, velocity=80),
                    mido.Message("note_off", note=pitch, time=480),
                ]
            )
        )
    midi.save(path)
    return path


def test_inspect_names_each_hand_as_play_reads_it(tmp_path):
    output = " ".join(run("inspect", two_tracks(tmp_path / "two.mid", ("Soprano", "Left Hand"))).output.split())
    assert "no track is named for the right hand" in output and "track 1 named for the left hand" in output
    unnamed = two_tracks(tmp_path / "unnamed.mid", ("Flute", "Cello"))
    args = ("play", unnamed, "--hand", "right", "--controller", "scripted", "-o", tmp_path / "o.mid")
    played = run(*args)
    assert played.exit_code == 0, played.output
    assert "no track is named for the right hand: took track 0" in " ".join(played.output.split())


def test_play_json_notes_and_quiet(tmp_path):
    song = EXAMPLES / "three-note.mid"
    args = ("play", song, "-o", tmp_path / "o.mid", "--controller", "scripted")
    to_stdout = run(*args, "--json", "-", "--notes", "2")
    assert to_stdout.exit_code == 0, to_stdout.output
    report = json.loads(to_stdout.stdout)  # standard output is the JSON alone; the tables went to stderr
    assert report == json.loads((tmp_path / "o.report.json").read_text())
    assert report["performer"] == "scripted pianist" and len(report["notes"]) == 3
    assert "the first 2 of 3 notes" in to_stdout.stderr and "note F1" in to_stdout.stderr

    to_file = run(*args, "--json", tmp_path / "r.json")
    assert json.loads((tmp_path / "r.json").read_text())["f1"] == report["f1"]
    assert "per note" not in to_file.output  # no per-note table unless --notes asks for one
    quiet = run(*args, "--quiet", "--notes", "3")
    assert quiet.exit_code == 0 and quiet.output.strip().splitlines() == [
        f"performance written to {tmp_path / 'o.mid'}, report to {tmp_path / 'o.report.json'}"
    ]


def test_score_prints_the_first_rows_of_its_per_note_table(tmp_path):
    from pianobot.cli.commands.score import SCORE_NOTES
    from pianobot.music.midi_out import write_midi
    from pianobot.music.piece import Note, Piece

    long = tmp_path / "long.mid"  # more notes than the default shows
    write_midi(Piece(tuple(Note(0.25 * i, 60 + i % 12, 0.25 * i + 0.2, 64) for i in range(SCORE_NOTES + 15))), long)

    def rows(result) -> int:  # the per-note table's rows (each ends in its status)
        return result.output.count("│ matched │")

    default = run("score", long, long)
    assert default.exit_code == 0, default.output
    assert f"the first {SCORE_NOTES} of {SCORE_NOTES + 15} notes; --notes N shows N" in default.output
    assert rows(default) == SCORE_NOTES
    every = run("score", long, long, "--notes", str(SCORE_NOTES + 15))
    assert rows(every) == SCORE_NOTES + 15 and "--notes N shows N" not in every.output
    for none in (("--notes", "0"), ("--no-notes",)):  # (--no-notes: older scripts' spelling)
        assert "per note" not in run("score", long, long, *none).output


def test_the_first_screen_explains_a_few_figures_and_all_shows_the_rest(scale_file):
    from pianobot.perform.report import FIGURES

    first = run("score", scale_file, scale_file, "--no-notes")
    every = run("score", scale_file, scale_file, "--no-notes", "--all")
    pedal = {"note F1 with offsets, sounding (pedal)", "sustain pedal"}  # (where a file has it: test_pedal.py)
    for figure in FIGURES:
        if figure.label in pedal:
            assert f"│ {figure.label} " not in every.output
            continue
        assert (f"│ {figure.label} " in first.output) == figure.first  # (in the figure column)
        assert f"│ {figure.label} " in every.output and " ".join(figure.meaning.split()[:3]) in every.output
    assert (
        3 <= sum(f.first for f in FIGURES if f.label not in pedal) <= 6 and "--all shows every figure" in first.output
    )


def test_the_sound_notice_says_what_make_sound_installs():
    from pianobot.perform.audio import SOUND

    packages = re.search(r"^SOUND_PACKAGES := (.+)$", (ROOT / "Makefile").read_text(), re.M).group(1).split()
    assert re.findall(r"[a-z0-9-]*(?:fluidsynth|soundfont)[a-z0-9-]*", SOUND.split("(")[1]) == packages


def test_play_counts_the_file_s_own_fingering_as_score_does(tmp_path):
    """A file without fingering: n/a in both (the planner's fingering is not the file's); a file with
    marks on some notes: both count those marks only."""
    plain = Piece(tuple(Note(0.5 * i, 60 + 2 * i, 0.5 * i + 0.45, 80) for i in range(5)), bpm=120)
    marked = Piece(tuple(replace(n, finger=3) if i in (0, 3) else n for i, n in enumerate(plain.notes)), bpm=120)
    for name, piece, marks in (("plain", plain, 0), ("marked", marked, 2)):
        song = write_midi(piece, tmp_path / f"{name}.mid")
        played = run("play", song, "-o", tmp_path / f"{name}-o.mid", "--controller", "scripted", "--json", "-")
        assert played.exit_code == 0, played.output
        report = json.loads(played.stdout)
        scored = json.loads(run("score", tmp_path / f"{name}-o.mid", song, "--json", "-").stdout)
        assert report["fingering_accuracy"] == scored["fingering_accuracy"]
        assert sum(n["target_finger"] is not None for n in report["notes"]) == marks
        if marks:
            assert report["fingering_accuracy"] is not None
        else:
            assert report["fingering_accuracy"] is None and "fingering" in played.stderr
