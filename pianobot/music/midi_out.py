"""Pieces out to standard MIDI files: one track per hand for a piece with hands, fingering in
lyric events (:mod:`pianobot.music.midi_io` reads them back; its conventions are there)."""

from __future__ import annotations

import io
from pathlib import Path

import mido

from pianobot.files import atomic_write
from pianobot.music.finger_text import finger_text
from pianobot.music.midi_io import SUSTAIN, TRACK_NAMES, UNASSIGNED_TRACK
from pianobot.music.pedal import Pedal
from pianobot.music.piece import Piece


def _write_resolution(bpm: float) -> tuple[int, int]:
    """(tempo in microseconds per beat, ticks per beat) so that one tick is exactly 1 ms."""
    tempo = max(1000, round(60e6 / bpm / 1000) * 1000)
    return tempo, tempo // 1000


def _track(part: Piece, name: str, tempo: int | None, pedal: Pedal = Pedal()) -> mido.MidiTrack:
    """One track of ``part``'s notes with fingering lyrics, named ``name``, with the tempo if given
    and the sustain pedal (control change 64: 127 down, 0 up)."""
    events: list[tuple[int, int, mido.Message | mido.MetaMessage]] = []
    for time, down in pedal.changes():  # (a release sorts before the note-offs at its tick, a press after them)
        message = mido.Message("control_change", control=SUSTAIN, value=127 if down else 0)
        events.append((round(time * 1000), 3 if down else 0, message))
    for chord in part.chords():
        tick = round(chord[0].onset * 1000)
        if any(n.finger is not None for n in chord):
            text = finger_text([n.finger for n in sorted(chord, key=lambda n: n.pitch)])
            events.append((tick, 1, mido.MetaMessage("lyrics", text=text)))
        for note in chord:
            events.append((tick, 2, mido.Message("note_on", note=note.pitch, velocity=note.velocity)))
    for note in part.notes:
        events.append((round(note.offset * 1000), 0, mido.Message("note_off", note=note.pitch, velocity=0)))
    events.sort(key=lambda e: (e[0], e[1]))
    track = mido.MidiTrack()
    track.append(mido.MetaMessage("track_name", name=name))
    if tempo is not None:
        track.append(mido.MetaMessage("set_tempo", tempo=tempo))
    last = 0
    for tick, _, msg in events:
        track.append(msg.copy(time=tick - last))
        last = tick
    track.append(mido.MetaMessage("end_of_track", time=0))
    return track


def midi_bytes(piece: Piece, *, name: str = "pianobot", pedal: Pedal = Pedal()) -> bytes:
    """The piece as a MIDI file with 1 ms ticks and fingering lyrics: type 0 (one track named
    ``name``) when no note has a hand, else type 1 with one track per hand ("Right Hand", "Left
    Hand", then "Unassigned" for notes without a hand), the first carrying the tempo and ``pedal``."""
    tempo, tpb = _write_resolution(piece.bpm)
    if piece.hands:
        parts = [(TRACK_NAMES[hand], piece.part(hand)) for hand in piece.hands]
        parts += [(UNASSIGNED_TRACK, piece.part(None))] if any(n.hand is None for n in piece.notes) else []
    else:
        parts = [(name, piece)]
    # any name: a file name may be '音.mid'
    midi = mido.MidiFile(type=1 if piece.hands else 0, ticks_per_beat=tpb, charset="utf-8")
    for i, (track_name, part) in enumerate(parts):
        midi.tracks.append(_track(part, track_name, tempo if i == 0 else None, pedal if i == 0 else Pedal()))
    buffer = io.BytesIO()
    midi.save(file=buffer)
    return buffer.getvalue()


def write_midi(piece: Piece, path: str | Path, *, name: str = "pianobot", pedal: Pedal = Pedal()) -> Path:
    """Write ``piece`` (and its sustain ``pedal``) to ``path`` atomically (see :func:`midi_bytes`)."""
    return atomic_write(path, midi_bytes(piece, name=name, pedal=pedal))
