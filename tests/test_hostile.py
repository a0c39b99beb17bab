"""Hostile and unlucky input, end to end (issue 18): every case answers with one line on stderr
and exit code 2 (or works, where the input is fine), in time and memory bounded by what the
file really holds, and a failed run never changes an existing output file."""

import errno
import os
from pathlib import Path

import mido
import pytest
from conftest import fail_in, lyric, midi_file, off, on, within
from typer.testing import CliRunner

from pianobot import files
from pianobot.cli.app import app
from pianobot.music.midi_io import describe_tracks, read_midi, write_midi
from pianobot.music.piece import Note, Piece

runner = CliRunner()
TINY = Piece((Note(0.0, 60, 0.5, 80, 2), Note(0.5, 64, 1.0, 90, 3)), bpm=60)


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


def assert_one_line_error(result, *words):
    """Exit code 2, one 'error:' line on stderr (and at most warnings beside it), no traceback."""
    assert result.exit_code == 2, (result.output, result.exception)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and all(line.startswith(("error: ", "warning: ")) for line in lines), result.stderr
    assert "Traceback" not in result.output
    for word in words:
        assert word in errors[0], errors[0]
    return errors[0]


@pytest.fixture
def no_simulation(monkeypatch):
    """Any run that reaches the simulator fails the test: errors must come before the work."""

    def perform(*args, **kwargs):
        raise AssertionError("the simulation started")

    monkeypatch.setattr("pianobot.perform.perform.perform", perform)


# -- 1. tempo ---------------------------------------------------------------------------------
def test_a_tempo_of_zero_is_one_line_in_every_command(tmp_path, no_simulation):
    song = midi_file(tmp_path / "zero.mid", [("m", [(0, on(64)), (480, off(64))])], tempo_events=((0, 0),))
    good = write_midi(TINY, tmp_path / "good.mid")
    for args in (
        ("inspect", song),
        ("finger", song, "-o", tmp_path / "f.mid"),
        ("score", good, song),
        ("score", song, good),
        ("play", song, "-o", tmp_path / "p.mid", "--controller", "scripted"),
        ("train", song, "--models", tmp_path / "models"),
    ):
        assert_one_line_error(run(*args), "zero.mid sets a tempo of 0", "--tempo BPM")
    assert run("inspect", song, "--tempo", "60").exit_code == 0
    assert run("finger", song, "-o", tmp_path / "f.mid", "--tempo", "60").exit_code == 0


# -- 2. names outside Latin-1 ------------------------------------------------------------------
def test_file_names_outside_latin_1_finger_and_play(tmp_path):
    song = write_midi(TINY.without_fingering(), tmp_path / "音 楽.mid")
    fingered = run("finger", song, "-o", tmp_path / "指 使い.mid")
    assert fingered.exit_code == 0, fingered.output
    assert describe_tracks(tmp_path / "指 使い.mid")[0].name == "音 楽 fingered by pianobot"
    played = run("play", song, "-o", tmp_path / "演奏.mid", "--controller", "scripted")
    assert played.exit_code == 0, played.output
    assert describe_tracks(tmp_path / "演奏.mid")[0].name == "pianobot (scripted pianist): 音 楽"
    assert read_midi(tmp_path / "演奏.mid").has_fingering
    assert run("score", tmp_path / "演奏.mid", song).exit_code == 0


def test_brackets_in_names_are_not_taken_for_markup(tmp_path):
    """Rich reads '[/x]' as a closing tag: a file, track or option with one must still print."""
    folder = tmp_path / "d["
    folder.mkdir()
    song = folder / "red] [bold].mid"  # its path holds '[/red]'
    midi_file(song, [("[/red] right", [(0, on(60)), (480, off(60))])])
    result = run("inspect", song)
    assert result.exit_code == 0, result.output
    assert "[/red] right" in result.output
    fingered = run("finger", song, "-o", folder / "c].mid")
    assert fingered.exit_code == 0 and "d[/c].mid" in fingered.output.replace("\n", ""), fingered.output
    line = assert_one_line_error(run("inspect", song, "--track", "[/x]"), "no track '[/x]'")
    assert "'[/red] right'" in line


