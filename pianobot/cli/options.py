"""The options several commands share, and the helpers that turn them into library objects."""

from __future__ import annotations

import contextlib
import functools
import inspect
import os
import warnings
from dataclasses import dataclass, replace
from enum import StrEnum
from pathlib import Path
from typing import Optional

import typer

from pianobot.agent.config import ACTORS, DEVICES
from pianobot.agent.store import DEFAULT_STORE
from pianobot.env.rewards import REWARDS
from pianobot.errors import PianobotError, PianobotWarning, SettingError, quote
from pianobot.learn.config import LEARNERS
from pianobot.learn.explore import EXPLORATIONS
from pianobot.music.instrument import PIANO, HandSpec, KeyboardSpec
from pianobot.music.load import HANDS, LoadOptions
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.music.piece import parse_pitch, pitch_name
from pianobot.music.tasks import FAMILIES
from pianobot.perform.controllers import CONTROLLERS
from pianobot.sim.hand import HAND_MODELS, default_fingers, hand_model
from pianobot.sim.world_config import CONTROL_MODES


@contextlib.contextmanager
def option(name: str | None = None, value=None):
    """Phrase a library's ValueError about an option's value (or about options together: no
    name) as the command's error."""
    try:
        yield
    except ValueError as e:
        raise PianobotError(f"{name} {quote(str(value))}: {e}" if name else str(e)) from None


# -- choices -----------------------------------------------------------------------------------
def choices(name: str, values: tuple[str, ...]) -> type[StrEnum]:
    """The allowed values of an option, from the library's tuple of them: typer lists them in
    ``--help`` and refuses any other value with its own usage error (exit 2). A command passes
    ``.value`` on to the library."""
    return StrEnum(name, {value: value for value in values})


Controller = choices("Controller", CONTROLLERS)
Learner = choices("Learner", LEARNERS)
Cluster = choices("Cluster", ("local", "ray"))
Task = choices("Task", FAMILIES)
Control = choices("Control", CONTROL_MODES)
Reward = choices("Reward", REWARDS)
Explore = choices("Explore", EXPLORATIONS)
Actor = choices("Actor", ACTORS)
HandPart = choices("HandPart", HANDS)
Device = choices("Device", DEVICES)
HandModelName = choices("HandModelName", tuple(HAND_MODELS))


def value(choice: StrEnum | None) -> str | None:
    """The plain string of a choice (None stays None), for the library's configurations."""
    return None if choice is None else choice.value


# -- shared options --------------------------------------------------------------------------
PhraseNotes = typer.Option(
    DEFAULT_MAX_NOTES, "--phrase-notes", help="Most notes in one phrase (one policy each).", min=1
)
GeneralPolicy = typer.Option(
    None,
    "--general-policy",
    help="The general policy's folder (default: the newest that fits in --models, else the packaged one).",
)
PlayPhraseNotes = typer.Option(
    None,
    "--phrase-notes",
    help=f"Most notes in a phrase (default: the longest, up to {DEFAULT_MAX_NOTES}, with trained policies).",
    min=1,
    metavar="N",
)
HtmlReport = typer.Option(
    None,
    "--html",
    help="Also write a report for a browser (offline).",
)
AllFigures = typer.Option(False, "--all", help="Print every figure, not the few to read first.")
AllRows = typer.Option(False, "--all", help="List every note and phrase (by default the tables stop after 100 rows).")

# -- reading a piece, once for every command that reads one ---------------------------------------
PIECE = "Reading the piece"
INSTRUMENT = "Keyboard and hand"


def _reading(kind, default, flag: str, text: str, panel: str = PIECE) -> tuple:
    """One reading option: its type, and its typer option in its help panel."""
    return kind, typer.Option(default, flag, help=text, rich_help_panel=panel)


