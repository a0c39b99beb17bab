"""Regenerate examples/midi/: the paper's five tasks and a few public-domain melodies.

Run `make examples` (or `python examples/make_examples.py`). Every file is written with
pianobot's own MIDI writer, so the fingering sits in lyric events as docs/fingering.md
describes. All pieces fit the default keyboard (C4-B5) and the default hand (fingers 2, 3, 4).

`minuet-performed.mid` is made to look like a recording of a human player (two named hand
tracks, timing off the grid, overlapping legato, dynamics, pedal, a slowing tempo map, no
fingering); it is generated, not recorded. So are `twinkle-performed.mid` (both hands in one
unnamed track, the right hand with octaves, thirds and a note held under a leap) and
`nocturne-performed.mid` (two unnamed tracks: a slow cantabile right hand with grace notes, a
turn, a quick run and chords a three-finger hand cannot span, over wide left-hand arpeggios),
written as a digital piano records: one tempo, the player's rubato in the note times, velocity
from the touch, the pedal changed with the harmony. Their right hands need `--hand right`,
which reduces what the robot hand cannot play (docs/fingering.md).

Three more are two-hand pieces with tracks named "Right Hand" and "Left Hand", written the same
way (rubato in the note times, the pedal changed with each bar, velocity from the touch, no
fingering), all public-domain music: `chorale-performed.mid` (Old Hundredth harmonised in four
voices, soprano and alto in the right hand, tenor and bass in the left),
`ode-to-joy-performed.mid` (the tune over a bass line of broken chords) and
`prelude-performed.mid` (the opening of Bach's Prelude in C, BWV 846: each bar's chord broken
into sixteenths). Each hand stays within the reach of its fingers chord by chord, and the right
hands lie on the default keyboard.

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


# -- recordings of a human player: voices, rubato, pedal ------------------------------------------
# Each hand is a list of voices: (tokens, base velocity, legato). A token is 'PITCH:BEATS',
# 'P+Q:BEATS' (a chord), 'r:BEATS' (a rest) or '~PITCH', a grace note sounded just before the
# next note. Legato is how far (s) a note runs into the next one; negative: detached.
GRACE_GAP = 0.1
"""Seconds between a grace note and the note it leads into (varied by +-20 ms)."""

# Twinkle Twinkle for two hands, as an amateur plays it from a simple arrangement: the melody in
# octave 5, doubled at the octave (C4+C5) or over a held inner note (E4 held while the melody
# leaps C5-G5); the left hand's broken chords, then close chords whose top note (C4) lies at or
# above the split, so that --hand right takes it into the right hand's part.
_TWINKLE_A = "C5:1 C5:1 G5:1 G5:1 A5:1 A5:1 G5:2 F5:1 F5:1 E5:1 E5:1 D5:1 D5:1 C5:2 "
_TWINKLE_B = "G5:1 G5:1 F5:1 F5:1 E5:1 E5:1 D5:2 "
TWINKLE_RIGHT = [
    (_TWINKLE_A + _TWINKLE_B * 2 + _TWINKLE_A, 74, 0.04),
    (
        "C4:1 E4:2 r:1 F5:2 E5:2 A4:2 G4:2 F4:1 B4:1 E4+G4:2 "
        "E5:2 D5:2 C5:2 B4:2 C5:4 G4:2 F4+B4:2 "
        "r:4 F5:2 E5:2 A4:2 G4:2 F4:1 B4:1 E4+G4:2",
        54,
        0.0,
    ),
]
_BROKEN = {"C": "C3 G3 E3 G3", "F": "A2 F3 C3 F3", "G": "B2 G3 D3 G3"}
TWINKLE_LEFT = [
    (
        " ".join(f"{p}:1/2" for h in "CCFCFCGC" + "CFCGCFCG" for p in _BROKEN[h].split())
        + " C3+G3+C4:2 E3+G3+C4:2 F3+A3+C4:2 E3+G3+C4:2 F3+A3+C4:2 E3+G3+C4:2 G3+B3+D4:2 C2+C3:2",
        50,
        -0.05,
    )
]

# A slow nocturne-like piece in F major, 3/4: a cantabile right hand with grace notes, a turn, a
# quick flourish and chords a three-finger hand cannot all reach (F4+C5+F5, four-note chords);
# the left hand's arpeggios span up to two octaves.
NOCTURNE_RIGHT = [
    (
        "C5:2 A4:1 ~D5 C5:3/2 Bb4:1/2 A4:1 G4:1 ~A4 G4:1/2 F4:1/2 E4:1 F4:3 "
        "A5:2 G5:1 ~Bb5 A5:3/2 G5:1/2 F5:1 E5:1/2 F5:1/2 G5:1/2 A5:1/2 Bb5:1/2 G5:1/2 F5:2 r:1 "
        "D5:1 ~E5 D5:1 C5:1 Bb4:2 A4:1 ~A4 ~G4 ~F#4 G4:2 ~B4 C5:1 C5:3 "
        "F5:1 E5:1/4 F5:1/4 E5:1/4 D5:1/4 C5:1 C5:1/6 D5:1/6 E5:1/6 F5:1/6 G5:1/6 A5:1/6 Bb5:1 G5:1 "
        "A5:1 ~G5 F5:1 E5:1 F5:3",
        72,
        0.05,
    ),
    (
        "r:9 A4+C5:3 r:3 r:3 r:3 F4+C5:2 r:1 r:3 r:3 r:3 E4+Bb4:3 r:3 r:3 r:3 F4+A4+C5:3",
        54,
        0.0,
    ),
]
_ARPEGGIO = {
    "F": "F2 C3 A3 C4 A3 C3",
    "C7": "C2 G2 E3 Bb3 E3 G2",
    "Bb": "Bb1 F2 D3 F3 D3 F2",
    "Dm": "D2 A2 F3 A3 F3 A2",
    "Gm": "G2 D3 Bb3 D4 Bb3 D3",
}
NOCTURNE_LEFT = [
    (
        " ".join(f"{p}:1/2" for h in "F F C7 F Dm Gm C7 F Bb F C7 C7 Dm Gm C7".split() for p in _ARPEGGIO[h].split())
        + " F1+F2:3",
        46,
        0.12,
    )
]


# -- two-hand pieces with tracks named for the hands (issue 35) ---------------------------------
# Old Hundredth (Louis Bourgeois, Genevan Psalter, 1551), harmonised here in four voices in G
# major, one chord per melody note, as a church pianist plays it from a hymn book: soprano and
# alto in the right hand, tenor and bass in the left, each hand within the reach of its fingers.
# Rows are (beats, soprano, alto, tenor, bass); each line of the hymn opens with a half note and
# closes on a held chord.
CHORALE = [
    *[
        (2, "G4", "D4", "B3", "G3"),
        (1, "G4", "E4", "B3", "E3"),
        (1, "F#4", "D4", "A3", "D3"),
        (1, "E4", "C4", "G3", "C3"),
    ],
    *[
        (1, "D4", "C4", "A3", "D3"),
        (1, "G4", "D4", "B3", "G3"),
        (1, "A4", "E4", "A3", "C3"),
        (4, "B4", "D4", "B3", "G3"),
    ],
    *[
        (2, "B4", "D4", "B3", "G3"),
        (1, "B4", "F#4", "B3", "D3"),
        (1, "B4", "E4", "G3", "E3"),
        (1, "A4", "D4", "F#3", "D3"),
    ],
    *[
        (1, "G4", "D4", "B3", "G3"),
        (1, "C5", "E4", "G3", "C3"),
        (1, "B4", "D4", "G3", "D3"),
        (4, "A4", "C4", "F#3", "D3"),
    ],
    *[
        (2, "G4", "D4", "B3", "G3"),
        (1, "A4", "D4", "F#3", "D3"),
        (1, "B4", "D4", "G3", "B2"),
        (1, "A4", "E4", "A3", "C3"),
    ],
    *[
        (1, "G4", "D4", "B3", "D3"),
        (1, "E4", "C4", "G3", "C3"),
        (1, "F#4", "C4", "A3", "D3"),
        (4, "G4", "D4", "B3", "G3"),
    ],
    *[
        (2, "D5", "G4", "B3", "G3"),
        (1, "B4", "E4", "G3", "E3"),
        (1, "G4", "E4", "G3", "C3"),
        (1, "A4", "F#4", "A3", "D3"),
    ],
    *[
        (1, "C5", "E4", "A3", "C3"),
        (1, "B4", "D4", "G3", "D3"),
        (1, "A4", "C4", "F#3", "D3"),
        (4, "G4", "D4", "B3", "G3"),
    ],
]
CHORALE_RIGHT = [(" ".join(f"{alto}+{soprano}:{beats}" for beats, soprano, alto, _, _ in CHORALE), 68, 0.02)]
CHORALE_LEFT = [(" ".join(f"{bass}+{tenor}:{beats}" for beats, _, _, tenor, bass in CHORALE), 56, 0.02)]

# Ode to Joy (Beethoven, Symphony No. 9, 1824) as a first piano piece: the tune in the right
# hand, a bass line of broken chords in quarter notes in the left.
_ODE_A = "E5:1 E5:1 F5:1 G5:1 G5:1 F5:1 E5:1 D5:1 C5:1 C5:1 D5:1 E5:1 "
ODE_RIGHT = [
    (
        _ODE_A
        + "E5:3/2 D5:1/2 D5:2 "
        + _ODE_A
        + "D5:3/2 C5:1/2 C5:2 "
        + "D5:1 D5:1 E5:1 C5:1 D5:1 E5:1/2 F5:1/2 E5:1 C5:1 D5:1 E5:1/2 F5:1/2 E5:1 D5:1 C5:1 D5:1 G4:2 "
        + _ODE_A
        + "D5:3/2 C5:1/2 C5:2",
        70,
        0.02,
    )
]
_ODE_BASS = {"C": "C3:1 G3:1 E3:1 G3:1", "G": "B2:1 G3:1 D3:1 G3:1", "GC": "G2:2 C3:2", "CG": "C3:2 G2:2"}
ODE_LEFT = [(" ".join(_ODE_BASS[h] for h in "C G C G C G C GC G C G CG C G C GC".split()), 52, -0.05)]

# The opening of the Prelude in C (J. S. Bach, BWV 846, 1722), as it is often played: each bar's
# chord broken into sixteenths, its two lowest notes held in the left hand, the figure above in
# the right, the pedal changed with each bar, and a player's rubato.
_PRELUDE_BARS = [
    ("C4", "E4", "G4", "C5", "E5"),
    ("C4", "D4", "A4", "D5", "F5"),
    ("B3", "D4", "G4", "D5", "F5"),
    ("C4", "E4", "G4", "C5", "E5"),
    ("C4", "E4", "A4", "E5", "A5"),
    ("C4", "D4", "F#4", "A4", "D5"),
    ("B3", "D4", "G4", "D5", "G5"),
    ("B3", "C4", "E4", "G4", "C5"),
    ("A3", "C4", "E4", "G4", "C5"),
    ("D3", "A3", "D4", "F#4", "C5"),
    ("G3", "B3", "D4", "G4", "B4"),
]
PRELUDE_RIGHT = [
    (
        " ".join(
            f"r:1/2 {c}:1/4 {d}:1/4 {e}:1/4 {c}:1/4 {d}:1/4 {e}:1/4" for *_, c, d, e in _PRELUDE_BARS for _ in "12"
        )
        + " r:1/2 C4+E4+G4:7/2",
        66,
        0.03,
    )
]
PRELUDE_LEFT = [
    (" ".join(f"{a}:2" for a, *_ in _PRELUDE_BARS for _ in "12") + " C3:4", 50, 0.05),
    (" ".join(f"r:1/4 {b}:7/4" for _, b, *_ in _PRELUDE_BARS for _ in "12") + " r:1/4 G3:15/4", 44, 0.05),
]


def _events(voices, at, rng, lead: float) -> list[tuple[float, float, int, int]]:
    """(onset s, offset s, pitch, velocity) of every note of one hand, played the way a person
    plays: onsets scattered around the beat, chords spread, the melody (first voice) a little
    ahead and louder, dynamics that swell over each phrase, grace notes just before their note."""
    out = []
    for number, (text, base, legato) in enumerate(voices):
        beat, graces = 0.0, []
        for token in text.split():
            if token.startswith("~"):
                graces.append(parse_pitch(token[1:]))
                continue
            name, beats = token.split(":")
            length = float(Fraction(beats))
            if name != "r":
                start = at(beat) - (lead if number == 0 else 0.0) + rng.normal(0, 0.012)
                end = at(beat + length)
                swell = math.sin(math.pi * (beat % 12) / 12)
                for k, pitch in enumerate(sorted(parse_pitch(p) for p in name.split("+"))[::-1]):
                    on = start + k * rng.uniform(0.0, 0.015)  # a chord's lower notes a little late
                    off = end + legato + rng.normal(0, 0.01) if legato >= 0 else on + 0.85 * (end - start)
                    velocity = base + 14 * swell + rng.normal(0, 4) - 6 * k
                    out.append((on, max(off, on + 0.05), pitch, int(np.clip(velocity, 20, 120))))
                on = start
                for pitch in reversed(graces):  # grace notes sound just before their note, legato
                    off, on = on + 0.01, on - GRACE_GAP * rng.uniform(0.8, 1.2)
                    out.append((on, off, pitch, int(np.clip(base - 10 + rng.normal(0, 4), 20, 120))))
            graces = []
            beat += length
    # a key rises before it is struck again: a note ends 20 ms before the same key sounds again
    out.sort(key=lambda e: (e[2], e[0]))
    for i in range(len(out) - 1):
        if out[i][2] == out[i + 1][2] and out[i][1] > out[i + 1][0] - 0.02:
            out[i] = (out[i][0], max(out[i][0] + 0.03, out[i + 1][0] - 0.02), *out[i][2:])
    return sorted(out)


def _clock(bpm: float, beats: float, phrase: float):
    """Seconds at each beat for a player's rubato: the tempo breathes within each phrase, slows
    into its end, and slows more at the end of the piece."""
    grid = np.arange(0.0, beats + 8.0, 1 / 48)
    where = (grid % phrase) / phrase
    speed = 1 + 0.05 * np.sin(2 * np.pi * where) - 0.15 * np.clip((where - 0.8) / 0.2, 0, 1)
    speed -= 0.3 * np.clip((grid - (beats - 4)) / 4, 0, 1)
    clock = np.concatenate([[0.0], np.cumsum(60.0 / (bpm * speed[:-1]) / 48)])
    return lambda beat: float(np.interp(beat, grid, clock))


def recording(
    right,
    left,
    bpm: float,
    beats_per_bar: int,
    phrase_bars: int,
    *,
    one_track: bool,
    seed: int = 0,
    names: tuple[str, str] | None = None,
) -> mido.MidiFile:
    """A two-hand performance the way a digital piano records it: no track names, no fingering,
    one tempo (120 bpm, the recorder's) with the music's own rubato in the note times, velocity
    from the touch, note-offs as note-ons of velocity 0, and the sustain pedal changed (up, then
    down again) just after every change of harmony. ``one_track`` writes both hands in one track
    (type 0), as most recorders do; else one track per hand after a conductor track, named
    ``names`` where given (as a notation program exports a piano score: "Right Hand", "Left Hand")."""
    rng = np.random.default_rng(seed)
    beats = sum(float(Fraction(t.split(":")[1])) for t in right[0][0].split() if not t.startswith("~"))
    at = _clock(bpm, beats, beats_per_bar * phrase_bars)
    hands = [_events(right, at, rng, lead=0.015), _events(left, at, rng, lead=0.0)]
    pedal = []
    for bar in range(int(beats // beats_per_bar) + 1):
        for half in range(0, beats_per_bar, max(1, beats_per_bar // 2) if one_track else beats_per_bar):
            when = at(bar * beats_per_bar + half)
            pedal += [(when + 0.03, 0), (when + rng.uniform(0.08, 0.14), int(rng.integers(90, 128)))]
    tick = lambda seconds: max(0, round(seconds * 960))  # noqa: E731  (480 ticks per beat at 120 bpm)
    tracks = []
    for events in [hands[0] + hands[1]] if one_track else hands:
        messages = []
        for on, off, pitch, velocity in events:
            messages += [
                (tick(on), 1, mido.Message("note_on", note=pitch, velocity=velocity)),
                (tick(off), 0, mido.Message("note_on", note=pitch, velocity=0)),
            ]
        tracks.append(messages)
    tracks[0] += [(tick(t), 0, mido.Message("control_change", control=64, value=v)) for t, v in pedal]
    meta = [
        (0, -1, mido.MetaMessage("set_tempo", tempo=500_000)),
        (0, -1, mido.MetaMessage("time_signature", numerator=beats_per_bar, denominator=4)),
    ]
    midi = mido.MidiFile(type=0 if one_track else 1, ticks_per_beat=480)
    if not one_track:
        midi.tracks.append(_track(meta))
        meta = []
    for number, messages in enumerate(tracks):
        named = [(0, -2, mido.MetaMessage("track_name", name=names[number]))] if names else []
        midi.tracks.append(_track(named + meta + [(0, -1, mido.Message("program_change", program=0))] + messages))
        meta = []
    return midi


def _track(events) -> mido.MidiTrack:
    track, last = mido.MidiTrack(), 0
    for when, _, message in sorted(events, key=lambda e: (e[0], e[1])):
        track.append(message.copy(time=when - last))
        last = when
    return track


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, piece in {**TASKS, **MELODIES}.items():
        write_midi(piece, OUT / f"{name}.mid", name=name)
    write_midi(SIDECAR.without_fingering(), OUT / "five-finger-sidecar.mid", name="five-finger-sidecar")
    write_pig(SIDECAR, OUT / "five-finger-sidecar_fingering.txt")
    performed(MINUET_RIGHT, MINUET_LEFT, bpm=84).save(OUT / "minuet-performed.mid")
    recording(TWINKLE_RIGHT, TWINKLE_LEFT, bpm=96, beats_per_bar=4, phrase_bars=2, one_track=True).save(
        OUT / "twinkle-performed.mid"
    )
    recording(NOCTURNE_RIGHT, NOCTURNE_LEFT, bpm=54, beats_per_bar=3, phrase_bars=4, one_track=False).save(
        OUT / "nocturne-performed.mid"
    )
    hands = ("Right Hand", "Left Hand")
    recording(
        CHORALE_RIGHT, CHORALE_LEFT, bpm=72, beats_per_bar=4, phrase_bars=3, one_track=False, seed=3, names=hands
    ).save(OUT / "chorale-performed.mid")
    recording(ODE_RIGHT, ODE_LEFT, bpm=100, beats_per_bar=4, phrase_bars=4, one_track=False, seed=4, names=hands).save(
        OUT / "ode-to-joy-performed.mid"
    )
    recording(
        PRELUDE_RIGHT, PRELUDE_LEFT, bpm=60, beats_per_bar=4, phrase_bars=2, one_track=False, seed=5, names=hands
    ).save(OUT / "prelude-performed.mid")
    print(f"wrote {len(TASKS) + len(MELODIES) + 7} pieces to {OUT}")


if __name__ == "__main__":
    main()
