"""One way to read a file: from the file on disk to what the players get.

Every command that reads a piece (``play``, ``score``, ``inspect``, ``finger``, ``train``) and
:func:`pianobot.play`'s callers read it here, in steps, each a function:

1. :func:`open_song`: the file read and parsed, once (a PIG .txt file as text where needed);
2. :func:`choose_model`: where no hand model is named, the pianist's hands for a file they play
   with both hands, fingered with fingers the Allegro-like hand lacks, or that hand's one hand
   refuses and the pianist's plays, else that hand;
   :func:`choose_fingers`: the model's finger set both hands play with where none is named
   (:func:`~pianobot.pianist.parts.keeps_more`: the Allegro-like hand's thumbs where they keep notes three fingers leave out);
3. :func:`read_both_hands`: whether the file plays both hands (:func:`two_hands`), and then every
   note with its hand (:class:`HandsReading`);
4. otherwise one hand's part: :func:`choose_keys` (the keys it needs where none are named) and
   :func:`read_part` (with a hand named, reduced to what the hand can play,
   :func:`~pianobot.pianist.reduce.load_for_hand`);
5. :func:`finger_part`: one hand's part checked against the keyboard and fingered by the planner
   where it has no fingering.

:func:`read_piece` takes them in order into a :class:`ReadPiece` (tracks, one hand or two, each
hand's part, what was reduced and why, fingering, fingers, keyboard, the sustain pedal). Each step
says what it did in a :class:`~pianobot.errors.PianobotWarning`, or refuses a file in a one-line
:class:`~pianobot.errors.PianobotError`; the caller words what undoes a choice (:class:`Wording`).
Each hand's part as its player is given it is :mod:`pianobot.pianist.parts`'s.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

from pianobot.errors import PianobotError, PianobotWarning
from pianobot.music import midi_io
from pianobot.music.instrument import HandSpec, KeyboardSpec, check_playable, keys_for
from pianobot.music.load import LoadOptions, end_legato, load_hands, load_part, load_pedal, load_piece
from pianobot.music.midi_io import MidiSource, TrackInfo, source_path
from pianobot.music.pedal import Pedal
from pianobot.music.piece import HANDS, Piece, pitch_name
from pianobot.music.pig import sidecar_for
from pianobot.pianist.assign import load_two_hands
from pianobot.pianist.fingering import ensure_fingering
from pianobot.pianist.fingering_plan import FingeringPlan
from pianobot.pianist.parts import keeps_more, one_hand_refusal, one_hands_fingering
from pianobot.pianist.reduce import load_for_hand
from pianobot.sim.hand import default_fingers, hand_model

Source = Path | MidiSource
"""A file to read: a PIG .txt file's path, or a .mid file read once (:func:`open_song`)."""


@dataclass(frozen=True)
class Wording:
    """How the caller says what undoes a choice the reading made (options on the command line, else settings)."""

    three: str = "hand=HandSpec() plays with three"
    """After the line that gives both hands their thumbs."""
    keys: str = "a keyboard named for it plays on other keys"
    """After the line that moves a one-hand piece onto its own octaves."""
    refinger: str = "load.refinger"
    """Why a piece with fingering was fingered again."""
    written: str = "write the fingered piece to keep it"
    """After the line that says a fingering was planned."""


@dataclass(frozen=True)
class ReadPiece:
    """A file as read for its players (:func:`read_piece`)."""

    path: Path
    source: Source = field(repr=False)
    """The file as read (:func:`open_song`): any further reading derives from it."""
    tracks: tuple[TrackInfo, ...]
    """The MIDI file's tracks (none for a PIG file)."""
    keyboard: KeyboardSpec
    """The keys: those named, else the default (both hands: each player's own), else a one-hand
    piece's own octaves where its notes lie off the default keys."""
    fingers: HandSpec
    """The fingers each hand plays with."""
    thumbs: tuple[int, int] | None = None
    """Where the thumbs were chosen: (notes both hands are given with three fingers, with thumbs)."""
    hands: HandsReading | None = None
    """Both hands: every note with its hand, and what the file named (else one hand's part)."""
    part: Piece | None = None
    """One hand's part as read (with a hand named, reduced to what it can play), before fingering."""
    piece: Piece | None = None
    """What is played: both hands' notes, each with its hand; or one hand's part, fingered
    (None where the reading stopped before fingering)."""
    fingering: FingeringPlan | None = None
    """One hand's fingering as the planner made it (None: the file's own, or not fingered here)."""
    reduced: tuple[str, ...] = ()
    """What was reduced away or changed, and why: one line per kind, as said."""
    pedal: Pedal = Pedal()
    """The file's sustain pedal, timed as its notes (:func:`~pianobot.music.load.load_pedal`)."""

    @property
    def both(self) -> bool:
        """Whether both hands play."""
        return self.hands is not None

    @property
    def name(self) -> str:
        """The file's name."""
        return self.path.name


