"""A .mid file read once: its bytes checked and parsed (mido) into a :class:`MidiSource`, which
every reader of :mod:`pianobot.music.midi_io` takes in place of a path (a MusicXML score is read
into one too: :mod:`pianobot.music.musicxml`)."""

from __future__ import annotations

import io
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import mido
from mido.midifiles.meta import KeySignatureError, MetaSpec_key_signature, add_meta_spec

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.files import misnamed, read_input

MAX_FILE_BYTES = 50_000_000
"""The largest .mid file read."""


class _AnyKey(MetaSpec_key_signature):
    """A key signature as mido reads it, a key no signature names (8 sharps, mode 2) read as C major."""

    type = "key_signature"  # (mido names a spec without one by its class)

    def decode(self, message, data):
        try:
            super().decode(message, data)
        except KeySignatureError:
            message.key = "C"


@contextmanager
def _any_key():
    """mido reading every key signature (:class:`_AnyKey`) while inside, as before after."""
    add_meta_spec(_AnyKey)
    try:
        yield
    finally:
        add_meta_spec(MetaSpec_key_signature)


def _track_chunks(data: bytes) -> tuple[int, bool]:
    """How many complete track chunks ('MTrk' and its whole length) follow the header, and
    whether the data ends inside a chunk (a cut file)."""
    pos, count = 8 + int.from_bytes(data[4:8], "big"), 0
    while pos + 8 <= len(data):
        size = int.from_bytes(data[pos + 4 : pos + 8], "big")
        if pos + 8 + size > len(data):
            return count, True
        count += data[pos : pos + 4] == b"MTrk"
        pos += 8 + size
    return count, pos < len(data)


def _load(path: Path) -> mido.MidiFile:
    data = read_input(path, limit=MAX_FILE_BYTES, kind=".mid file")
    if not data.startswith(b"MThd"):
        raise PianobotError(
            misnamed(path, data)
            or f"{path} is not a MIDI file (it does not start with 'MThd'): give a standard .mid file"
        )
    if len(data) < 14:
        raise PianobotError(
            f"{path} is not a readable MIDI file (its header is cut short): it may be truncated or corrupt; re-export it"
        )
    division = int.from_bytes(data[12:14], "big")
    if division & 0x8000:
        raise PianobotError(f"{path} uses SMPTE time division, which pianobot does not read: re-export it with beats")
    if division == 0:
        raise PianobotError(f"{path} says a beat has 0 ticks (its header is corrupt): re-export it")
    declared, (held, cut) = int.from_bytes(data[10:12], "big"), _track_chunks(data)
    if cut and declared > held:
        raise PianobotError(
            f"{path} is not a readable MIDI file (it ends inside track {held}): it may be truncated or corrupt; "
            "re-export it"
        )
    if declared > held:
        raise PianobotError(
            f"{path} is truncated or its header does not match its tracks: the header says {declared} track(s), "
            f"the file holds {held} complete one(s); re-export it"
        )
    if declared < held:
        warnings.warn(
            PianobotWarning(
                f"{path.name}: the header says {declared} track(s) but the file holds {held}; read {declared}"
            )
        )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                midi = mido.MidiFile(file=io.BytesIO(data))
            except KeySignatureError:  # (a key no signature names: pianobot reads no key signature)
                with _any_key():
                    midi = mido.MidiFile(file=io.BytesIO(data))
    except Exception as e:  # mido raises many types on corrupt data
        reason = str(e) or type(e).__name__
        raise PianobotError(
            f"{path} is not a readable MIDI file ({reason}): it may be truncated or corrupt; re-export it"
        ) from None
    if midi.type == 2:
        raise PianobotError(f"{path} is a type 2 MIDI file (independent patterns): re-export it as type 0 or 1")
    return midi


@dataclass(frozen=True, eq=False)
class MidiSource:
    """A .mid file read once (:func:`open_midi`): its path and its parsed contents. Every reader
    here takes one in place of a path, so that a command reads its file once and derives the rest
    from what it read."""

    path: Path
    midi: mido.MidiFile = field(repr=False)

    @property
    def name(self) -> str:
        """The file's name."""
        return self.path.name


def open_midi(path: str | Path | MidiSource) -> MidiSource:
    """The .mid file at ``path``, read and parsed (a bad file refused in one line); a MusicXML
    score (.musicxml, .xml, .mxl) read and rendered as one (:mod:`pianobot.music.musicxml`); a
    :class:`MidiSource` is returned as it is."""
    if isinstance(path, MidiSource):
        return path
    path = Path(path)
    if path.suffix.lower() in (".musicxml", ".xml", ".mxl"):
        from pianobot.music.musicxml import open_musicxml  # (music21 only where a score is read)

        return open_musicxml(path)
    return MidiSource(path, _load(path))


def source_path(source: str | Path | MidiSource) -> Path:
    """The path of a file given by its path or as a :class:`MidiSource`."""
    return source.path if isinstance(source, MidiSource) else Path(source)


def opened(source: str | Path | MidiSource) -> tuple[Path, mido.MidiFile]:
    """(path, parsed file): a :class:`MidiSource`'s own, else the file read now (:func:`open_midi`)."""
    opened = open_midi(source)
    return opened.path, opened.midi
