"""benchmarks/sim.py with each hand model: what it replays is what that hand played."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from benchmarks import sim
from pianobot.music.load import load_piece
from pianobot.music.piece import Piece
from pianobot.sim.hand import default_fingers

TWINKLE = sim.ROOT / "examples" / "midi" / "twinkle.mid"


def test_a_hand_the_file_fingers_keeps_the_file_s_fingering_and_another_is_fingered_by_the_planner():
    piece = load_piece(TWINKLE)  # (fingers 2-4: both hands have them)
    assert sim.fingered(piece, default_fingers("allegro")) is piece
    assert sim.fingered(piece, default_fingers("pianist")) is piece
    thumb = Piece(tuple(replace(n, finger=1) if i == 0 else n for i, n in enumerate(piece.notes)), bpm=piece.bpm)
    assert sim.fingered(thumb, default_fingers("pianist")) is thumb
    allegro = sim.fingered(thumb, default_fingers("allegro"))
    assert [(n.onset, n.pitch) for n in allegro.notes] == [(n.onset, n.pitch) for n in piece.notes]
    assert {n.finger for n in allegro.notes} <= set(default_fingers("allegro").fingers)


def pressed(env, actions) -> set[int]:
    keys = set()
    for action in actions:
        info = env.step(action)[4]
        keys |= set(np.flatnonzero(info["pressed"]).tolist())
    env.close()
    return keys


@pytest.mark.parametrize("model", ["allegro", "pianist"])
def test_the_replay_presses_the_keys_the_recorded_hand_played_on_either_keyboard(model):
    spec = default_fingers(model)
    piece = sim.fingered(load_piece(TWINKLE), spec)
    actions, wrist, touching, _ = sim.record(piece, spec)
    assert len(actions[0]) == 4 * len(spec.fingers) + 1 and touching
    written = {n.pitch for n in piece.notes}
    on_paper = pressed(sim.replay_env(piece, wrist, False, sim.PAPER, spec), actions)
    assert {sim.PAPER.lowest + k for k in on_paper} == written
    on_piano = pressed(sim.replay_env(piece, wrist, False, sim.PIANO, spec), actions)
    assert {sim.PIANO.lowest + k for k in on_piano} == written