def open_song(path: str | Path | MidiSource) -> Source:
    """The file at ``path`` read once: a .mid file (or a MusicXML score) parsed, refused in one line where
    it is none; a PIG .txt file's path (its text read by each step that needs it)."""
    if isinstance(path, MidiSource) or Path(path).suffix.lower() == ".txt":
        return path if isinstance(path, MidiSource) else Path(path)
    return midi_io.open_midi(path)


def tracks_of(source: Source) -> tuple[TrackInfo, ...]:
    """The tracks of a MIDI file read (none for a PIG file)."""
    return tuple(midi_io.describe_tracks(source)) if isinstance(source, MidiSource) else ()


def choose_fingers(
    source: Source, options: LoadOptions, quiet: bool = False, wording: Wording = Wording(), model: str = HandSpec.model
) -> tuple[HandSpec, tuple[int, int] | None]:
    """Both hands' fingers where none are named (:func:`fingers_for_file`), said where they change (not ``quiet``)."""
    hand, counts = fingers_for_file(source, options, model)
    if counts is not None and not quiet:
        said = THUMBS_CHOSEN.format(more=counts[1], given=counts[0])
        warnings.warn(PianobotWarning(f"{source_path(source).name}: {said} ({wording.three})"))
    return hand, counts


PIANIST = "pianist"
"""The hand model that plays a two-hand file where none is named (:func:`choose_model`)."""


def choose_model(
    source: Source, options: LoadOptions, keyboard: KeyboardSpec | None = None
) -> tuple[str, HandsReading | None]:
    """The hand model a file is played with where none is named, and its both hands' reading: the
    Allegro-like hand (``HandSpec.model``) where its one hand plays the file, as its melody policy
    plays one hand's melodies better; else the pianist's hands (:data:`PIANIST`), as the validation
    sets favour them for two-hand music (docs/benchmarks.md, "The pianist's hand"): both where they
    play it with both hands (:func:`two_hands`: tracks named for hands, or notes one of their hands
    cannot play; their reading then), else one (a chordal part the Allegro-like hand would give to
    both hands; a fingering with a finger it lacks, 1 or 5, played as written; a part not fingered
    throughout that its one hand refuses, :func:`_only_pianist`). Where the pianist's
    reading refuses the file, the Allegro-like hand's reads it, and says why where it refuses it too."""
    keys = keyboard or KeyboardSpec()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            hands = two_hands(source, options, default_fingers(PIANIST), keys)
            written = {n.finger for n in load_piece(source, options).notes} - {None, *HandSpec().fingers}
        except PianobotError:
            return HandSpec.model, None
    if hands is not None or written:
        _warn_again(caught if hands is not None else [])  # (a one-hand reading says its own)
        return PIANIST, hands
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the chosen hand's reading says what it finds)
        try:
            pianist = two_hands(source, options, HandSpec(), keys) is not None or _only_pianist(source, options, keys)
        except PianobotError:
            pianist = True  # (refused for it, and the pianist's one hand plays it)
    return (PIANIST if pianist else HandSpec.model), None


def _only_pianist(source: Source, options: LoadOptions, keys: KeyboardSpec) -> bool:
    """Whether the pianist's one hand plays a one-hand file, unfingered or fingered in part (which the
    Allegro-like hand fingers anew), that the Allegro-like hand's one hand refuses (its notes held
    into the next ones, say, past its three fingers)."""
    piece = end_legato(load_piece(source, options))
    if options.hand is not None or (piece.has_fingering and not options.refinger):
        return False
    notes = piece.without_fingering()
    if not one_hand_refusal(notes, HandSpec(), keys):
        return False
    return not one_hand_refusal(notes, default_fingers(PIANIST), keys)


def read_both_hands(
    source: Source, options: LoadOptions, fingers: HandSpec, keyboard: KeyboardSpec = KeyboardSpec()
) -> HandsReading | None:
    """Both hands of the file where it plays both (:func:`two_hands`), else None."""
    return two_hands(source, options, fingers, keyboard)


