"""Both hands in one simulation (pianobot/env/two_hands.py, pianobot/sim/frame.py): each hand sees
itself as the one-hand environment's right hand, the left one mirrored, and plays its own part."""

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.env.two_hands import HandsEnv, world_keyboard
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.metrics import compare
from pianobot.music.piece import Note, Piece
from pianobot.music.window import Window
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.frame import HandView

KEYS = KeyboardSpec()  # the players' 24 keys, C4-B5
RIGHT = Window("right", KEYS, -1)  # the right hand's part written an octave higher: C5-B6
LEFT = Window("left", KEYS, -1)  # the left hand's mirrored and an octave lower: F1-E3
CONFIG = EnvConfig(tactile=True)
PHRASE = Piece(
    (
        Note(0.0, 60, 0.5, 70, 2),
        Note(0.5, 64, 1.0, 90, 3),
        Note(1.0, 67, 1.5, 60, 4),
        Note(1.5, 64, 2.0, 80, 3),
        Note(2.0, 60, 2.2, 100, 2),
    )
)
"""A phrase in the players' keys, fingered for a right hand."""


def test_the_world_holds_the_keys_of_both_windows():
    spec = world_keyboard([RIGHT, LEFT])
    assert (spec.lowest, spec.lowest + spec.count - 1) == (124 - 83 - 12, 83 + 12)
    with pytest.raises(ValueError, match="more than a piano's 88"):
        world_keyboard([Window("right", KEYS, -3), LEFT])  # C7-B8 and F1-E3


TOLERANCE = {"score": 0.0, "wrist": 0.01, "joints": 0.01, "joint_velocities": 0.05, "targets": 0.02, "tactile": 8}


def mirrored_env(seed_part: Piece = PHRASE) -> HandsEnv:
    """Both hands given the same phrase in their own frames: the left plays its mirror image."""
    return HandsEnv({"right": (RIGHT, seed_part), "left": (LEFT, seed_part)}, {"right": CONFIG, "left": CONFIG})


def test_a_left_hand_given_the_mirror_image_sees_what_the_right_hand_sees():
    """Same phrase in both frames, same seed: the world is symmetric, so every observation of the
    left hand (score, wrist, joints, finger targets, tactile images) is the right hand's, step by
    step, as the scripted pianist plays both."""
    env = mirrored_env()
    try:
        observations, _ = env.reset(seed=3)
        players = {h: ScriptedPianist(CONFIG) for h in env.hands}
        for step in range(env.horizon):
            for key in observations["right"]:  # (the solver's order differs slightly between the hands)
                left, right = (np.asarray(observations[h][key], float) for h in ("left", "right"))
                assert np.abs(left - right).max() <= TOLERANCE[key], (step, key)
            observations, _, _, truncated, info = env.step({h: p.act(observations[h]) for h, p in players.items()})
            assert info["rewards"]["left"] == pytest.approx(info["rewards"]["right"], abs=1e-3)
        assert truncated
    finally:
        env.close()


def test_a_hands_view_maps_places_and_keys_both_ways():
    env = mirrored_env()
    try:
        left: HandView = env.view("left")
        for q in (60, 61, 70, 83):  # each key of the view lies where the world's key it stands for does
            world_pitch = LEFT.outward(q)
            assert world_pitch == 124 - (q + 12) and left.pitch(world_pitch) == q
            box = env.world.boxes[world_pitch - env.world.config.keyboard.spec.lowest]
            assert left.x(box.center[0]) == pytest.approx(left.boxes[q - KEYS.lowest].center[0])
        assert left.pitch(RIGHT.outward(70)) is None  # a key of the right hand's half: not the left's
        assert left.world_action(np.ones(13))[-1] == -1.0  # the mirrored wrist moves the other way
    finally:
        env.close()


def test_both_hands_play_their_parts_and_each_note_is_credited_to_its_hand():
    """A right-hand phrase and a different left-hand one, together: the scripted pianist plays
    both (note F1 1.0 per hand against its part in the world's keys), every note sounded by the
    hand whose part it is."""
    left_part = Piece(
        tuple(Note(n.onset + 0.25, n.pitch + 2, n.offset + 0.25, n.velocity, n.finger) for n in PHRASE.notes)
    )
    env = HandsEnv({"right": (RIGHT, PHRASE), "left": (LEFT, left_part)}, {"right": CONFIG, "left": CONFIG})
    from pianobot.sim.recorder import NoteRecorder

    try:
        observations, _ = env.reset(seed=0)
        players = {h: ScriptedPianist(CONFIG) for h in env.hands}
        recorder = NoteRecorder()
        while True:
            observations, _, _, truncated, info = env.step({h: p.act(observations[h]) for h, p in players.items()})
            recorder.add(info["events"], info["fingers"], info["struck_by"])
            if truncated:
                break
        played = recorder.piece(end=env.world.time, start=env.score_start)
    finally:
        env.close()
    for hand, window, part in (("right", RIGHT, PHRASE), ("left", LEFT, left_part)):
        written = Piece(
            tuple(Note(n.onset, window.outward(n.pitch), n.offset, n.velocity, n.finger) for n in part.notes)
        )
        own = Piece(tuple(n for n in played.notes if n.hand == hand))
        assert compare(written, own).f1 == 1.0, hand
    assert (
        env.horizon == PianoEnv(piece=left_part, config=EnvConfig(tactile=False)).horizon
    )  # as long as the longer part


