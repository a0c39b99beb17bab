"""PIG v1.0 fingering files (the PIG piano-fingering dataset's format).

One header line (``//Version: PianoFingering_v170101``), then one note per line with 8
tab-separated columns: id, onset (s), offset (s), spelled pitch (``C#4``, ``Bb3``), onset
velocity, offset velocity, channel (0 right hand, 1 left hand), finger (``+1``..``+5`` right,
``-1``..``-5`` left; a substitution ``3_1`` counts as its first finger, the one that strikes).

A PIG file can be read as a piece on its own, or applied as a fingering sidecar to the notes of
a .mid file (:func:`apply_fingering`).
"""

from __future__ import annotations

import bisect
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

from pianobot.errors import PianobotError, quote
from pianobot.files import atomic_write, content_kind, read_input, renamed
from pianobot.music.piece import HANDS, Note, Piece, parse_pitch, pitch_name, resolve_overlaps

HEADER = "//Version: PianoFingering_v170101"
SIDECAR_SUFFIX = "_fingering.txt"
"""A sidecar for ``song.mid`` is ``song_fingering.txt`` in the same folder (PIG's own naming)."""
MATCH_TOLERANCE = 0.025
"""A sidecar note matches a MIDI note of the same pitch whose onset is this close (seconds)."""
MAX_FILE_BYTES = 50_000_000
"""A PIG file larger than this is refused unread (bytes), as a MIDI file is."""


def _parse_finger(text: str, where: str) -> tuple[int, int]:
    """(finger 1-5, hand sign +1/-1) from '+3', '-2', '3', '3_1'."""
    token = text.strip().split("_")[0]
    try:
        value = int(token)
    except ValueError:
        raise PianobotError(f"{where}: finger '{quote(text)}' is not a number like +3, -2 or 3_1") from None
    if not 1 <= abs(value) <= 5:
        raise PianobotError(f"{where}: finger '{quote(text)}' must be 1-5 (right hand) or -1..-5 (left hand)")
    return abs(value), (-1 if token.startswith("-") else 1)


