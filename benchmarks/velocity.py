"""Velocity calibration as played: the scripted pianist strikes one key at a range of target
velocities; the table shows what the simulated keyboard sounded.

    python benchmarks/velocity.py
"""

from __future__ import annotations

from pianobot.music.piece import Note, Piece, pitch_name
from pianobot.perform.perform import perform

TARGETS = (10, 30, 50, 70, 90, 110, 127)


def main() -> None:
    print("| key | " + " | ".join(str(v) for v in TARGETS) + " |")
    print("| --- |" + " ---: |" * len(TARGETS))
    for pitch in (64, 66):  # a white key (E4) and a black key (F#4)
        played = []
        for target in TARGETS:
            piece = Piece((Note(0.0, pitch, 0.5, target, 3),), bpm=60)
            notes = perform(piece, "scripted", seed=0).played.notes
            played.append("/".join(str(n.velocity) for n in notes) or "-")
        print(f"| {pitch_name(pitch)} | " + " | ".join(played) + " |")


if __name__ == "__main__":
    main()