SHARED = Window("left", KEYS, 1)
"""A left window over nearly the right one's keys (C4-B5 mirrored an octave up: G3-E5)."""


def test_starts_closer_than_the_world_allows_are_moved_apart():
    env = HandsEnv({"right": (RIGHT, PHRASE), "left": (SHARED, PHRASE)}, {"right": CONFIG, "left": CONFIG})
    try:
        gap, width = env.world.min_separation, env.world.width
        for right, left in ((0.5, 0.5), (0.5, 0.6), (0.0, 0.0), (width, width), (0.3, 0.25)):
            high, low = env._apart(right, left)
            assert high - low == pytest.approx(gap) and 0.0 <= low and high <= width, (right, left)
        assert env._apart(0.6, 0.2) == (0.6, 0.2)  # far enough: left where they were
        moved = 0
        for seed in range(12):
            drawn = [env.view(h).world_wrist(e.draw_start(seed)) for h, e in env.hands.items()]
            moved += drawn[0] - drawn[1] < gap
            env.reset(seed=seed)
            assert env.world.hand_state(0)[0] - env.world.hand_state(1)[0] >= gap - 1e-6
        assert moved  # (some of the starts drawn were too close)
    finally:
        env.close()


def test_a_hand_is_not_rewarded_or_blamed_for_the_keys_the_other_hand_plays():
    """Windows that share keys: the right hand holds C5, a key of the left hand's view too; the
    left hand hears it, but its step info never has it pressed (so its reward neither pays nor
    blames it), and no finger of the left hand is credited with it."""
    part = Piece((Note(0.0, 60, 1.0, 80, 3),))  # the right hand's C4: the world's C5
    left_part = Piece((Note(0.0, SHARED.inward(57), 1.0, 80, 3),))  # A3
    env = HandsEnv({"right": (RIGHT, part), "left": (SHARED, left_part)}, {"right": CONFIG, "left": CONFIG})
    c5 = env.view("left").pitch(RIGHT.outward(60))
    assert c5 is not None  # C5 lies in both windows
    try:
        observations, _ = env.reset(seed=1)
        players = {h: ScriptedPianist(CONFIG) for h in env.hands}
        heard = sounded = 0
        while True:
            observations, _, _, truncated, info = env.step({h: p.act(observations[h]) for h, p in players.items()})
            left, right = info["hands"]["left"], info["hands"]["right"]
            heard += any(e.pitch == c5 and e.on for e in left["events"])
            sounded += bool(right["pressed"][60 - KEYS.lowest])
            assert not left["pressed"][c5 - KEYS.lowest] and c5 not in left["fingers"]
            if truncated:
                break
        assert heard == 1 and sounded > 10  # the right hand held it for many steps
    finally:
        env.close()


def test_hands_of_other_timelines_or_a_discrete_wrist_are_refused():
    from dataclasses import replace

    for left in (replace(CONFIG, lead_in=0.0), replace(CONFIG, tail=1.0)):
        with pytest.raises(ValueError, match="lead-in and tail"):
            HandsEnv({"right": (RIGHT, PHRASE), "left": (LEFT, PHRASE)}, {"right": CONFIG, "left": left})
    discrete = replace(CONFIG, world=replace(CONFIG.world, discrete_wrist=True))
    with pytest.raises(ValueError, match="discrete wrist"):
        HandsEnv({"right": (RIGHT, PHRASE), "left": (LEFT, PHRASE)}, {"right": discrete, "left": discrete})


def test_the_hands_must_share_their_physics():
    other = EnvConfig(world=CONFIG.world.__class__(solver_iterations=20))
    with pytest.raises(ValueError, match="share their physics"):
        HandsEnv({"right": (RIGHT, PHRASE), "left": (LEFT, PHRASE)}, {"right": CONFIG, "left": other})
