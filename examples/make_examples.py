"""Regenerate examples/midi/: the paper's five tasks and a few public-domain melodies.

Run `make examples` (or `python examples/make_examples.py`). Every file is written with
pianobot's own MIDI writer, so the fingering sits in lyric events as docs/fingering.md
describes. All pieces fit the default keyboard (C4-B5) and the default hand (fingers 2, 3, 4).

Fingerings were chosen by hand for a three-finger hand: within one hand position the index,
middle and ring fingers lie over three neighbouring white keys, and the wrist moves between
positions.
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

from pianobot.music.midi_io import write_midi
from pianobot.music.pig import write_pig
from pianobot.music.piece import Note, Piece, parse_pitch

OUT = Path(__file__).parent / "midi"


def melody(bpm: float, events: str, velocities: list[int] | None = None) -> Piece:
    """Notes from 'PITCH:BEATS:FINGER' tokens; a chord joins pitches with '+' and fingers with '+'.

    A rest is 'r:BEATS'. Durations are in beats at ``bpm`` (fractions allowed: '1/3').
    """
    beat = 60.0 / bpm
    notes, time, index = [], 0.0, 0
    for token in events.split():
        parts = token.split(":")
        beats = float(Fraction(parts[1]))
        if parts[0] != "r":
            pitches = parts[0].split("+")
            fingers = parts[2].split("+")
            for pitch, finger in zip(pitches, fingers):
                velocity = velocities[index % len(velocities)] if velocities else 80
                notes.append(Note(time, parse_pitch(pitch), time + beats * beat, velocity, int(finger)))
            index += 1
        time += beats * beat
    return Piece(tuple(notes), bpm=bpm)


TASKS = {
    # The paper's task families (section "Learning to Play the Piano"), at its 60 bpm.
    "one-note": melody(60, "E4:1:3", [80]),
    "three-note": melody(60, "C4:1:2 D4:1:3 E4:1:4", [70, 95, 60]),
    "six-note": melody(60, "C4:1:2 D4:1:3 E4:1:4 F4:1:2 G4:1:3 A4:1:4", [64, 80, 96, 72, 88, 56]),
    "rhythmic": melody(60, "C4:1:2 D4:1/2:3 E4:1/2:4 D4:1/3:3 C4:1/3:2 D4:1/3:3", [80, 64, 96, 72, 56, 88]),
    "chord": melody(60, "C4+E4:1:2+4 D4+F4:1:2+4 E4+G4:1:2+4", [70, 90, 60]),
}

MELODIES = {
    "twinkle": melody(
        90,
        "C4:1:2 C4:1:2 G4:1:3 G4:1:3 A4:1:4 A4:1:4 G4:2:3 "
        "F4:1:2 F4:1:2 E4:1:4 E4:1:4 D4:1:3 D4:1:3 C4:2:2",
        [72, 72, 84, 84, 92, 92, 86, 76, 76, 70, 70, 66, 66, 60],
    ),
    "ode-to-joy": melody(
        90,
        "E4:1:2 E4:1:2 F4:1:3 G4:1:4 G4:1:4 F4:1:3 E4:1:2 "
        "D4:1:3 C4:1:2 C4:1:2 D4:1:3 E4:1:4 E4:3/2:4 D4:1/2:3 D4:2:3",
        [70, 72, 76, 84, 86, 80, 74, 70, 64, 66, 70, 80, 84, 72, 62],
    ),
    "mary": melody(
        100,
        "E4:1:4 D4:1:3 C4:1:2 D4:1:3 E4:1:4 E4:1:4 E4:2:4 "
        "D4:1:3 D4:1:3 D4:2:3 E4:1:2 G4:1:4 G4:2:4 "
        "E4:1:4 D4:1:3 C4:1:2 D4:1:3 E4:1:4 E4:1:4 E4:1:4 E4:1:4 D4:1:3 D4:1:3 E4:1:4 D4:1:3 C4:4:2",
        [80, 74, 68, 74, 80, 82, 84, 72, 74, 76, 82, 92, 90, 80, 74, 68, 74, 80, 82, 84, 86, 76, 74, 78, 70, 60],
    ),
    "c-major-scale": melody(
        80,
        "C4:1:2 D4:1:3 E4:1:4 F4:1:2 G4:1:3 A4:1:4 B4:1:2 C5:1:3 "
        "B4:1:2 A4:1:3 G4:1:2 F4:1:4 E4:1:3 D4:1:2 C4:2:2",
        [60, 64, 68, 72, 76, 80, 84, 90, 84, 80, 76, 72, 68, 64, 60],
    ),
}

# A piece whose fingering comes from a PIG sidecar file instead of lyric events.
SIDECAR = melody(80, "G4:1:2 A4:1:3 B4:1:4 A4:1:3 G4:2:2", [70, 80, 90, 80, 70])


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, piece in {**TASKS, **MELODIES}.items():
        write_midi(piece, OUT / f"{name}.mid", name=name)
    write_midi(SIDECAR.without_fingering(), OUT / "five-finger-sidecar.mid", name="five-finger-sidecar")
    write_pig(SIDECAR, OUT / "five-finger-sidecar_fingering.txt")
    print(f"wrote {len(TASKS) + len(MELODIES) + 1} pieces to {OUT}")


if __name__ == "__main__":
    main()
