"""benchmarks/early.py: the scripted pianist's early releases counted by the rule the strike planner names."""

from collections import Counter
from dataclasses import replace

import pytest

from benchmarks import early
from pianobot.music.piece import Note, Piece
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.pianist.strikes import StrikePlanner
from pianobot.sim.hand import default_fingers, hand_config

PIANIST = replace(PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand_config(default_fingers("pianist"))))


def watched(piece: Piece) -> tuple[Counter, Counter, Piece]:
    counts, steps = Counter(), Counter()
    with early.watch(counts, steps):
        played = perform(piece, "scripted", PIANIST, seed=0).played
    return counts, steps, played


@pytest.mark.parametrize(
    "notes, rule",
    [
        # a soft repeat: let go to rise past where the key lets its note go and strike it again (at
        # velocity 80 that takes no step of the note's: it is let go as it ends)
        ((Note(0.0, 60, 0.5, 40, 2), Note(0.5, 60, 1.0, 40, 2)), "own next note"),
        ((Note(0.0, 60, 0.5, finger=2), Note(0.5, 60, 1.0, finger=3)), "same key"),  # another finger's C4
        ((Note(0.0, 60, 0.5, finger=2), Note(0.5, 81, 1.0, finger=5)), "wrist move"),  # A5: the hand moves
    ],
)
def test_a_note_let_go_before_its_end_is_counted_by_the_rule_that_let_it_go(notes, rule):
    counts, steps, played = watched(Piece(notes))
    assert dict(counts) == {rule: 1}
    assert 1 <= steps[rule] <= 10  # (the steps of C4's 0.5 s still written when it was let go)
    assert sorted(n.pitch for n in played.notes) == sorted(n.pitch for n in notes)


def test_a_wrist_move_is_not_taken_for_another_finger_on_the_same_key_and_its_steps_run_past_the_window():
    """C4 held 2 s (40 steps, past the 11-row score window) is let go for B4, out of reach; another finger's
    C4 comes later: the release is the wrist's, and every step of C4 still written counts."""
    piece = Piece((Note(0.0, 60, 2.0, finger=2), Note(0.5, 71, 1.0, finger=5), Note(2.0, 60, 2.5, finger=3)))
    counts, steps, played = watched(piece)
    assert counts["same key"] == 0 and counts["wrist move"] >= 1
    assert steps["wrist move"] > 11
    c4 = min((n for n in played.notes if n.pitch == 60), key=lambda n: n.onset)
    assert steps["wrist move"] >= round((2.0 - c4.offset) / 0.05) - 1


def test_a_wrist_move_while_another_finger_s_strike_on_the_key_is_in_sight_is_the_wrist_s():
    """C4 (index) to 0.6 s, B4 (little finger) at 0.5 s, out of reach with C4 held, then C4 again by the
    middle finger at 0.6 s: the B4 lets go of C4 before the middle finger's strike is due."""
    piece = Piece((Note(0.0, 60, 0.6, finger=2), Note(0.5, 71, 1.0, finger=5), Note(0.6, 60, 1.0, finger=3)))
    counts, _, _ = watched(piece)
    assert dict(counts) == {"wrist move": 2}


def test_watching_changes_nothing_played_and_the_planner_is_restored_even_after_an_error():
    piece = Piece((Note(0.0, 60, 0.5, finger=2), Note(0.5, 81, 1.0, finger=5)))
    plan, released_for = StrikePlanner.plan, StrikePlanner.released_for
    _, _, played = watched(piece)
    assert played == perform(piece, "scripted", PIANIST, seed=0).played
    with pytest.raises(RuntimeError), early.watch(Counter(), Counter()):
        assert StrikePlanner.plan is not plan
        raise RuntimeError
    assert (StrikePlanner.plan, StrikePlanner.released_for) == (plan, released_for)


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


def test_an_excerpt_the_set_lacks_is_one_clear_line(monkeypatch, capsys):
    import sys

    monkeypatch.setattr(sys, "argv", ["early", "--set", "validation", "--only", "nosuch"])
    with pytest.raises(SystemExit) as exit:
        early.main()
    assert exit.value.code == 2
    assert "--only nosuch: no such excerpt in the validation set" in capsys.readouterr().err


def test_each_hand_s_fingers_are_the_named_model_s_or_chosen_per_file_as_the_corpus_chooses(monkeypatch, tmp_path):
    """--hand-model pianist plays the pianist's five fingers; --hand-model allegro (no fingers given) the
    fingers chosen per file, as benchmarks.corpus and play choose them (music21 and the run stood in for)."""
    import types

    from pianobot.music.instrument import THUMB

    used = []
    figures = types.SimpleNamespace(f1=1.0, step_f1=1.0, f1_with_offsets=1.0)
    performance = types.SimpleNamespace(report=lambda: figures, given_report=lambda: figures)
    monkeypatch.setattr(early, "write_excerpt", lambda *args: None)
    monkeypatch.setattr(early, "fingers_for_file", lambda file, options: (THUMB, None))
    monkeypatch.setattr(early, "two_hands", lambda file, options, fingers: types.SimpleNamespace(piece=None))
    monkeypatch.setattr(early, "play_hands", lambda piece, who, models, hand: used.append(hand) or performance)
    excerpt = early.SETS["test"][:1]
    early.early(excerpt, tmp_path, None)
    early.early(excerpt, tmp_path, default_fingers("pianist"))
    assert used == [THUMB, default_fingers("pianist")]