# fmt: off
READING = {  # parameter name: (type, option); the commands' --help shows them in two panels of their own
    "track": _reading(Optional[str], None, "--track", "Only these tracks (indices or names: 2,3)."),
    "tempo": _reading(Optional[float], None, "--tempo", "Re-time the piece at this tempo (bpm)."),
    "transpose": _reading(int, LoadOptions.transpose, "--transpose", "Shift every note by N semitones."),
    "fingering": _reading(Optional[Path], None, "--fingering", "A PIG fingering file (default: <song>_fingering.txt)."),
    "hand_part": _reading(Optional[HandPart], None, "--hand", "Only this hand's part of a two-hand piece."),
    "split": _reading(str, pitch_name(LoadOptions.split), "--split", "Lowest note of the right hand, where no track says."),
    "quantize": _reading(Optional[str], None, "--quantize", "Move notes to a grid, e.g. 1/16 (recordings)."),
    "refinger": _reading(bool, LoadOptions.refinger, "--refinger/--no-refinger", "Plan fingers even where the file has them."),
    "pedal": _reading(bool, LoadOptions.pedal, "--pedal/--no-pedal", "Play and score the file's sustain pedal (CC64)."),
    "lowest_note": _reading(Optional[str], None, "--lowest-note", f"Lowest key, e.g. C4 or 60 (default {pitch_name(KeyboardSpec.lowest)} or the piece's).", INSTRUMENT),
    "keys": _reading(Optional[int], None, "--keys", f"Number of keys (default {KeyboardSpec.count} or the piece's).", INSTRUMENT),
    "hand_model": _reading(Optional[HandModelName], None, "--hand-model", "allegro (the paper's, and --thumb's; one hand's default) or pianist (both hands').", INSTRUMENT),
    "thumb": _reading(Optional[bool], None, "--thumb/--no-thumb", "The Allegro hand's thumb (default: if more notes).", INSTRUMENT),
}
# fmt: on


@dataclass(frozen=True)
class Reading:
    """What the reading options say: how to read the piece, and the keyboard and hand it is read for."""

    options: LoadOptions
    keyboard: KeyboardSpec
    hand: HandSpec
    keyboard_named: bool = False
    """Whether --lowest-note or --keys was given (else the reading (:func:`~pianobot.pianist.reading.choose_keys`) may choose the keys,
    and both hands' parts go on their players' keys)."""
    hand_named: bool = False
    """Whether the fingers are named: --thumb or --no-thumb given, or a hand with one finger set (else the reading
    (:func:`~pianobot.pianist.reading.choose_fingers`) may give both hands their thumbs)."""
    model_named: bool = True
    """Whether the hand model is named: --hand-model given, or --thumb/--no-thumb (the Allegro-like
    hand's); else :attr:`hand` is the Allegro-like hand's, and the reading chooses the model
    (:func:`~pianobot.pianist.reading.choose_model`)."""


def make_reading(**given) -> Reading:
    """The :class:`Reading` of the reading options' values; an option a command does not offer
    keeps its default."""
    values = {name: option.default for name, (_, option) in READING.items()} | given
    named = values["lowest_note"] is not None or values["keys"] is not None
    keyboard = KeyboardSpec(
        lowest=KeyboardSpec.lowest if values["lowest_note"] is None else parse_pitch(values["lowest_note"]),
        count=KeyboardSpec.count if values["keys"] is None else values["keys"],
    )
    if named and not (PIANO.lowest <= keyboard.lowest and keyboard.highest <= PIANO.highest):
        raise SettingError(
            f"the keyboard {keyboard.describe()} goes past the piano's 88 keys {PIANO.describe()}: "
            "choose keyboard.lowest and keyboard.count within them",
            "keyboard.lowest",
            "keyboard.count",
        )
    model_named = values["hand_model"] is not None or values["thumb"] is not None
    hand, hand_named = _fingers(value(values["hand_model"]) or HandSpec.model, values["thumb"])
    return Reading(
        options=LoadOptions(
            track=values["track"],
            tempo=values["tempo"],
            transpose=values["transpose"],
            fingering=values["fingering"],
            hand=value(values["hand_part"]),
            split=parse_pitch(values["split"]),
            quantize=values["quantize"],
            refinger=values["refinger"],
            pedal=values["pedal"],
        ),
        keyboard=keyboard,
        hand=hand,
        keyboard_named=named,
        hand_named=hand_named,
        model_named=model_named,
    )


def _fingers(model_name: str, thumb: bool | None) -> tuple[HandSpec, bool]:
    """The hand --hand-model names, with the fingers --thumb/--no-thumb choose among its finger
    sets (none given: its first), and whether they are named (given, or the hand has one set only)."""
    model = hand_model(model_name)
    if thumb is None:
        return default_fingers(model_name), len(model.finger_sets) == 1
    sets = [s for s in model.finger_sets if (1 in s) == thumb]
    if not sets:
        raise SettingError(
            f"--{'' if thumb else 'no-'}thumb: the {model_name} hand plays with fingers "
            f"{', '.join(map(str, model.finger_sets[0]))}: leave --thumb/--no-thumb out",
            "hand.fingers",
        )
    return HandSpec(fingers=sets[0], model=model_name), True