# -- 3. times in PIG files ---------------------------------------------------------------------
def test_nan_and_huge_times_in_pig_files(tmp_path, no_simulation):
    song = write_midi(TINY, tmp_path / "song.mid")
    header = "//Version: PianoFingering_v170101\n"
    (tmp_path / "song_fingering.txt").write_text(header + "0\tnan\t0.5\tC4\t80\t80\t0\t2\n")
    for command in ("inspect", "play"):
        extra = ("-o", tmp_path / "p.mid", "--controller", "scripted") if command == "play" else ()
        assert_one_line_error(run(command, song, *extra), "song_fingering.txt line 2", "onset nan")
    (tmp_path / "ref.txt").write_text(header + "0\t0\t1e12\tC4\t80\t80\t0\t2\n")
    with within(30):  # it asked for 2.27 PiB
        assert_one_line_error(run("score", song, tmp_path / "ref.txt"), "ref.txt line 2", "at most 60 minutes")


# -- 4. special files --------------------------------------------------------------------------
def test_symbolic_link_loops_fifos_and_devices_are_one_line(tmp_path, no_simulation):
    good = write_midi(TINY, tmp_path / "good.mid")
    (tmp_path / "loop.mid").symlink_to(tmp_path / "loop2.mid")
    (tmp_path / "loop2.mid").symlink_to(tmp_path / "loop.mid")
    os.mkfifo(tmp_path / "fifo.mid")
    play = ("--controller", "scripted")
    with within(60):
        for bad, words in (
            (tmp_path / "loop.mid", "loop of symbolic links"),
            (tmp_path / "fifo.mid", "not a regular file"),
            (Path("/dev/zero"), "not a regular file"),
        ):
            assert_one_line_error(run("inspect", bad), words)
            assert_one_line_error(run("finger", bad, "-o", tmp_path / "f.mid"), words)
            assert_one_line_error(run("play", bad, "-o", tmp_path / "p.mid", *play), words)
            assert_one_line_error(run("score", good, bad), words)
            assert_one_line_error(run("inspect", good, "--fingering", bad), words)
    assert not (tmp_path / "f.mid").exists() and not (tmp_path / "p.mid").exists()
    result = run("finger", good, "-o", tmp_path / "loop.mid")  # an output that is a loop is replaced, not followed
    assert result.exit_code == 0 and read_midi(tmp_path / "loop.mid") == TINY
    assert_one_line_error(run("finger", good, "-o", "/dev/null"), "*.mid")


# -- 5. output folders that cannot be written --------------------------------------------------


def output_commands(song, folder, other):
    return (
        ("finger", song, "-o", folder / "f.mid"),
        ("play", song, "-o", folder / "p.mid", "--controller", "scripted"),
        ("play", song, "-o", other / "p.mid", "--controller", "scripted", "--wav", folder / "p.wav"),
        ("play", song, "-o", other / "p.mid", "--controller", "scripted", "--video", folder / "p.mp4"),
        ("score", song, song, "--json", folder / "s.json"),
        ("score", song, song, "--plot", folder / "s.png"),
    )


@pytest.mark.parametrize("error, words", [(errno.EROFS, "read-only file system"), (errno.ENOSPC, "no space left")])
def test_an_unwritable_output_folder_is_refused_before_any_work(tmp_path, monkeypatch, no_simulation, error, words):
    song = write_midi(TINY, tmp_path / "song.mid")
    folder, other = tmp_path / "out", tmp_path / "other"
    folder.mkdir(), other.mkdir()
    monkeypatch.setattr(files.tempfile, "mkstemp", fail_in(folder, error))
    monkeypatch.setattr("pianobot.music.metrics.compare", lambda *a, **k: pytest.fail("scored before checking"))
    for args in output_commands(song, folder, other):
        assert_one_line_error(run(*args), f"cannot write {folder}", words)
    assert list(folder.iterdir()) == [] and list(other.iterdir()) == []


def fsync_fails_for(name):
    """An os.fsync that reports a full disk for (temporary files of) ``name`` only."""
    real = os.fsync

    def fsync(fd):
        if name in os.readlink(f"/proc/self/fd/{fd}"):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(fd)

    return fsync


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs /proc to tell files apart")
def test_a_full_disk_during_the_final_write_is_one_line_and_keeps_old_files(tmp_path, monkeypatch):
    import imageio.v2

    song = write_midi(TINY, tmp_path / "song.mid")
    folder, other = tmp_path / "out", tmp_path / "other"
    folder.mkdir(), other.mkdir()
    for name in ("f.mid", "p.mid", "p.report.json", "p.wav", "p.mp4", "s.json", "s.png"):
        (folder / name).write_text("old")

    class FullDisk:
        def __init__(self, path, **kwargs):
            Path(path).write_bytes(b"\0\0\0\x08free")

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def append_data(self, frame):
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(imageio.v2, "get_writer", FullDisk)
    for args in output_commands(song, folder, other):
        target = Path(args[-1]) if args[0] != "play" or len(args) > 6 else Path(args[3])
        with monkeypatch.context() as m:
            m.setattr(files.os, "fsync", fsync_fails_for(target.name))
            assert_one_line_error(run(*args), f"could not write {target}", "no space left", "unchanged")
        assert target.read_text() == "old"
    assert sorted(p.name for p in folder.iterdir()) == [
        "f.mid",
        "p.mid",
        "p.mp4",
        "p.report.json",
        "p.wav",
        "s.json",
        "s.png",
    ]  # and no temporary files
    assert all(p.read_text() == "old" for p in folder.iterdir())


