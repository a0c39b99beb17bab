"""Regenerate examples/midi/: the paper's five tasks and a few public-domain melodies.

Run `make examples` (or `python examples/make_examples.py`). Every file is written with
pianobot's own MIDI writer, so the fingering sits in lyric events as docs/fingering.md
describes. All pieces fit the default keyboard (C4-B5) and the default hand (fingers 2, 3, 4).

`minuet-performed.mid` is made to look like a recording of a human player (two named hand
tracks, timing off the grid, overlapping legato, dynamics, pedal, a slowing tempo map, no
fingering); it is generated, not recorded.

Fingerings were chosen by hand for a three-finger hand: within one hand position the index,
middle and ring fingers lie over three neighbouring white keys, and the wrist moves between
positions.
"""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import mido
import numpy as np

from pianobot.music.midi_io import write_midi
from pianobot.music.piece import Note, Piece, parse_pitch
from pianobot.music.pig import write_pig

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
        "C4:1:2 C4:1:2 G4:1:3 G4:1:3 A4:1:4 A4:1:4 G4:2:3 F4:1:2 F4:1:2 E4:1:4 E4:1:4 D4:1:3 D4:1:3 C4:2:2",
        [72, 72, 84, 84, 92, 92, 86, 76, 76, 70, 70, 66, 66, 60],
    ),
    "ode-to-joy": melody(
        90,
        "E4:1:2 E4:1:2 F4:1:3 G4:1:4 G4:1:4 F4:1:3 E4:1:2 D4:1:3 C4:1:2 C4:1:2 D4:1:3 E4:1:4 E4:3/2:4 D4:1/2:3 D4:2:3",
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
        "C4:1:2 D4:1:3 E4:1:4 F4:1:2 G4:1:3 A4:1:4 B4:1:2 C5:1:3 B4:1:2 A4:1:3 G4:1:2 F4:1:4 E4:1:3 D4:1:2 C4:2:2",
        [60, 64, 68, 72, 76, 80, 84, 90, 84, 80, 76, 72, 68, 64, 60],
    ),
}

# A piece whose fingering comes from a PIG sidecar file instead of lyric events.
SIDECAR = melody(80, "G4:1:2 A4:1:3 B4:1:4 A4:1:3 G4:2:2", [70, 80, 90, 80, 70])


# The opening of the Minuet in G (BWV Anh. 114) as a two-hand piano part, no fingering: (pitch, beats).
MINUET_RIGHT = (
    "D5:1 G4:1/2 A4:1/2 B4:1/2 C5:1/2 D5:1 G4:1 G4:1 E5:1 C5:1/2 D5:1/2 E5:1/2 F#5:1/2 G5:1 G4:1 G4:1 "
    "C5:1 D5:1/2 C5:1/2 B4:1/2 A4:1/2 B4:1 C5:1/2 B4:1/2 A4:1/2 G4:1/2 F#4:1 G4:1/2 A4:1/2 B4:1/2 G4:1/2 "
    "A4:3 D5:1 G4:1/2 A4:1/2 B4:1/2 C5:1/2 D5:1 G4:1 G4:1 E5:1 C5:1/2 D5:1/2 E5:1/2 F#5:1/2 G5:1 G4:1 G4:1 "
    "C5:1 D5:1/2 C5:1/2 B4:1/2 A4:1/2 B4:1 C5:1/2 B4:1/2 A4:1/2 G4:1/2 A4:1 B4:1/2 A4:1/2 G4:1/2 F#4:1/2 G4+B4+D5+G5:3"
)
MINUET_LEFT = "G3+B3:2 A3:1 B3:3 C4:3 B3:3 A3:3 G3:3 D4:1 B3:1 G3:1 D4:1 D3:1 C4:1 " * 1 + (
    "B3:3 C4:3 B3:3 A3:3 G3:3 D3:3 G3:3 D3:3 G2:3"
)


def performed(right: str, left: str, bpm: float, seed: int = 0) -> mido.MidiFile:
    """A two-track file the way a recording of a human player looks: named hand tracks, timing a
    little off the beat, legato notes overlapping, dynamics that swell and fade, a tempo map that
    slows at the end, and the sustain pedal changed every bar; no fingering."""
    rng = np.random.default_rng(seed)
    tpb = 480
    midi = mido.MidiFile(type=1, ticks_per_beat=tpb)
    conductor = mido.MidiTrack([mido.MetaMessage("track_name", name="tempo", time=0)])
    total_beats = sum(float(Fraction(t.split(":")[1])) for t in right.split())
    changes = [(0, bpm), (total_beats - 6, bpm * 0.92), (total_beats - 3, bpm * 0.8)]
    last = 0
    for beat, tempo in changes:
        tick = round(beat * tpb)
        conductor.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(tempo), time=tick - last))
        last = tick
    midi.tracks.append(conductor)
    for name, part, base in (("Right Hand", right, 76), ("Left Hand", left, 56)):
        events, beat = [], 0.0
        for token in part.split():
            pitches, beats = token.split(":")
            length = float(Fraction(beats))
            phrase = math.sin(math.pi * (beat % 12) / 12)  # swell within each four-bar phrase
            for pitch in pitches.split("+"):
                on = max(0, round((beat + rng.normal(0, 0.02)) * tpb))
                off = round((beat + length + rng.uniform(0.0, 0.08)) * tpb)  # legato: a little into the next note
                velocity = int(np.clip(base + 18 * phrase + rng.normal(0, 5), 20, 120))
                events += [
                    (on, 1, mido.Message("note_on", note=parse_pitch(pitch), velocity=velocity)),
                    (off, 0, mido.Message("note_off", note=parse_pitch(pitch), velocity=40)),
                ]
            beat += length
        if name == "Right Hand":
            for bar in range(int(beat // 3) + 1):  # pedal up and down again just after each downbeat
                events += [
                    (bar * 3 * tpb + 30, 0, mido.Message("control_change", control=64, value=0)),
                    (bar * 3 * tpb + 60, 1, mido.Message("control_change", control=64, value=100)),
                ]
        track = mido.MidiTrack([mido.MetaMessage("track_name", name=name, time=0)])
        last = 0
        for tick, _, message in sorted(events, key=lambda e: (e[0], e[1])):
            track.append(message.copy(time=tick - last))
            last = tick
        midi.tracks.append(track)
    return midi


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, piece in {**TASKS, **MELODIES}.items():
        write_midi(piece, OUT / f"{name}.mid", name=name)
    write_midi(SIDECAR.without_fingering(), OUT / "five-finger-sidecar.mid", name="five-finger-sidecar")
    write_pig(SIDECAR, OUT / "five-finger-sidecar_fingering.txt")
    performed(MINUET_RIGHT, MINUET_LEFT, bpm=84).save(OUT / "minuet-performed.mid")
    print(f"wrote {len(TASKS) + len(MELODIES) + 2} pieces to {OUT}")


if __name__ == "__main__":
    main()
