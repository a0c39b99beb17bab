"""Fixtures built in code: small pieces written to tmp_path, never files from the network."""

from __future__ import annotations

import os
import signal
import tempfile
from contextlib import contextmanager

import mido
import pytest
from typer.testing import CliRunner

from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece


@pytest.fixture
def scale() -> Piece:
    """Four quarter notes at 60 bpm, fingered 2 3 4 2, with different velocities."""
    return Piece(
        (
            Note(0.0, 60, 1.0, 70, 2),
            Note(1.0, 62, 2.0, 90, 3),
            Note(2.0, 64, 3.0, 60, 4),
            Note(3.0, 65, 4.0, 100, 2),
        ),
        bpm=60,
    )


@pytest.fixture
def scale_file(tmp_path, scale):
    return write_midi(scale, tmp_path / "scale.mid")


def midi_file(path, tracks, ticks_per_beat=480, tempo_events=((0, 500_000),)):
    """Write a type-1 MIDI file from per-track lists of (absolute tick, message)."""
    midi = mido.MidiFile(type=1, ticks_per_beat=ticks_per_beat)
    conductor = mido.MidiTrack()
    last = 0
    for tick, tempo in tempo_events:
        conductor.append(mido.MetaMessage("set_tempo", tempo=tempo, time=tick - last))
        last = tick
    midi.tracks.append(conductor)
    for name, events in tracks:
        track = mido.MidiTrack()
        track.append(mido.MetaMessage("track_name", name=name, time=0))
        last = 0
        for tick, msg in sorted(events, key=lambda e: e[0]):
            track.append(msg.copy(time=tick - last))
            last = tick
        midi.tracks.append(track)
    midi.save(path)
    return path


def on(note, velocity=80, channel=0):
    return mido.Message("note_on", note=note, velocity=velocity, channel=channel)


def off(note, channel=0):
    return mido.Message("note_off", note=note, velocity=0, channel=channel)


def lyric(text):
    return mido.MetaMessage("lyrics", text=text)


@pytest.fixture(autouse=True, scope="session")
def one_torch_thread():
    """Tests run beside other processes on 2 cores: torch's thread pool must not spin against them."""
    try:
        import torch
    except ImportError:
        yield
        return
    torch.set_num_threads(1)
    yield


@contextmanager
def within(seconds: int):
    """Fail instead of hanging (a FIFO read without care waits for a writer forever)."""

    def stop(*_):
        raise TimeoutError(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def fail_in(folder, error):
    """A mkstemp that fails with ``error`` in ``folder`` (as a read-only or full disk would) and works elsewhere."""
    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):
        if dir is not None and os.path.samefile(dir, folder):
            raise OSError(error, os.strerror(error))
        return real(*args, dir=dir, **kwargs)

    return mkstemp


def run(*args):
    """``pianobot ARGS`` in this process (typer's runner); the result has exit_code, output and stderr."""
    from pianobot.cli.app import app

    return CliRunner().invoke(app, [str(a) for a in args])


def assert_one_line_error(result, *words):
    """Exit code 2 and exactly one line on stderr (inspect may still have printed what it found)."""
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    assert "Traceback" not in result.output
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]