# -- 6. a bound on what a file may ask ---------------------------------------------------------
def test_a_tiny_file_asking_for_hours_is_refused_before_any_work(tmp_path, no_simulation):
    """One delta time of 0x0FFFFFFF ticks in a 40-byte file made `play` allocate 7 GB."""
    huge = midi_file(tmp_path / "huge.mid", [("m", [(0, on(64)), (0x0FFFFFFF, off(64))])])
    assert huge.stat().st_size < 64
    good = write_midi(TINY, tmp_path / "good.mid")
    with within(60):
        for args in (
            ("inspect", huge),
            ("finger", huge, "-o", tmp_path / "f.mid"),
            ("play", huge, "-o", tmp_path / "p.mid", "--controller", "scripted"),
            ("score", huge, good),
            ("score", good, huge),
        ):
            assert_one_line_error(run(*args), "at most 60 minutes", "cut the file", "--tempo")


# -- 7. messages -------------------------------------------------------------------------------
def test_a_megabyte_lyric_is_quoted_short(tmp_path):
    events = [(0, lyric("2")), (0, on(64)), (480, off(64)), (480, lyric("9 " * 500_000)), (480, on(65)), (960, off(65))]
    song = midi_file(tmp_path / "l.mid", [("m", events)])
    result = run("inspect", song)
    assert result.exit_code == 0, result.output
    (line,) = [line for line in result.stderr.splitlines() if "figured bass" in line]
    assert len(line) < 300 and "…" in line


def test_a_header_claiming_more_tracks_than_the_file_holds(tmp_path):
    data = write_midi(TINY, tmp_path / "t.mid").read_bytes()
    (tmp_path / "t.mid").write_bytes(data[:10] + b"\xff\xff" + data[12:])
    assert_one_line_error(run("inspect", tmp_path / "t.mid"), "truncated or its header does not match its tracks")


def test_a_chord_too_big_for_the_hand_blames_the_hand_in_every_command(tmp_path, no_simulation):
    chord = Piece(tuple(Note(0, 60 + i, 1, 80, 2 + i % 3) for i in range(10)), bpm=60)  # fingered: no planner
    for song in (write_midi(chord, tmp_path / "f.mid"), write_midi(chord.without_fingering(), tmp_path / "u.mid")):
        for args in (
            ("inspect", song),
            ("finger", song, "-o", tmp_path / "o.mid"),
            ("play", song, "-o", tmp_path / "p.mid", "--controller", "scripted"),
        ):
            line = assert_one_line_error(run(*args), "10 notes sound at once", "the hand has 3 fingers")
            assert "--phrase-notes" not in line


def test_messages_with_line_breaks_stay_on_one_line(tmp_path):
    song = midi_file(tmp_path / "n.mid", [("m", [(0, lyric("2")), (0, on(64)), (480, lyric("1\n9")), (480, off(64))])])
    result = run("inspect", song)
    assert result.exit_code == 0, result.output
    assert [line for line in result.stderr.splitlines() if "1\\n9" in line and "figured bass" in line]
    odd = write_midi(TINY, tmp_path / "line\nbreak.mid")
    assert_one_line_error(run("inspect", odd, "--track", "x\ny"), "line\\nbreak.mid", "'x\\ny'")
    assert mido.MidiFile(odd).tracks  # the file itself is fine


def test_long_option_values_are_quoted_short(tmp_path, no_simulation):
    song = write_midi(TINY, tmp_path / "song.mid")
    for args in (
        ("play", song, "-o", tmp_path / "p.mid", "--controller", "r" * 10_000),
        ("inspect", song, "--track", "t" * 10_000),
        ("inspect", song, "--quantize", "1/" + "x" * 10_000),
        ("inspect", song, "--hand", "h" * 10_000),
        ("inspect", song, "--lowest-note", "C" + "9" * 10_000),
    ):
        assert len(assert_one_line_error(run(*args), "…")) < 400