def reads(*, without: tuple[str, ...] = ()):
    """Give a command the reading options (all of them but ``without``): they are added to its
    signature, after its own parameters, and reach it as one ``reading: Reading`` argument."""
    unknown = set(without) - set(READING)
    assert not unknown, f"no reading options {unknown}"

    def decorate(command):
        own = inspect.signature(command, eval_str=True)
        added = [
            inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=option, annotation=kind)
            for name, (kind, option) in READING.items()
            if name not in without
        ]
        parameters = [p for p in own.parameters.values() if p.name != "reading"] + added

        @functools.wraps(command)
        def wrapper(*args, **kwargs):
            given = {name: kwargs.pop(name) for name in READING if name in kwargs}
            return command(*args, reading=make_reading(**given), **kwargs)

        wrapper.__signature__ = own.replace(parameters=parameters)
        wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
        return wrapper

    return decorate


def check_midi_output(output: Path, song: Path, what: str, score: bool = False) -> None:
    """-o must name a .mid file other than the input (``score``: or a MusicXML score, .musicxml/.xml/.mxl)."""
    suffixes = (".mid", ".midi") + ((".musicxml", ".xml", ".mxl") if score else ())
    if output.suffix.lower() not in suffixes:
        also = " or a MusicXML score, name it *.mid or *.musicxml (*.mxl compressed)" if score else ", name it *.mid"
        raise PianobotError(f"-o {output}: {what} is a MIDI file{also}")
    if os.path.realpath(output) == os.path.realpath(song):  # (realpath: a symbolic-link loop is no crash)
        raise PianobotError(f"-o {output} would overwrite the input {song.name}: choose another file name")


def check_models(models: Path) -> None:
    """One line where ``--models`` names a store that is not there: a mistyped path would otherwise
    play with the packaged policies without a word (the default, ``models``, may be absent)."""
    if models.is_dir() or (models == DEFAULT_STORE and not models.exists()):
        return
    if models == DEFAULT_STORE:
        raise PianobotError(
            f"the model store {models}/ here is a file, not a folder: move it, or name the store with --models"
        )
    what = "is not a folder" if models.exists() else "does not exist"
    raise PianobotError(
        f"--models {models}: {what}; name the folder `pianobot train` wrote its policies to, "
        "or leave --models out to play with the packaged policies"
    )


def check_files(inputs: dict[str, Path | None], outputs: dict[str, Path | None]) -> None:
    """The files a command writes (``outputs``, by option; None: not asked for; '-': standard
    output) are each a file of their own, none of them one it reads (``inputs``, by what the user
    calls it), and --json names a *.json file: a run never writes over what the user had."""
    json_path = outputs.get("--json")
    if json_path is not None and str(json_path) != "-" and Path(json_path).suffix.lower() != ".json":
        raise PianobotError(f"--json {json_path}: the figures are a JSON file, name it *.json")
    seen: dict[str, str] = {os.path.realpath(path): name for name, path in inputs.items() if path is not None}
    for option, path in outputs.items():
        if path is None or str(path) == "-":
            continue
        where = os.path.realpath(path)  # (realpath: a symbolic-link loop is no crash)
        same = next((name for other, name in seen.items() if _same_file(where, other)), None)
        if where in seen or same is not None:
            raise PianobotError(f"{option} {path} would overwrite {seen.get(where, same)}: choose another file name")
        seen[where] = f"what {option} writes" if option.startswith("-") else option


def _same_file(one: str, other: str) -> bool:
    """Whether two existing paths are one file (another spelling on a case-insensitive disk, a hard link)."""
    try:
        return os.path.samefile(one, other)
    except OSError:
        return False


def check_html(path: Path | None) -> None:
    """--html must name an .html file."""
    if path is not None and path.suffix.lower() not in (".html", ".htm"):
        raise PianobotError(f"--html {path}: the report is a web page, name it *.html")


