"""A MusicXML file's XML, read before music21 reads the score (:mod:`pianobot.music.musicxml`).

Here: the bytes read with a bound (a compressed .mxl unpacked with one too), the XML parsed and
checked to be a partwise score, each note's fingering marks made unambiguous for music21 (a
chord's unfingered notes given a placeholder "-", alternate marks removed), and the sustain
pedal's marks found at their own places (part, measure, quarter notes into it), which music21
does not keep. Every problem is one line (:class:`~pianobot.errors.PianobotError`).
"""

from __future__ import annotations

import io
import posixpath
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from pianobot.errors import PianobotError, quote
from pianobot.files import misnamed, read_input

MAX_FILE_BYTES = 50_000_000
"""The largest score read, as a file and unpacked from an .mxl."""
MAX_NOTES = 100_000
"""The most notes a score may hold (a long sonata holds some 20,000): more is refused before music21 reads it."""
KIND = "MusicXML score (.musicxml, .xml or .mxl)"


@dataclass(frozen=True)
class PedalMark:
    """One sustain pedal change written in a score: where, and whether the pedal goes down."""

    part: str
    """The part's id."""
    measure: int
    """The measure's place among the part's measures (from 0)."""
    beats: Fraction
    """Quarter notes from the measure's start."""
    down: bool


@dataclass
class Score:
    """A score's XML as read (:func:`read_tree`)."""

    root: ET.Element
    pedal: list[PedalMark] = field(default_factory=list)
    repeats: bool = False
    """Whether it has repeat signs, endings or jumps (:data:`JUMPS`)."""
    jumps: bool = False
    """Whether it has jumps (:data:`JUMPS`: not taken, so its repeats are not written out either)."""
    cues: int = 0
    """Cue notes left out (:func:`_silence_cues`)."""
    second_marks: int = 0
    """Notes with a second fingering mark (not an alternate), read by their first (:func:`_fix_fingering`)."""


def read_tree(path: Path) -> Score:
    """The XML of the score at ``path``: see the module's text."""
    root = _parse(_xml_bytes(path), path)
    if root.tag == "score-timewise":
        raise PianobotError(
            f"{path} is a timewise MusicXML score, which pianobot does not read: re-export it (partwise)"
        )
    if root.tag != "score-partwise":
        raise PianobotError(f"{path} is XML but no MusicXML score (its root is <{quote(root.tag, 30)}>): give a {KIND}")
    notes = sum(1 for _ in root.iter("note"))
    if notes == 0:
        raise PianobotError(f"{path} holds no notes: give a score with notes for the piano")
    if notes > MAX_NOTES:
        raise PianobotError(f"{path} holds {notes:,} notes, more than {MAX_NOTES:,}: that is not a piano piece; cut it")
    cues = second = 0
    for part in root.iter("part"):
        for measure in part.iter("measure"):
            cues += _silence_cues(measure)
            second += _fix_fingering(measure)
    jumps = any(sound.get(jump) for sound in root.iter("sound") for jump in JUMPS)
    repeats = jumps or any(True for _ in root.iter("repeat")) or any(True for _ in root.iter("ending"))
    return Score(root, _pedal(root), repeats, jumps, cues, second)


def _xml_bytes(path: Path) -> bytes:
    """The score's XML bytes: the file's, or the score inside a compressed .mxl (a zip file)."""
    data = read_input(path, limit=MAX_FILE_BYTES, kind=KIND)
    if path.suffix.lower() != ".mxl" and not data.startswith(b"PK\x03\x04"):
        return data
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            inner = _root_file(archive, path)
            info = archive.getinfo(inner)
            if info.file_size > MAX_FILE_BYTES:
                raise PianobotError(
                    f"{path} unpacks to more than {MAX_FILE_BYTES / 1e6:g} MB: that is not a piano piece"
                )
            with archive.open(info) as f:
                xml = f.read(MAX_FILE_BYTES + 1)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, RuntimeError, EOFError, OSError) as e:
        what = "not a compressed MusicXML file (no zip archive)" if not data.startswith(b"PK") else "a damaged .mxl"
        reason = quote(str(e) or type(e).__name__, 40)
        raise PianobotError(misnamed(path, data) or f"{path} is {what} ({reason}): give a {KIND}") from None
    if len(xml) > MAX_FILE_BYTES:
        raise PianobotError(f"{path} unpacks to more than {MAX_FILE_BYTES / 1e6:g} MB: that is not a piano piece")
    return xml


def _root_file(archive: zipfile.ZipFile, path: Path) -> str:
    """The score's name inside an .mxl: the one META-INF/container.xml names, else its only .xml/.musicxml file."""
    names = archive.namelist()
    if "META-INF/container.xml" in names:
        container = _parse(archive.read("META-INF/container.xml")[:1_000_000], path)
        for rootfile in container.iter():
            named = posixpath.normpath(rootfile.get("full-path") or ".")  # ("./score.xml" is "score.xml")
            if rootfile.tag.endswith("rootfile") and named in names:
                return named
    scores = [n for n in names if not n.startswith("META-INF/") and n.lower().endswith((".xml", ".musicxml"))]
    if len(scores) != 1:
        raise PianobotError(f"{path} is a zip file without one MusicXML score in it: give a {KIND}")
    return scores[0]