def read_pig_rows(path: str | Path) -> list[tuple[Note, int]]:
    """Every note of a PIG file with its channel (0 right hand, 1 left hand)."""
    path = Path(path)
    data = read_input(
        path,
        limit=MAX_FILE_BYTES,
        kind="PIG fingering file",
        missing=f"fingering file {path} does not exist: check the path given to load.fingering",
    )
    if found := content_kind(data):  # (a song named .txt, or a fingering file that is none)
        raise PianobotError(
            f"{path} holds {found[0]}, not PIG fingering text: to play it, name it {renamed(path, found[1])}; "
            "as a fingering file, give the PIG .txt file"
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise PianobotError(f"cannot read fingering file {path} ({e}): it must be a UTF-8 PIG text file") from None
    rows: list[tuple[Note, int]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.startswith("//"):
            continue
        where = f"{path.name} line {number}"
        cols = line.split("\t") if "\t" in line else line.split()
        if len(cols) < 8:
            raise PianobotError(
                f"{where} has {len(cols)} columns, a PIG file needs 8 "
                "(id, onset, offset, pitch, onset velocity, offset velocity, channel, finger)"
            )
        try:
            onset, offset = float(cols[1]), float(cols[2])
            velocity = int(cols[4])
            channel = int(cols[6])
        except ValueError:
            raise PianobotError(f"{where}: onset, offset, velocity and channel must be numbers") from None
        if channel not in (0, 1):
            raise PianobotError(f"{where}: channel {channel} must be 0 (right hand) or 1 (left hand)")
        finger, _ = _parse_finger(cols[7], where)
        try:
            pitch = parse_pitch(cols[3])
            note = Note(onset=onset, pitch=pitch, offset=offset, velocity=max(1, min(127, velocity)), finger=finger)
        except PianobotError as e:
            raise PianobotError(f"{where}: {e}") from None
        rows.append((note, channel))
    if not rows:
        raise PianobotError(f"fingering file {path} holds no notes: is it a PIG v1.0 file?")
    return rows


CHANNELS = {"right": 0, "left": 1}
"""PIG's channel for each hand."""


def read_pig(path: str | Path, *, hand: str | None = "right") -> Piece:
    """A PIG file's notes for one hand as a piece (fingers stored as 1-5, no hand: a one-hand part),
    or with ``hand=None`` both hands' notes, each with its hand (channel 0 right, 1 left)."""
    rows = read_pig_rows(path)
    if hand is None:  # (a key sounds once at a time: an earlier note ends where its key starts again)
        return Piece(tuple(resolve_overlaps([replace(note, hand=HANDS[channel]) for note, channel in rows])))
    channel = CHANNELS[hand]
    notes = resolve_overlaps([note for note, ch in rows if ch == channel])
    if not notes:
        other = "left" if hand == "right" else "right"
        raise PianobotError(
            f"{path} has no {hand}-hand notes (channel {channel}): play the other hand with load.hand {other}"
        )
    return Piece(tuple(notes))


def pig_text(piece: Piece) -> str:
    """The piece as PIG text. Every note needs a finger. A note of the left hand is written on
    channel 1 with its finger negative; every other note (the right hand's, or one without a
    hand) on channel 0 with its finger positive."""
    lines = [HEADER]
    for i, note in enumerate(piece.notes):
        if note.finger is None:
            raise PianobotError(f"{note.describe()} has no finger: a PIG file needs a finger for every note")
        left = note.hand == "left"
        lines.append(
            "\t".join(
                [
                    str(i),
                    f"{note.onset:.6f}",
                    f"{note.offset:.6f}",
                    pitch_name(note.pitch),
                    str(note.velocity),
                    "80",
                    str(CHANNELS["left" if left else "right"]),
                    str(-note.finger if left else note.finger),
                ]
            )
        )
    return "\n".join(lines) + "\n"


def write_pig(piece: Piece, path: str | Path) -> Path:
    return atomic_write(path, pig_text(piece))


def sidecar_for(midi_path: str | Path) -> Path:
    """Where the fingering sidecar of a .mid file would be."""
    midi_path = Path(midi_path)
    return midi_path.with_name(midi_path.stem + SIDECAR_SUFFIX)


def _matches(piece: Piece, pig_path: str | Path) -> list[tuple[Note, int]]:
    """For each note of ``piece`` (in order) its PIG note and channel: the note of the same pitch
    starting nearest, within :data:`MATCH_TOLERANCE`, each PIG note used once."""
    by_pitch: dict[int, list[tuple[Note, int]]] = defaultdict(list)  # each pitch's PIG notes in onset order
    for note, channel in sorted(read_pig_rows(pig_path), key=lambda r: (r[0].onset, r[0].pitch)):
        by_pitch[note.pitch].append((note, channel))
    onsets = {pitch: [n.onset for n, _ in rows] for pitch, rows in by_pitch.items()}
    used = {pitch: [False] * len(rows) for pitch, rows in by_pitch.items()}
    found = []
    for note in piece.notes:
        best = None
        candidates = by_pitch.get(note.pitch, [])
        first = bisect.bisect_left(onsets.get(note.pitch, []), note.onset - MATCH_TOLERANCE - 1e-9)
        for i in range(first, len(candidates)):
            gap = abs(candidates[i][0].onset - note.onset)
            if candidates[i][0].onset > note.onset + MATCH_TOLERANCE + 1e-9:
                break
            if not used[note.pitch][i] and gap <= MATCH_TOLERANCE and (best is None or gap < best[0]):
                best = (gap, i)
        if best is None:
            raise PianobotError(
                f"fingering file {Path(pig_path).name} has no note for {note.describe()}: "
                "the sidecar must list the same notes as the .mid file (same pitches and onsets)"
            )
        used[note.pitch][best[1]] = True
        found.append(candidates[best[1]])
    return found


def apply_fingering(piece: Piece, pig_path: str | Path, *, hands: bool = False) -> Piece:
    """Take each note's finger from the PIG note of the same pitch starting at the same time;
    with ``hands``, also its hand from the PIG note's channel (0 right, 1 left).

    Every note of ``piece`` must find its PIG note (within :data:`MATCH_TOLERANCE`); PIG notes
    left over (e.g. the other hand's) are ignored.
    """
    notes = [
        replace(note, finger=match.finger, hand=HANDS[channel] if hands else note.hand)
        for note, (match, channel) in zip(piece.notes, _matches(piece, pig_path))
    ]
    return Piece(tuple(notes), bpm=piece.bpm)
