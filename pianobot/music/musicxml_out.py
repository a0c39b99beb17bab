"""A piece written as a MusicXML score (``pianobot finger -o song.musicxml``), with music21.

Both hands: one piano part of two staves, the right hand's on the upper, the left hand's on the
lower (notes without a hand on a third); one hand: one staff. Notes that start and end together are a
chord, others their own voices. Each note's finger is a fingering mark (a chord's notes each
their own); the piece's tempo is a metronome mark (shown in whole beats a minute, sounding exactly). Onsets and lengths
are counted in beats at that tempo and moved to the nearest sixteenth or eighth-note triplet
(:data:`GRID`), so that a notation program shows them as notes; a piece played by a person (not
on a grid) is written as the nearest such notes. Reading the score back
(:mod:`pianobot.music.musicxml`) gives the same pitches, hands and fingers, and the onsets to that
quantization. A ``.mxl`` name gets the compressed form.
"""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

from pianobot.files import atomic_write
from pianobot.music.musicxml import music21
from pianobot.music.piece import Note, Piece

GRID = (4, 3)
"""Divisions of a beat that onsets and lengths are moved to: sixteenths and eighth-note triplets."""
CONTAINER = (
    '<?xml version="1.0" encoding="UTF-8"?>\n<container><rootfiles>'
    '<rootfile full-path="score.musicxml" media-type="application/vnd.recordare.musicxml+xml"/>'
    "</rootfiles></container>\n"
)


def musicxml_bytes(piece: Piece, *, name: str = "pianobot", compressed: bool = False) -> bytes:
    """The piece as a MusicXML score (see the module's text); ``compressed``: as an .mxl archive."""
    m21 = music21()
    score = m21.stream.Score()
    score.insert(0, m21.metadata.Metadata(title=name))
    staves = [(hand, piece.part(hand)) for hand in piece.hands]
    if any(n.hand is None for n in piece.notes):
        staves.append((None, piece.part(None)))
    if len(staves) == 1:
        score.insert(0, _staff(m21, m21.stream.Part(), staves[0][1], piece.bpm, name, staves[0][0] == "left"))
    else:
        parts = [
            _staff(m21, m21.stream.PartStaff(), part, piece.bpm, name, hand == "left", tempo=i == 0)
            for i, (hand, part) in enumerate(staves)
        ]
        for part in parts:
            score.insert(0, part)
        score.insert(0, m21.layout.StaffGroup(parts, name=name, symbol="brace"))
    xml = m21.musicxml.m21ToXml.GeneralObjectExporter(score).parse()
    if not compressed:
        return xml
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("META-INF/container.xml", CONTAINER)
        archive.writestr("score.musicxml", xml)
    return buffer.getvalue()


def write_musicxml(piece: Piece, path: str | Path, *, name: str = "pianobot") -> Path:
    """Write ``piece`` to ``path`` as MusicXML, atomically (see :func:`musicxml_bytes`)."""
    return atomic_write(path, musicxml_bytes(piece, name=name, compressed=Path(path).suffix.lower() == ".mxl"))


def _staff(m21, staff, part: Piece, bpm: float, name: str, bass: bool, tempo: bool = True):
    """``staff`` (a music21 Part or PartStaff) holding ``part``'s notes, fingered, in beats at ``bpm``."""
    staff.partName = name
    staff.insert(0, m21.clef.BassClef() if bass else m21.clef.TrebleClef())
    if tempo:
        shown = round(bpm)  # (the mark a notation program shows; the tempo sounds exactly)
        staff.insert(0, m21.tempo.MetronomeMark(number=shown, numberSounding=None if shown == bpm else round(bpm, 4)))
    voices: list[tuple[float, object]] = []  # (where the voice's last note ends, the voice)
    for onset, length, element in _elements(m21, part, bpm / 60.0):
        free = next((i for i, (end, _) in enumerate(voices) if end <= onset), None)
        if free is None:
            voices.append((0.0, m21.stream.Voice()))
            free = len(voices) - 1
        voices[free][1].insert(onset, element)
        voices[free] = (onset + length, voices[free][1])
    if len(voices) == 1:
        for element in voices[0][1].notes:
            staff.insert(element.offset, element)
    else:
        for _, voice in voices:
            staff.insert(0, voice)
    staff.makeNotation(inPlace=True)
    return staff


def _elements(m21, part: Piece, beat: float) -> list[tuple[float, float, object]]:
    """(onset, length, music21 note or chord) for ``part``'s notes, in beats (``beat`` a second's),
    the notes that start and end together a chord, each note with its fingering mark."""
    together: dict[tuple[float, float], list[Note]] = {}
    for note in part.notes:
        onset = _beats(note.onset * beat)
        length = max(_beats(note.offset * beat) - onset, 1 / max(GRID))
        together.setdefault((onset, length), []).append(note)
    elements = []
    for (onset, length), notes in sorted(together.items()):
        notes = sorted(notes, key=lambda n: n.pitch)
        element = m21.note.Note(notes[0].pitch) if len(notes) == 1 else m21.chord.Chord([n.pitch for n in notes])
        element.quarterLength = length
        for n in notes:
            element.articulations.append(m21.articulations.Fingering(n.finger if n.finger is not None else "-"))
        elements.append((onset, length, element))
    return elements


def _beats(value: float) -> float:
    """``value`` (in beats) moved to the nearest line of :data:`GRID`."""
    return min((round(value * d) / d for d in GRID), key=lambda v: abs(v - value))
