"""benchmarks/early.py: the scripted pianist's early releases counted by the rule that made them."""

from collections import Counter
from dataclasses import replace

import pytest

from benchmarks import early
from pianobot.music.piece import Note, Piece
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.pianist.strikes import StrikePlanner
from pianobot.sim.hand import default_fingers, hand_config

PIANIST = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand_config(default_fingers("pianist"))))


@pytest.mark.parametrize(
    "second, rule",
    [
        (Note(0.5, 60, 1.0, finger=2), "own next note"),  # the index strikes C4 again: it rises first
        (Note(0.5, 60, 1.0, finger=3), "same key"),  # the middle finger strikes C4 again: the key rises first
        (Note(0.5, 81, 1.0, finger=5), "wrist move"),  # A5, out of reach with C4 held: the hand moves
    ],
)
def test_a_note_let_go_before_its_end_is_counted_by_its_rule_and_the_planner_is_restored(second, rule):
    piece = Piece((Note(0.0, 60, 0.5, finger=2), second))
    counts, steps = Counter(), Counter()
    original = early.watch(counts, steps)
    try:
        played = perform(piece, "scripted", PIANIST, seed=0).played
    finally:
        StrikePlanner.plan = original
    assert dict(counts) == {rule: 1}
    assert 1 <= steps[rule] <= 10  # (the steps of C4's 0.5 s still written when it was let go)
    assert sorted(n.pitch for n in played.notes) == sorted(n.pitch for n in piece.notes)
    assert StrikePlanner.plan is original and "_let_go" in vars(StrikePlanner)


def test_the_table_sums_every_excerpt():
    row = {
        "piece": "x",
        "releases": {"own next note": 1, "same key": 0, "wrist move": 2},
        "steps": {"own next note": 3, "same key": 0, "wrist move": 8},
        "played": {"f1": 1.0, "step_f1": 0.5, "f1_offsets": 0.25},
        "as_given": {"f1": 1.0, "step_f1": 1.0, "f1_offsets": 0.75},
    }
    other = {**row, "piece": "y", "as_given": {"f1": 1.0, "step_f1": 1.0, "f1_offsets": 1.0}}
    lines = early.table([row, other]).splitlines()
    assert lines[-1] == "| all (2) | 2 (6) | 0 (0) | 4 (16) | 0.500, 0.250 | 1.000, 0.875 |"
