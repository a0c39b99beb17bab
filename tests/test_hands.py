"""Hand assignment by planning (pianobot.pianist.assign): small pieces with known answers."""

import warnings
from dataclasses import replace

import pytest
from test_two_hands import warning_lines

from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec
from pianobot.music.piece import Note, Piece, parse_pitch
from pianobot.pianist.assign import assign_hands, finger_apart, finger_hands, reaches, stands, thin_for_hands


def notes(*items, hand=None):
    """Notes from (pitch name, onset, offset) triples."""
    return [Note(on, parse_pitch(name), off, hand=hand) for name, on, off in items]


def hands_of(piece):
    return {(n.name, n.onset): n.hand for n in piece}


def test_reach_comes_from_the_planner_and_the_left_hand_is_its_mirror():
    # the default three-finger hand spans up to a major seventh, not an octave; the thumb adds the octave
    assert reaches([60, 71], "right") and not reaches([60, 72], "right")
    assert reaches([60, 72], "right", HandSpec((1, 2, 3, 4)))
    assert not reaches([60, 62, 64, 65], "right")  # four notes, three fingers
    assert reaches([36, 47], "left") and not reaches([36, 48], "left")


def test_a_bass_line_under_a_melody():
    # bass on the beats, the melody between them: neither hand can take both lines
    bass = [(name, float(i), i + 0.5) for i, name in enumerate(["C3", "G2", "A2", "F2", "C3", "G2"])]
    melody = [(name, i + 0.5, i + 1.0) for i, name in enumerate(["E5", "D5", "C5", "A4", "G4", "B4"])]
    piece = Piece.of(notes(*bass, *melody))
    assigned = assign_hands(piece).piece
    assert all(hands_of(assigned)[(n, on)] == "left" for n, on, _ in bass)
    assert all(hands_of(assigned)[(n, on)] == "right" for n, on, _ in melody)


def test_a_chord_too_wide_for_one_hand_is_split_between_them():
    piece = Piece.of(notes(("C3", 0, 1), ("G3", 0, 1), ("E4", 0, 1), ("G4", 0, 1), ("C5", 0, 1)))
    result = assign_hands(piece)
    assert [n.hand for n in result.piece] == ["left", "left", "right", "right", "right"]
    assert result.unplayable == 0


def test_a_melody_that_moves_into_the_other_hands_region_passes_to_it():
    chords = [((m, i, i + 1), (b, i, i + 1)) for i, (m, b) in enumerate([("E5", "C3"), ("D5", "G2"), ("C5", "C3")])]
    scale = ["C5", "B4", "A4", "G4", "F4", "E4", "D4", "C4", "B3", "A3", "G3", "F3", "E3", "D3", "C3"]
    run = [(name, 3 + i * 0.25, 3.25 + i * 0.25) for i, name in enumerate(scale)]
    end = 3 + len(scale) * 0.25
    tail = [("E5", end, end + 1), ("C3", end, end + 1)]
    piece = Piece.of(notes(*[n for pair in chords for n in pair], *run, *tail))
    assigned = hands_of(assign_hands(piece).piece)
    run_hands = [assigned[(name, on)] for name, on, _ in run]
    switch = run_hands.index("left")
    assert run_hands == ["right"] * switch + ["left"] * (len(scale) - switch)  # one hand-over, downwards
    assert 3 <= switch <= len(scale) - 4  # the run is shared, not played by one hand
    assert assigned[("E5", end)] == "right" and assigned[("C3", end)] == "left"


def test_crossing_the_other_hands_held_notes_is_refused_and_given_hands_are_kept():
    held = notes(("E4", 0, 4), ("F4", 0, 4), ("G4", 0, 4), hand="right")  # every right-hand finger busy
    above = Piece.of([*held, *notes(("B4", 1, 2))])
    below = Piece.of([*held, *notes(("C4", 1, 2))])
    # B4 goes to the right hand (a held note will end early) rather than the left hand crossing over
    assert hands_of(assign_hands(above).piece)[("B4", 1)] == "right"
    assert hands_of(assign_hands(below).piece)[("C4", 1)] == "left"
    assert all(n.hand == "right" for n in assign_hands(below).piece if n.name in {"E4", "F4", "G4"})


def test_chords_beyond_two_hands_keep_the_bass_and_the_melody():
    piece = Piece.of(notes(*[(name, 0, 1) for name in ["C2", "G2", "C3", "E3", "G3", "C4", "E4", "G4"]]))
    thinned, dropped = thin_for_hands(piece)
    assert dropped == 2 and [n.name for n in thinned] == ["C2", "G2", "C3", "C4", "E4", "G4"]