def _parse(data: bytes, path: Path) -> ET.Element:
    """The XML's root element, or one line where it is not well-formed XML."""
    try:
        return ET.fromstring(data)
    except ET.ParseError as e:
        said = misnamed(path, data) if path.suffix.lower() != ".mxl" else ""  # (not the score packed inside)
        raise PianobotError(said or f"{path} is not well-formed XML ({quote(str(e), 50)}): give a {KIND}") from None


JUMPS = ("dacapo", "dalsegno", "tocoda")
"""The ``<sound>`` attributes of a jump (da capo, dal segno, to coda), which is not taken."""


def _silence_cues(measure: ET.Element) -> int:
    """Cue notes (``<cue/>``: another part's notes printed small, not played) left out of
    ``measure``, each in time as a ``<forward>`` of its length (music21 would read them as notes);
    how many."""
    count = 0
    for note in list(measure):
        if note.tag != "note" or note.find("cue") is None:
            continue
        count += 1
        forward = None
        if note.find("chord") is None and note.find("grace") is None and note.find("duration") is not None:
            forward = ET.Element("forward")
            for tag in ("duration", "voice", "staff"):
                if note.find(tag) is not None:
                    forward.append(note.find(tag))
        position = list(measure).index(note)
        measure.remove(note)
        if forward is not None:
            measure.insert(position, forward)
    return count


def _fix_fingering(measure: ET.Element) -> int:
    """Each note's alternate and second fingering marks removed, and a chord with marks given a
    placeholder "-" on each unfingered note, so that music21 keeps each mark with its note; how many
    notes had a second mark (not an alternate: a substitution's, whose first finger strikes)."""
    chords: list[list[ET.Element]] = []
    second = 0
    for note in measure.findall("note"):
        for technical in note.findall("notations/technical"):
            marks = technical.findall("fingering")
            others = [m for m in marks if m.get("alternate") != "yes"][1:]
            second += bool(others)
            for mark in [m for m in marks if m.get("alternate") == "yes"] + others:
                technical.remove(mark)
        if note.find("chord") is not None and chords:
            chords[-1].append(note)
        else:
            chords.append([note])
    for chord in chords:
        marked = [note.find("notations/technical/fingering") is not None for note in chord]
        if len(chord) > 1 and any(marked):
            for note, has in zip(chord, marked):
                if not has:
                    notations = note.find("notations")
                    if notations is None:
                        notations = ET.SubElement(note, "notations")
                    technical = notations.find("technical")
                    if technical is None:
                        technical = ET.SubElement(notations, "technical")
                    ET.SubElement(technical, "fingering").text = "-"
    return second


def _pedal(root: ET.Element) -> list[PedalMark]:
    """The sustain pedal's changes in every part (``<pedal>``, else ``<sound damper-pedal>``)."""
    marks = []
    for part in root.findall("part"):
        divisions = Fraction(1)
        for index, measure in enumerate(part.findall("measure")):
            at = Fraction(0)
            for child in measure:
                if child.tag == "attributes" and _number(child.findtext("divisions")) > 0:
                    divisions = _number(child.findtext("divisions"))
                elif child.tag == "note" and child.find("chord") is None and child.find("grace") is None:
                    at += _number(child.findtext("duration")) / divisions
                elif child.tag in ("backup", "forward"):
                    step = _number(child.findtext("duration")) / divisions
                    at += step if child.tag == "forward" else -step
                elif child.tag == "direction":
                    when = at + _number(child.findtext("offset")) / divisions
                    for down in _pedal_changes(child):
                        marks.append(PedalMark(part.get("id", ""), index, max(when, Fraction(0)), down))
    return marks


def _pedal_changes(direction: ET.Element) -> list[bool]:
    """What a direction does to the sustain pedal: [True] down, [False] up, [False, True] a change."""
    changes = []
    for pedal in direction.findall("direction-type/pedal"):
        kind = pedal.get("type")
        changes += {"start": [True], "stop": [False], "change": [False, True]}.get(kind, [])
    if not direction.findall("direction-type/pedal"):
        damper = direction.find("sound")
        if damper is not None and damper.get("damper-pedal") in ("yes", "no"):
            changes.append(damper.get("damper-pedal") == "yes")
    return changes


def _number(text: str | None) -> Fraction:
    """A number written in the XML (0 where it is missing or no number)."""
    try:
        return Fraction(str(text).strip()) if text is not None else Fraction(0)
    except (ValueError, ZeroDivisionError):
        return Fraction(0)
