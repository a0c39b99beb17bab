"""Experiment: `pianobot train` with the parts family drawing a share of its instances (the first
argument) from hands' parts of real chorales (out/s23/chorales.pkl), each given as `play` gives it.

    PYTHONPATH=. python docs/runs/chorale-parts/train_chorales.py 0.5 train --task parts ...
"""

import pickle
import sys
import warnings

import pianobot.agent.tasks as tasks
from pianobot.cli.app import app
from pianobot.errors import PianobotError
from pianobot.music.instrument import check_playable
from pianobot.music.piece import HANDS
from pianobot.perform.together import prepare_part

share = float(sys.argv.pop(1))
with open("out/s23/chorales.pkl", "rb") as f:
    CHORALES = pickle.load(f)
duet_part = tasks.draw_part


def draw_part(rng, config=tasks.EnvConfig()):
    if rng.random() >= share:
        return duet_part(rng, config)
    keyboard, hand = config.world.keyboard, config.world.hand
    for _ in range(100):
        piece = CHORALES[int(rng.integers(len(CHORALES)))]
        side = HANDS[int(rng.integers(len(HANDS)))]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                _, part, _, _ = prepare_part(piece, side, keyboard.spec, hand.spec, None, False)
            check_playable(part, keyboard.spec, hand.spec)
        except PianobotError:
            continue
        return part
    return duet_part(rng, config)


tasks.draw_part = draw_part
sys.argv[0] = "pianobot"
app()