def test_each_hand_is_fingered_by_the_planner_the_left_through_the_mirror():
    left = notes(("C3", 0, 0.5), ("D3", 0.5, 1), ("E3", 1, 1.5), hand="left")
    right = notes(("C5", 0, 0.5), ("D5", 0.5, 1), ("E5", 1, 1.5), hand="right")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PianobotWarning)  # a playable piece is not reduced
        result = finger_hands(Piece.of([*left, *right]))
    fingers = {n.hand: [m.finger for m in result.piece.part(n.hand)] for n in result.piece}
    # a rising line: the right hand from its index finger up, the left hand from its ring finger down
    assert fingers["right"] == [2, 3, 4] and fingers["left"] == [4, 3, 2]
    assert result.piece.with_fingers([None] * 6) == Piece.of([*left, *right])


def test_finger_hands_needs_every_notes_hand():
    with pytest.raises(ValueError, match="assign_hands"):
        finger_hands(Piece.of(notes(("C4", 0, 1))))


def test_a_two_hand_file_without_named_tracks_is_read_with_every_notes_hand(tmp_path):
    from pianobot.music.midi_io import write_midi
    from pianobot.pianist.assign import load_two_hands

    bass = notes(("C3", 0, 1), ("G2", 1, 2))
    melody = notes(("E5", 0, 0.5), ("D5", 0.5, 1), ("C5", 1, 2))
    big = notes(*[(name, 2, 3) for name in ["C2", "G2", "C3", "E3", "G3", "C4", "E4", "G4"]])
    path = write_midi(Piece.of([*bass, *melody, *big]), tmp_path / "one-track.mid")  # no hands: one unnamed track
    piece, lines = warning_lines(load_two_hands, path)
    assert lines == [
        "one-track.mid has chords of more than 6 notes, more than two hands of 3 fingers hold: "
        "kept their lowest and highest 3, dropped 2 inner note(s)"
    ]
    assert {(n.name, n.hand) for n in piece if n.onset < 2} == {
        ("C3", "left"),
        ("G2", "left"),
        ("E5", "right"),
        ("D5", "right"),
        ("C5", "right"),
    }
    assert [n.hand for n in piece if n.onset == 2] == ["left"] * 3 + ["right"] * 3


def test_a_one_hand_melody_and_close_chords_stay_in_one_hand():
    scale = ["C4", "D4", "E4", "F4", "G4", "A4", "B4", "C5", "B4", "A4", "G4", "F4", "E4", "D4", "C4"]
    melody = Piece.of(notes(*[(name, i * 0.5, i * 0.5 + 0.5) for i, name in enumerate(scale)]))
    assert assign_hands(melody).piece.hands == ("right",)
    chords = Piece.of(notes(("C4", 0, 1), ("E4", 0, 1), ("D4", 1, 2), ("F4", 1, 2), ("E4", 2, 3), ("G4", 2, 3)))
    assert assign_hands(chords).piece.hands == ("right",)


def test_a_left_hand_chord_too_wide_keeps_its_bass_and_says_so_for_the_left_hand():
    piece = Piece.of([*notes(("C2", 0, 1), ("E3", 0, 1), hand="left"), *notes(("C5", 0, 1), hand="right")])
    result, lines = warning_lines(finger_hands, piece)
    assert [n.name for n in result.piece.part("left")] == ["C2"]  # the bass, not the upper note
    assert lines == [
        "the left hand's part has chords wider than this hand reaches: kept their lowest notes, dropped 1 upper note(s)"
    ]


def test_given_hands_that_cross_inside_a_chord_are_one_clear_error():
    from pianobot.errors import PianobotError

    crossed = Piece.of([*notes(("C5", 0, 1), hand="left"), *notes(("C4", 0, 1), hand="right")])
    with pytest.raises(PianobotError, match="hands that cross"):
        assign_hands(crossed)


def interleaved(count: int = 12) -> Piece:
    """A right hand alternating G4 A#4 over a left hand alternating D#4 A#3: hands a third apart."""
    notes = []
    for i in range(count):
        t = 0.25 * i
        notes.append(Note(t, parse_pitch("G4" if i % 2 == 0 else "A#4"), t + 0.25, 80, hand="right"))
        notes.append(Note(t, parse_pitch("D#4" if i % 2 == 0 else "A#3"), t + 0.25, 70, hand="left"))
    return Piece(tuple(notes), bpm=120)


def fingered_parts(piece: Piece) -> dict:
    from pianobot.perform.together import prepare_part

    parts = {}
    for hand in ("right", "left"):
        window, part, *_ = prepare_part(piece, hand, None, HandSpec(), start=0.0)
        parts[hand] = (window, part)
    return parts


def least_gap(parts: dict, fingered: dict) -> float:
    right = stands(parts["right"][0], fingered["right"])
    left = stands(parts["left"][0], fingered["left"])
    return min(up - down for s, e, up in right for s2, e2, down in left if s < e2 and s2 < e)


def test_hands_close_together_are_fingered_to_keep_their_wrists_as_far_apart_as_the_world_keeps_them():
    from pianobot.sim.hand import HandConfig, thumb_side_reach

    parts = fingered_parts(interleaved())
    gap = 2 * thumb_side_reach(HandConfig())
    alone = {hand: part for hand, (_, part) in parts.items()}
    assert least_gap(parts, alone) < gap - 0.01  # each hand fingered on its own: the wrists would meet
    apart = {hand: plan.piece for hand, plan in finger_apart(parts).items()}
    assert least_gap(parts, apart) >= gap - 1e-9
    for hand in ("right", "left"):  # the same notes, other fingers
        assert [(n.onset, n.pitch) for n in apart[hand].notes] == [(n.onset, n.pitch) for n in alone[hand].notes]
        assert apart[hand].has_fingering