WORDING = dict(
    three="--no-thumb plays with three",
    keys="--lowest-note and --keys name other keys",
    refinger="--refinger",
    written="`pianobot finger` writes it to a file",
)
"""What undoes a choice the reading makes, in the command line's words (:class:`~pianobot.pianist.reading.Wording`)."""


def read_file(
    song,
    reading: Reading,
    *,
    finger: bool = True,
    quiet: bool = False,
    both: bool = True,
    fit: bool = True,
    models: Path | None = None,
    policy: Path | None = None,
):
    """``song`` (a path, or a file already read: :func:`~pianobot.pianist.reading.open_song`) read as the reading options say, once (:func:`~pianobot.pianist.reading.read_piece`):
    the keyboard, the hand model and the fingers chosen where --lowest-note/--keys, --hand-model and
    --thumb/--no-thumb name none, each choice said in one line (not ``quiet``); ``finger``: one hand's part fingered too;
    ``both``: both hands where the file plays both; ``fit``: a one-hand part wider than the keys refused;
    ``models``: a model store whose phrase policies for this file were trained with one hand model
    makes that the model where none is named (:func:`stored_model`); ``policy``: a general policy's
    folder named, whose hand (model and fingers) is played where none is named (:func:`policy_hand`)."""
    from pianobot.pianist.reading import Wording, read_piece

    reading = reading if policy is None else policy_hand(reading, Path(policy))
    stored = None if reading.model_named else stored_model(song, models)
    read = read_piece(
        song,
        reading.options,
        reading.keyboard if reading.keyboard_named else None,
        reading.hand if reading.hand_named else None,
        finger=finger,
        both=both,
        fit=fit,
        quiet=quiet,
        wording=Wording(**WORDING),
        model=reading.hand.model if reading.model_named else stored,
    )
    if stored is not None and not quiet and stored != _file_model(read, reading):
        warnings.warn(
            PianobotWarning(
                f"{read.name}: played with the {stored} hand, the hand its policies in {models} were trained for "
                "(--hand-model names another)"
            )
        )
    return read


def _file_model(read, reading: Reading) -> str:
    """The hand model the file alone chooses (:func:`~pianobot.pianist.reading.choose_model`)."""
    from pianobot.pianist.reading import choose_model

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        keyboard = reading.keyboard if reading.keyboard_named else None
        return choose_model(read.source, reading.options, keyboard)[0]


def stored_model(song, models: Path | None) -> str | None:
    """The hand model of the phrase policies the store ``models`` holds for ``song`` (by the file's
    name), where they are all of one; where it holds none for it, of its general policies for
    hands' parts (``task-parts``), where they are all of one; else None (the reading chooses:
    :func:`~pianobot.pianist.reading.choose_model`). So a piece trained before keeps playing with
    the hand its policies were trained for, and a general policy of the user's own plays."""
    from pianobot.agent.general import piece_hand_models
    from pianobot.music.midi_io import source_path

    if models is None:
        return None
    found = piece_hand_models(models, source_path(song).name) or piece_hand_models(models, None)
    if len(found) != 1:
        return None
    (model,) = found
    return model


def policy_hand(reading: Reading, folder: Path) -> Reading:
    """``reading`` with the hand (model and fingers) the policy in ``folder`` was trained for, where
    its options name no hand model: a general policy named plays the hand it knows."""
    from pianobot.agent.policy import policy_configs
    from pianobot.agent.store import is_trained

    if reading.model_named or not is_trained(folder):  # (a folder without a policy: the command says so)
        return reading
    spec = policy_configs(folder)[0].world.hand.spec
    return replace(reading, hand=spec, hand_named=True, model_named=True)


def finger_file(read, reading: Reading):
    """A one-hand reading of :func:`read_file` (``finger=False``) fingered now
    (:func:`~pianobot.pianist.reading.finger_read`), its lines in the command line's words."""
    from pianobot.pianist.reading import Wording, finger_read

    return finger_read(read, reading.options, Wording(**WORDING))


def refuse_training_into(start: Path | None, jobs) -> None:
    """One line, before any work, when the policy to start from is a folder this run trains into
    (the same options, so the same hash): ``--force`` would delete it before it is read."""
    if start is not None and any(job.folder.resolve() == Path(start).resolve() for job in jobs):
        raise PianobotError(
            f"--general-policy {start} is the folder this run trains into: copy it elsewhere and start from the copy"
        )
