"""The shipped examples: playable by the default hand, and reproducible by their script."""

import importlib.util
from pathlib import Path

import pytest

from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable
from pianobot.music.load import load_piece
from pianobot.music.midi_io import describe_tracks
from pianobot.music.phrases import split_phrases

ROOT = Path(__file__).parent.parent
MIDI = sorted((ROOT / "examples" / "midi").glob("*.mid"))
TASKS = ["one-note", "three-note", "six-note", "rhythmic", "chord"]


def test_the_papers_tasks_and_four_melodies_are_there():
    names = {p.stem for p in MIDI}
    assert set(TASKS) <= names
    assert len(names - set(TASKS)) >= 4


@pytest.mark.parametrize("path", [p for p in MIDI if "performed" not in p.stem], ids=lambda p: p.stem)
def test_every_example_is_fingered_and_playable_on_the_default_keyboard(path):
    piece = load_piece(path)
    assert piece.has_fingering
    check_playable(piece, KeyboardSpec(), HandSpec())
    assert all(len(p.notes) <= 6 for p in split_phrases(piece))


def test_tasks_are_at_60_bpm():
    for name in TASKS:
        assert load_piece(ROOT / "examples" / "midi" / f"{name}.mid").bpm == 60


def test_chord_task_has_three_two_note_chords():
    chords = load_piece(ROOT / "examples" / "midi" / "chord.mid").chords()
    assert [len(c) for c in chords] == [2, 2, 2]


def test_script_regenerates_identical_files(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("make_examples", ROOT / "examples" / "make_examples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "OUT", tmp_path)
    module.main()
    for path in tmp_path.iterdir():
        assert path.read_bytes() == (ROOT / "examples" / "midi" / path.name).read_bytes(), path.name


def test_the_performance_style_example_looks_like_a_recording():
    """Two named hands, pedal, a tempo map, no fingering: what `--hand right` is for."""
    path = ROOT / "examples" / "midi" / "minuet-performed.mid"
    tracks = {t.name: t for t in describe_tracks(path)}
    assert tracks["Right Hand"].pedal > 0 and tracks["Left Hand"].notes > 0
    piece = load_piece(path)
    assert not any(n.finger for n in piece.notes)
    onsets = [n.onset for n in piece.notes]
    assert len({round(o, 3) for o in onsets}) > 60  # timing off the grid, not quantised