def test_hands_far_apart_keep_the_fingering_each_was_given():
    far = Piece(tuple(n if n.hand == "right" else replace(n, pitch=n.pitch - 24) for n in interleaved().notes), bpm=120)
    parts = fingered_parts(far)
    assert {hand: plan.piece for hand, plan in finger_apart(parts).items()} == {
        hand: part for hand, (_, part) in parts.items()
    }


def test_pianobot_finger_fingers_both_hands_to_keep_their_wrists_apart_as_play_does():
    fingered = finger_hands(interleaved(), refinger=True)
    right = {n.name: n.finger for n in fingered.piece.part("right").notes}
    left = {n.name: n.finger for n in fingered.piece.part("left").notes}
    assert right == {"G4": 2, "A#4": 3} and left == {"D#4": 2, "A#3": 4}  # (the right hand alone: 3, 4)
    assert fingered.plans["right"].piece.has_fingering and fingered.plans["left"].piece.has_fingering


def test_the_left_hand_moves_aside_where_the_right_hand_cannot():
    from pianobot.sim.hand import HandConfig, thumb_side_reach

    # a right-hand chord held under all three fingers, over the left hand of `interleaved`
    notes = [Note(0.0, parse_pitch(x), 2.0, 80, hand="right") for x in ("F4", "G4", "A4")]
    for i in range(8):
        t = 0.25 * i
        notes.append(Note(t, parse_pitch("D#4" if i % 2 == 0 else "A#3"), t + 0.25, 70, hand="left"))
    parts = fingered_parts(Piece(tuple(sorted(notes, key=lambda n: (n.onset, n.pitch))), bpm=120))
    alone = {hand: part for hand, (_, part) in parts.items()}
    apart = {hand: plan.piece for hand, plan in finger_apart(parts).items()}
    assert [n.finger for n in apart["right"].notes] == [n.finger for n in alone["right"].notes] == [2, 3, 4]
    assert {n.finger for n in alone["left"].notes} == {2, 4} and {n.finger for n in apart["left"].notes} == {2, 3}
    gap = 2 * thumb_side_reach(HandConfig())
    assert least_gap(parts, alone) < gap - 0.01 and least_gap(parts, apart) >= gap - 0.001  # (within a millimetre)


@pytest.mark.parametrize("fingers", [(2, 3, 4), (1, 2, 3, 4)])
def test_where_finger_apart_puts_a_hand_is_where_the_world_puts_it(fingers):
    """finger_apart's frames against the simulator's own (pianobot.sim.frame.HandView)."""
    import numpy as np

    from pianobot.env.two_hands import world_keyboard
    from pianobot.pianist.assign import _frame, _world_x
    from pianobot.pianist.fingering import Planner
    from pianobot.sim.frame import HandView
    from pianobot.sim.hand import FINGER_BASE_X, HandConfig
    from pianobot.sim.keyboard import KeyboardConfig
    from pianobot.sim.world import PianoWorld, WorldConfig

    spec = HandSpec(fingers)
    parts = fingered_parts(interleaved())
    keyboard = world_keyboard([window for window, _ in parts.values()])
    world = PianoWorld(
        WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=HandConfig(spec=spec)), hands=("right", "left")
    )
    try:
        offset = world.boxes[0].center[0] - _world_x(keyboard.lowest)  # (the world's keys start at its lowest)
        for index, hand in enumerate(("right", "left")):
            window, part = parts[hand]
            view = HandView(world, index, window)
            planner = Planner(KeyboardConfig(spec=window.keyboard), HandConfig(spec=spec))
            to_frame = _frame(window, part, planner)
            for x in np.linspace(0.0, 1.0, 5):
                assert to_frame(x) == pytest.approx(view.x(x + offset), abs=1e-9)
            for (_, _, wrist), chord in zip(stands(window, part), part.chords()):
                own = np.mean([planner.key_x[planner.spec.index(n.pitch)] - FINGER_BASE_X[n.finger] for n in chord])
                assert view.world_x(own) - offset == pytest.approx(wrist, abs=1e-9)
    finally:
        world.close()


def test_finger_apart_says_what_it_needs():
    parts = fingered_parts(interleaved())
    window, part = parts["left"]
    with pytest.raises(ValueError, match="every note fingered"):
        finger_apart({**parts, "left": (window, part.without_fingering())})
    with pytest.raises(ValueError, match="both hands' parts"):
        finger_apart({"right": parts["right"]})
    # a hand that keeps its fingering (a file's): only the other is planned, around it
    plans = finger_apart(parts, fixed=("right",))
    assert plans["right"] is None and {n.finger for n in plans["left"].piece.notes} == {2, 3}