def choose_keys(
    source: Source, options: LoadOptions, fingers: HandSpec, quiet: bool = False, wording: Wording = Wording()
) -> KeyboardSpec:
    """The keys a one-hand piece needs where none are named: the default keys where its notes lie
    on them, else its own octaves (:func:`~pianobot.music.instrument.keys_for`), said in one line
    (not ``quiet``)."""
    default = KeyboardSpec()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)  # (said when the part is read)
        piece = load_part(source, options, fingers)
    keys = keys_for(piece, default)
    if keys != default and not quiet:
        low, high = min(n.pitch for n in piece.notes), max(n.pitch for n in piece.notes)
        warnings.warn(
            PianobotWarning(
                f"{source_path(source).name}: its notes ({pitch_name(low)}-{pitch_name(high)}) lie off the default keys "
                f"{default.describe()}: played on {keys.describe()}, the piece's own octaves ({wording.keys})"
            )
        )
    return keys


def read_part(
    source: Source, options: LoadOptions, keyboard: KeyboardSpec, fingers: HandSpec, fit: bool = True
) -> tuple[Piece, tuple[str, ...]]:
    """One hand's part (:func:`~pianobot.pianist.reduce.load_for_hand`: with ``options.hand``,
    reduced to what the hand can play), and the lines its reading said."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PianobotWarning)
        part = load_for_hand(source, options, keyboard, fingers, fit=fit)
    _warn_again(caught)
    return part, tuple(str(w.message) for w in caught if issubclass(w.category, PianobotWarning))


def finger_part(
    part: Piece,
    options: LoadOptions,
    keyboard: KeyboardSpec,
    fingers: HandSpec,
    name: str,
    wording: Wording = Wording(),
) -> tuple[Piece, FingeringPlan | None]:
    """One hand's part checked against ``keyboard`` and ``fingers`` (a refusal's hint counts the whole transposition
    in), then fingered by the planner where it has no fingering, or fingering the hand cannot play, or with
    ``options.refinger`` (:func:`ensure_fingering`), said in one line with the plan's problems (``name``: the file's)."""
    check_playable(part.without_fingering(), keyboard, fingers, options.transpose)
    piece, plan = ensure_fingering(part, keyboard, fingers, options.refinger)
    if plan is not None:
        why = "this hand cannot play all of its fingering" if part.has_fingering else "it has notes without fingering"
        why = wording.refinger if options.refinger else why
        marks = [(n.finger, p.finger) for n, p in zip(part.notes, piece.notes) if n.finger is not None]
        kept = bool(marks) and not options.refinger and hand_model(fingers.model).written_fingering
        why += f"; kept {sum(a == b for a, b in marks)} of its {len(marks)} fingering marks" if kept else ""
        warnings.warn(
            PianobotWarning(
                f"{name}: fingering planned for fingers {', '.join(map(str, fingers.fingers))} ({why}): "
                f"wrist travel {plan.travel * 100:.1f} cm in {plan.moves} moves{'' if kept else '; ' + wording.written}"
            )
        )
        for problem in plan.said():
            warnings.warn(PianobotWarning(problem))
    check_playable(piece, keyboard, fingers)
    return piece, plan


def read_piece(
    path: str | Path | MidiSource,
    options: LoadOptions = LoadOptions(),
    keyboard: KeyboardSpec | None = None,
    fingers: HandSpec | None = None,
    *,
    finger: bool = True,
    both: bool = True,
    fit: bool = True,
    quiet: bool = False,
    wording: Wording = Wording(),
    model: str | None = HandSpec.model,
) -> ReadPiece:
    """The file at ``path`` read once for its players, step by step (the module's notes).
    ``keyboard``, ``fingers``: None where none are named (then chosen, ``fingers`` among ``model``'s
    finger sets, each choice said unless ``quiet``); ``model`` None: the hand model is chosen too
    (:func:`choose_model`; without ``both``, the Allegro-like hand). ``finger``: one hand's part also fingered
    (:func:`finger_part`; else :attr:`ReadPiece.piece` is None for one hand). ``both``: ask whether
    it plays both hands. ``fit``: as :func:`~pianobot.pianist.reduce.load_for_hand`'s."""
    source = open_song(path)
    name = source_path(source)
    tracks = tracks_of(source)
    pedal = load_pedal(source, options)
    thumbs = None
    if fingers is None and model is None and both:
        model, hands = choose_model(source, options, keyboard)
        if hands is not None:
            keys = keyboard or KeyboardSpec()
            return ReadPiece(
                name, source, tracks, keys, default_fingers(model), None, hands, piece=hands.piece, pedal=pedal
            )
    if fingers is None:
        fingers, thumbs = choose_fingers(source, options, quiet, wording, model or HandSpec.model)
    hands = read_both_hands(source, options, fingers, keyboard or KeyboardSpec()) if both else None
    if hands is not None:
        keys = keyboard or KeyboardSpec()
        return ReadPiece(name, source, tracks, keys, fingers, thumbs, hands, piece=hands.piece, pedal=pedal)
    keys = keyboard or choose_keys(source, options, fingers, quiet, wording)
    part, reduced = read_part(source, options, keys, fingers, fit)
    read = ReadPiece(name, source, tracks, keys, fingers, thumbs, None, part, reduced=reduced, pedal=pedal)
    return finger_read(read, options, wording) if finger else read


def finger_read(read: ReadPiece, options: LoadOptions, wording: Wording = Wording()) -> ReadPiece:
    """A one-hand reading made with ``finger=False`` (:func:`read_piece`), fingered now
    (:func:`finger_part`); a reading of both hands, or one already fingered, as it is."""
    if read.part is None or read.piece is not None:
        return read
    piece, plan = finger_part(read.part, options, read.keyboard, read.fingers, read.name, wording)
    return replace(read, piece=piece, fingering=plan)


@dataclass(frozen=True)
class HandsReading:
    """A two-hand file read for both hands: every note with its hand, and how many of each hand's the file
    named (tracks' names, a PIG file's channels) and how many the file named for the other hand but that
    hand lent (:mod:`~pianobot.pianist.lend`: out of its reach); the rest the planner assigned
    (:func:`~pianobot.pianist.assign.assign_hands`)."""

    piece: Piece
    named: dict[str, int]
    source: str = "its track"
    """What named a note's hand in the file: 'its track', 'the PIG channel'."""
    lent: dict[str, int] = field(default_factory=dict)
    """Per hand: the notes it was lent, which the file named for the other hand (a note the planner
    assigned and then lent counts as the planner's)."""

    def to_dict(self, hand: str) -> dict:
        """``hand``'s part: how many notes, its range, how many the file named, the other hand lent
        and the planner assigned."""
        part = self.piece.part(hand)
        named, lent = self.named.get(hand, 0), self.lent.get(hand, 0)
        return {
            "notes": len(part),
            "range": [pitch_name(min(n.pitch for n in part.notes)), pitch_name(max(n.pitch for n in part.notes))],
            "named_by_file": named,
            "lent_by_other_hand": lent,
            "assigned_by_planner": len(part) - named - lent,
        }

    def describe(self, hand: str) -> str:
        """One line on ``hand``'s part: 'right hand: 64 notes, C4-D5, named by its track'."""
        part, other = self.to_dict(hand), "left" if hand == "right" else "right"
        shares = [
            (part["named_by_file"], f"named by {self.source}"),
            (part["lent_by_other_hand"], f"lent by the {other} hand (out of its reach)"),
            (part["assigned_by_planner"], "assigned by the fingering planner"),
        ]
        shares = [(count, what) for count, what in shares if count]
        who = shares[0][1] if len(shares) == 1 else ", ".join(f"{count} {what}" for count, what in shares)
        notes = f"{part['notes']} note{'s' * (part['notes'] != 1)}"
        return f"{hand} hand: {notes}, {'-'.join(part['range'])}, {who}"


def read_hands(
    path: str | Path | MidiSource, options: LoadOptions = LoadOptions(), spec: HandSpec = HandSpec()
) -> HandsReading:
    """Both hands of the file at ``path`` (:func:`~pianobot.pianist.assign.load_two_hands`), with what the file named."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)  # said by load_two_hands
        given = load_hands(source := open_song(path), options)
    piece = load_two_hands(source, options, spec)
    dropped = len(given.hands) == 1 < len(piece.hands) and all(n.hand for n in given.notes)  # (one hand named: dropped)
    written = {} if dropped else {(n.pitch, n.onset): n.hand for n in given.notes if n.hand is not None}
    named, lent = {hand: 0 for hand in HANDS}, {hand: 0 for hand in HANDS}
    for note in piece.notes:  # (notes the reading thinned away count for neither)
        hand = written.get((note.pitch, note.onset))
        if hand is not None:
            (named if hand == note.hand else lent)[note.hand] += 1
    said = "the PIG channel" if source_path(path).suffix.lower() == ".txt" else "its track"
    if said == "its track" and (options.fingering or sidecar_for(source_path(path)).exists()):
        said = "its track" if names_hands(source, options.track) else "its fingering file's channel"
    return HandsReading(piece, named, said, lent)


def names_hands(path: str | Path | MidiSource, track: str | None = None) -> bool:
    """Whether the file says which hand plays its notes: a track named for a hand (of those
    ``track`` names, :func:`~pianobot.music.midi_io.read_midi`'s; None: all), or a PIG file."""
    if source_path(path).suffix.lower() == ".txt":
        return True
    source = midi_io.open_midi(path)
    read = None if track is None else set(midi_io.selected_tracks(source, track))
    return any(
        t.notes and midi_io.track_hand(t.name) and (read is None or t.index in read)
        for t in midi_io.describe_tracks(source)
    )


def two_hands(
    path: str | Path | MidiSource,
    options: LoadOptions,
    spec: HandSpec = HandSpec(),
    keyboard: KeyboardSpec = KeyboardSpec(),
) -> HandsReading | None:
    """Both hands of the file at ``path`` where ``pianobot play`` plays both, else None (one hand).

    Both hands, without ``options.hand`` (with ``options.track``, only the tracks it names are
    read, one as a whole file's notes): a file with tracks named for hands (the others' notes
    given hands by the fingering planner) or a PIG file, with notes for both; or a file one hand
    cannot play, whose notes the planner gives to both: wider than one hand's ``keyboard``, or
    refused by one hand's reading of the notes alone (notes off the keys, more at once than the
    fingers, a chord or move out of reach; a fingering that could be one hand's is then not taken,
    :func:`one_hands_fingering`, unless the file gives the hands too). Where the planner gives every
    note to one hand, or both hands' reading refuses it too, one hand's reading says why. Warnings are said only where both hands
    play (or where the file is refused: notes beyond the piano)."""
    if options.hand is not None:
        return None
    path, source = source_path(path), open_song(path)
    if options.track is not None:
        if path.suffix.lower() == ".txt":
            return None  # (one hand's reading refuses --track on a PIG file)
    if path.suffix.lower() == ".txt" and (options.tempo or options.fingering or options.quantize):
        return None  # (one hand's reading refuses them in its own words)
    one_hand_refuses, fingered = "", False
    if not names_hands(source, options.track):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # said when the piece is read
            piece = end_legato(load_piece(source, options))  # (as one hand's reading reads it)
        pitches = [n.pitch for n in piece.notes]
        if max(pitches) - min(pitches) < keyboard.count:
            fingered = one_hands_fingering(piece)  # (one hand's fingering, where that hand plays it)
            one_hand_refuses = one_hand_refusal(piece.without_fingering(), spec, keyboard, options.refinger)
            if not one_hand_refuses:
                return None
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            hands = read_hands(source, options, spec)
    except PianobotError:
        if one_hand_refuses:
            return None  # one hand's reading says why, in its own words
        _warn_again(caught)
        raise
    if len(hands.piece.hands) < 2:
        return None
    _warn_again(caught)
    if one_hand_refuses:
        anew = " and fingered anew (its fingering is one hand's)" if fingered and not any(hands.named.values()) else ""
        warnings.warn(
            PianobotWarning(
                f"{path.name}: one hand cannot play it ({one_hand_refuses}): its notes are given to both hands{anew}"
            )
        )
    anew = fingered and one_hand_refuses and not any(hands.named.values())  # (else the file gave hands too)
    return replace(hands, piece=hands.piece.without_fingering()) if anew else hands


def _warn_again(caught: list) -> None:
    for warning in caught:
        warnings.warn(warning.message)


def fingers_for_file(
    path: str | Path | MidiSource, options: LoadOptions, model: str = HandSpec.model
) -> tuple[HandSpec, tuple[int, int] | None]:
    """Both hands' fingers for the file at ``path`` where none are named, as ``play`` chooses among
    ``model``'s finger sets (:func:`keeps_more` of the file's both hands read with each, :func:`two_hands`),
    else the first set; on the default keys whatever keys are named (``score`` reads as ``play`` did)."""
    sets = [HandSpec(fingers=fingers, model=model) for fingers in hand_model(model).finger_sets]
    readings = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)
        try:
            source = open_song(path)
            for fingers in sets if len(sets) > 1 else ():
                reading = two_hands(source, options, fingers)
                if reading is None:
                    return sets[0], None
                readings.append((fingers, reading.piece))
        except PianobotError:
            return sets[0], None
    if not readings:
        return sets[0], None
    index, counts = keeps_more(readings)
    return sets[index], counts


THUMBS_CHOSEN = "both hands play with their thumbs too: they are given {more} of the notes, three fingers {given}"
"""The line said where :func:`~pianobot.pianist.parts.thumbs_keep_more` gives both hands their thumbs (with how to choose three)."""
