"""Semiquavers at 120 bpm (0.125 s a note), one hand, the scripted pianist: a C major scale over
one octave and over two (up and down), and an Alberti bass (C3 G3 E3 G3 ..., 32 notes), each
fingered by the planner and played from hand start 0 on a keyboard C2-C7.

    python -m benchmarks.semiquavers [--hand-model pianist] [--seconds 0.125]

Prints, per figure, the notes the planner could not give the hand in time and the note F1.
"""

from __future__ import annotations

import argparse

from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.piece import Note, Piece
from pianobot.perform.plan import perform_plan, plan_performance
from pianobot.pianist.fingering import plan_fingering
from pianobot.sim.hand import HAND_MODELS, default_fingers, hand_config
from pianobot.sim.keyboard import KeyboardConfig

KEYBOARD = KeyboardSpec(36, 61)
C_MAJOR = (0, 2, 4, 5, 7, 9, 11)


def line(pitches: list[int], seconds: float) -> Piece:
    """One note every ``seconds``, each held until the next."""
    return Piece(tuple(Note(seconds * i, p, seconds * (i + 1), 80) for i, p in enumerate(pitches)), bpm=120)


def scale(octaves: int) -> list[int]:
    """C major from C4 up ``octaves`` octaves and down again."""
    up = [60 + 12 * o + step for o in range(octaves) for step in C_MAJOR] + [60 + 12 * octaves]
    return up + up[-2::-1]


def alberti() -> list[int]:
    """C3 G3 E3 G3 four times, B2 G3 D3 G3 twice, C3 G3 E3 G3 twice."""
    return [48, 55, 52, 55] * 4 + [47, 55, 50, 55] * 2 + [48, 55, 52, 55] * 2


def play(piece: Piece, hand: HandSpec) -> tuple[int, float]:
    """(notes the planner could not give in time, note F1 of the scripted pianist)."""
    plan = plan_fingering(piece, KeyboardConfig(spec=KEYBOARD), hand_config(hand))
    performance = perform_plan(plan_performance(plan.piece, "scripted", hand=hand, keyboard=KEYBOARD))
    return len(plan.problems), performance.report().f1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hand-model", choices=tuple(HAND_MODELS), default="pianist", help="the hand that plays")
    parser.add_argument("--seconds", type=float, default=0.125, help="seconds a note (default 0.125)")
    args = parser.parse_args()
    hand = default_fingers(args.hand_model)
    for name, pitches in (
        ("scale, one octave", scale(1)),
        ("scale, two octaves", scale(2)),
        ("Alberti bass", alberti()),
    ):
        problems, f1 = play(line(pitches, args.seconds), hand)
        print(f"{name} ({len(pitches)} notes): {problems} note(s) too fast for the planner, note F1 {f1:.3f}")


if __name__ == "__main__":
    main()
