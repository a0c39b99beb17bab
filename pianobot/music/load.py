"""From a file on disk to a validated piece: the one entry point the CLI and training use."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music import midi_io, pig
from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable
from pianobot.music.piece import Piece


@dataclass(frozen=True)
class LoadOptions:
    """How to read a piece."""

    track: str | None = None
    """One track by index or name; None merges all tracks."""
    tempo: float | None = None
    """Re-time the piece at this constant tempo in bpm (the paper plays at 60); None keeps the file's tempo map."""
    transpose: int = 0
    """Shift every note by this many semitones."""
    fingering: Path | None = None
    """A PIG fingering file for the notes; None looks for the sidecar ``<name>_fingering.txt``."""


def load_piece(path: str | Path, options: LoadOptions = LoadOptions()) -> Piece:
    """Read a .mid file (or a PIG .txt file) with its fingering, then re-time and transpose it."""
    path = Path(path)
    if path.suffix.lower() == ".txt":
        if options.tempo is not None:
            raise PianobotError("--tempo needs a MIDI file: a PIG file has times in seconds but no beats")
        if options.fingering is not None:
            raise PianobotError("a PIG file carries its own fingering: drop --fingering")
        piece = pig.read_pig(path)
    else:
        piece = midi_io.read_midi(path, track=options.track)
        sidecar = options.fingering or pig.sidecar_for(path)
        if options.fingering is not None or sidecar.exists():
            embedded = any(n.finger is not None for n in piece.notes)
            piece = pig.apply_fingering(piece, sidecar)
            if embedded:
                warnings.warn(PianobotWarning(f"fingering from {sidecar.name} replaces the fingering inside {path.name}"))
        if options.tempo is not None:
            # re-read with the new tempo, then carry the fingering over note by note
            fingers = [n.finger for n in piece.notes]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", PianobotWarning)  # already reported by the first read
                retimed = midi_io.read_midi(path, track=options.track, bpm=options.tempo)
            piece = retimed.with_fingers(fingers)
    if not piece.notes:
        raise PianobotError(f"{path} has no notes: give a MIDI file with at least one note")
    return piece.transpose(options.transpose)


def load_playable(path: str | Path, options: LoadOptions, keyboard: KeyboardSpec, hand: HandSpec) -> Piece:
    """:func:`load_piece`, then check that ``hand`` can play it on ``keyboard``."""
    piece = load_piece(path, options)
    check_playable(piece, keyboard, hand)
    return piece
