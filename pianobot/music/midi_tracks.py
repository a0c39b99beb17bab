"""A MIDI file's tracks as pianobot sees them before reading their notes: each track's name, notes,
channels, pedal presses, range and General MIDI program (:class:`TrackInfo`, :func:`list_tracks`), and
which hand a track's name says it holds (:func:`track_hand`). :mod:`pianobot.music.midi_io` reads the
notes."""

from __future__ import annotations

import re
from dataclasses import dataclass

import mido

from pianobot.music.pedal import DOWN_AT
from pianobot.music.piece import HANDS

HAND_NAMES = {
    "right": re.compile(r"\bright|\brh\b|\br\.h\.|\btreble|\bupper|\bmelod", re.IGNORECASE),
    "left": re.compile(r"\bleft|\blh\b|\bl\.h\.|\bbass(?!oon)|\blower|\baccomp", re.IGNORECASE),
}
"""What a track's name says when it holds one hand's part: words, not parts of words (General MIDI's
"Bright Acoustic Piano", "Upright", a copyright line, a bassoon hold no hand)."""
TRACK_NAMES = {"right": "Right Hand", "left": "Left Hand"}
"""The names pianobot gives the hands' tracks when it writes a piece with hands."""
UNASSIGNED_TRACK = "Unassigned"
"""The track for the notes without a hand, in a piece with hands."""


def track_hand(name: str) -> str | None:
    """The hand a track's name says it holds ('right' for 'Right Hand', 'RH', 'Treble'...), or None."""
    words = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name).replace("_", " ")  # ("PianoRight", "piano_right": two words)
    said = [hand for hand in HANDS if HAND_NAMES[hand].search(words)]
    return said[0] if len(said) == 1 else None


@dataclass(frozen=True)
class TrackInfo:
    """What one track of a MIDI file holds."""

    index: int
    name: str
    notes: int
    channels: tuple[int, ...]
    pedal: int = 0
    """Sustain pedal presses (control change 64 going down)."""
    low: int | None = None
    """Lowest and highest pitch played."""
    high: int | None = None
    program: int | None = None
    """The General MIDI program (0-127) its first program change sets, if any."""

    @property
    def instrument(self) -> str | None:
        """Its General MIDI program's family ("strings", "reed"), None where it sets none."""
        return None if self.program is None else GM_FAMILIES[self.program // 8]

    @property
    def keyboard(self) -> bool:
        """Whether its General MIDI program is a keyboard's (a piano, a celesta, an organ; a track that
        sets none plays General MIDI's default, the piano)."""
        return self.program is None or self.program < 9 or 16 <= self.program < 24


GM_FAMILIES = (
    "piano", "chromatic percussion", "organ", "guitar", "bass", "strings", "ensemble", "brass",
    "reed", "pipe", "synth lead", "synth pad", "synth effects", "ethnic", "percussive", "sound effects",
)  # fmt: skip
"""General MIDI's sixteen families of eight programs each, in program order."""


SUSTAIN = 64
"""The sustain pedal's MIDI control change number."""
PERCUSSION = 9
"""MIDI channel 10 (9 counted from 0): General MIDI's drums, whose notes are no piano keys."""


def _presses(down) -> int:
    """How many times the pedal goes down, of its states in order (a digital piano sends a stream of
    values while the foot moves: each one down is no new press)."""
    count, before = 0, False
    for now in down:
        count += now and not before
        before = now
    return count


def list_tracks(midi: mido.MidiFile) -> list[TrackInfo]:
    """Each track's name and notes (the drums' on channel 10 left out, as the reading leaves them)."""
    infos = []
    for i, track in enumerate(midi.tracks):
        name = _text(next((m.name for m in track if m.type == "track_name"), ""))
        ons = [m for m in track if m.type == "note_on" and m.velocity > 0 and m.channel != PERCUSSION]
        pedal = _presses(m.value >= DOWN_AT for m in track if m.type == "control_change" and m.control == SUSTAIN)
        pitches = [m.note for m in ons]
        infos.append(
            TrackInfo(
                i,
                name,
                len(ons),
                tuple(sorted({m.channel for m in ons})),
                pedal,
                min(pitches, default=None),
                max(pitches, default=None),
                next((m.program for m in track if m.type == "program_change"), None),
            )
        )
    return infos


def _text(text: str) -> str:
    """A text read as Latin-1 (mido's default), as UTF-8 where its bytes are UTF-8 (as pianobot writes names)."""
    try:
        return text.encode("latin-1").decode("utf-8")
    except UnicodeError:
        return text
