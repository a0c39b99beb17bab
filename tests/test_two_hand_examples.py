"""The two-hand examples (a chorale, a piano piece with a bass line, a recording with pedal and
rubato): tracks named for the hands, read with both hands, each note's hand found again by the
planner, each hand's part fingered."""

import warnings
from pathlib import Path

import pytest

from pianobot.errors import PianobotWarning
from pianobot.music.load import load_hands
from pianobot.music.midi_io import describe_tracks
from pianobot.pianist.assign import assign_hands, finger_hands

MIDI = Path(__file__).parent.parent / "examples" / "midi"
TWO_HANDS = ["chorale-performed", "ode-to-joy-performed", "prelude-performed"]


@pytest.mark.parametrize("name", TWO_HANDS)
def test_a_two_hand_example_looks_like_a_recording_with_named_hands(name):
    path = MIDI / f"{name}.mid"
    tracks = [t for t in describe_tracks(path) if t.notes]
    assert [t.name for t in tracks] == ["Right Hand", "Left Hand"]
    assert sum(t.pedal for t in describe_tracks(path)) >= 10
    piece = load_hands(path)
    assert piece.hands == ("right", "left") and all(n.hand for n in piece.notes)
    # (load_hands refuses hands that cross)
    assert min(n.pitch for n in piece.part("left")) < 60 <= max(n.pitch for n in piece.part("right"))
    assert not any(n.finger for n in piece.notes)
    assert len({round(n.onset % 0.125, 3) for n in piece.notes}) > 20  # not on a grid
    assert len({n.velocity for n in piece.notes}) >= 25


@pytest.mark.parametrize("name", [*TWO_HANDS, "minuet-performed"])
def test_the_planner_gives_each_note_the_hand_its_track_names(name):
    piece = load_hands(MIDI / f"{name}.mid")
    found = assign_hands(piece.with_hands(None)).piece
    agree = sum(a.hand == b.hand for a, b in zip(piece.notes, found.notes)) / len(piece)
    assert agree >= 0.98, name


@pytest.mark.parametrize("name", TWO_HANDS)
def test_each_hand_of_a_two_hand_example_is_fingered_nearly_whole(name):
    piece = load_hands(MIDI / f"{name}.mid")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        fingered = finger_hands(piece).piece
    assert fingered.has_fingering and fingered.hands == ("right", "left")
    for hand in ("right", "left"):
        assert len(fingered.part(hand)) >= 0.97 * len(piece.part(hand)), hand
