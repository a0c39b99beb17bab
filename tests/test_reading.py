"""The one way to read a file (pianobot/pianist/reading.py): each command reads its file once."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mido
import pytest
from conftest import run

from pianobot.music import midi_file
from pianobot.music.instrument import THUMB, HandSpec, KeyboardSpec
from pianobot.pianist.reading import ReadPiece, open_song, read_piece

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "midi"
TWO_HANDS = EXAMPLES / "ode-to-joy-performed.mid"
ONE_HAND = EXAMPLES / "mary.mid"


@pytest.fixture
def reads(monkeypatch):
    """The .mid files read during a test, by name: each read of a file's bytes that mido's
    MidiFile then parses (writing a file makes a MidiFile without one, and is not counted)."""
    seen: list[str] = []
    real = mido.MidiFile
    read_input = midi_file.read_input

    def reading(path, *args, **kwargs):
        seen.append(Path(path).name)
        return read_input(path, *args, **kwargs)

    def parsed(*args, **kwargs):
        if kwargs.get("file") is None and kwargs.get("filename") is None:
            return real(*args, **kwargs)
        assert seen, "a MIDI file parsed without being read"
        return real(*args, **kwargs)

    monkeypatch.setattr(midi_file, "read_input", reading)
    monkeypatch.setattr(mido, "MidiFile", parsed)
    return seen


@pytest.mark.parametrize("song", [TWO_HANDS, ONE_HAND], ids=["two hands", "one hand"])
def test_play_reads_its_file_once(song, tmp_path, reads):
    result = run("play", song, "-o", tmp_path / "out.mid", "--controller", "scripted", "--quiet")
    assert result.exit_code == 0, result.output
    assert reads.count(song.name) == 1, reads


@pytest.mark.parametrize("song", [TWO_HANDS, ONE_HAND], ids=["two hands", "one hand"])
def test_inspect_and_finger_read_their_file_once(song, tmp_path, reads):
    assert run("inspect", song).exit_code == 0
    assert reads.count(song.name) == 1, reads
    assert run("finger", song, "-o", tmp_path / "fingered.mid").exit_code == 0
    assert reads.count(song.name) == 2, reads


def test_score_reads_the_reference_once(tmp_path, reads):
    played = tmp_path / "played.mid"
    played.write_bytes(TWO_HANDS.read_bytes())
    assert run("score", played, TWO_HANDS).exit_code == 0
    assert reads.count(TWO_HANDS.name) == 1, reads


def test_read_piece_says_what_it_read():
    read = read_piece(TWO_HANDS)
    assert isinstance(read, ReadPiece) and read.both and read.piece is read.hands.piece
    assert read.fingers in (HandSpec(), THUMB) and read.keyboard == KeyboardSpec()
    assert [t.index for t in read.tracks if t.notes]
    with pytest.raises(dataclasses.FrozenInstanceError):
        read.fingers = THUMB
    one = read_piece(open_song(ONE_HAND))
    assert not one.both and one.piece is not None and all(n.finger is not None for n in one.piece.notes)
    assert read_piece(ONE_HAND, finger=False).piece is None
