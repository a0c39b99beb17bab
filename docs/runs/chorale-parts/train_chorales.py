"""Experiment: the parts family with hands' parts of real chorales (out/s23/chorales.pkl) for a share of its instances."""
import sys, pickle, warnings
import numpy as np
import pianobot.agent.tasks as tasks
from pianobot.errors import PianobotError
from pianobot.music.piece import HANDS
from pianobot.perform.hands import prepare_part
from pianobot.music.instrument import check_playable

share = float(sys.argv.pop(1))
CHORALES = pickle.load(open("out/s23/chorales.pkl", "rb"))
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
                window, part, start, left = prepare_part(piece, side, keyboard.spec, hand.spec, None, False)
            check_playable(part, keyboard.spec, hand.spec)
        except PianobotError:
            continue
        return part
    return duet_part(rng, config)

tasks.draw_part = draw_part
from pianobot.cli.app import app
sys.argv[0] = "pianobot"
app()
