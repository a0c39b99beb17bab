"""The `pianobot play` command."""

from __future__ import annotations

import contextlib
import json
import os
from pathlib import Path
from typing import Optional

import typer

from pianobot.cli.options import (
    DEFAULT_STORE,
    AllFigures,
    Controller,
    HtmlReport,
    PlayPhraseNotes,
    Reading,
    check_files,
    check_html,
    check_midi_output,
    check_models,
    choices,
    finger_file,
    read_file,
    reads,
)
from pianobot.cli.terminal import err, out, said, write_json
from pianobot.errors import PianobotError
from pianobot.files import atomic_write, check_writable
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.perform.controllers import CONTROLLERS


@contextlib.contextmanager
def progress(what: str):
    """A progress bar on standard error's terminal (none in a log: there a bar is noise, and its
    last line break an empty line); yields the ``on_step(done, total)`` that moves it."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err, transient=True, disable=not err.is_terminal) as bar:
        task = bar.add_task(what, total=None)
        yield lambda done, total: bar.update(task, completed=done, total=total)


GUARDS = {"auto": (False, None), "hold": (False, True), "wrist": (True, False), "both": (True, True)}
GUARDS |= {"none": (False, False)}
"""--guard -> (wrist_guard, hold_guard) of :class:`~pianobot.perform.plan.PerformancePlan`; 'auto'
is the plan's defaults (a test holds them equal: the plan module is slow to import)."""
Guard = choices("Guard", tuple(GUARDS))
NAMED = ("general", "scripted", "none")
"""The --policy values that name no folder."""

SONG_OPTION = typer.Argument(
    ...,
    help="A .mid file, a MusicXML score (.musicxml, .xml, .mxl) or a PIG .txt file.",
)
OUTPUT_OPTION = typer.Option(..., "--output", "-o", help="The .mid file of what was played.")
CONTROLLER_OPTION = typer.Option(
    CONTROLLERS[0],
    "--controller",
    help="sac (trained policies), scripted (the hand-written pianist) or random.",
)
POLICY_OPTION = typer.Option(
    "general",
    "--policy",
    help="Who plays phrases with no policy of their own: general, a general policy's folder "
    "(or right=DIR,left=DIR), scripted or none (docs/play.md).",
)
GUARD_OPTION = typer.Option(
    "auto",
    "--guard",
    help="The scripted pianist's help to the general policy (docs/play.md).",
)
SEED_OPTION = typer.Option(
    0,
    "--seed",
    help="Seed of the hand's start (and of random).",
    min=0,
    metavar="N",
)
SOUNDFONT_OPTION = typer.Option(
    None,
    "--soundfont",
    help="A .sf2 soundfont (default: one installed).",
)
JSON_PATH_OPTION = typer.Option(
    None,
    "--json",
    help="Also write the report as JSON ('-': stdout).",
)
NOTES_OPTION = typer.Option(0, "--notes", min=0, metavar="N", help="Print N rows of the per-note table.")
QUIET_OPTION = typer.Option(False, "--quiet", "-q", help="Print only the files written, warnings and errors.")


@reads()
def play(
    song: Path = SONG_OPTION,
    output: Path = OUTPUT_OPTION,
    controller: Controller = CONTROLLER_OPTION,
    models: Path = typer.Option(DEFAULT_STORE, "--models", help="The model store's folder."),
    policy: str = POLICY_OPTION,
    guard: Guard = GUARD_OPTION,
    phrase_notes: Optional[int] = PlayPhraseNotes,
    seed: int = SEED_OPTION,
    video: Optional[Path] = typer.Option(None, "--video", help="Also record a video (.mp4)."),
    wav: Optional[Path] = typer.Option(None, "--wav", help="Also write the sound (.wav)."),
    soundfont: Optional[Path] = SOUNDFONT_OPTION,
    gui: bool = typer.Option(False, "--gui", help="Show the simulation in a window."),
    html: Optional[Path] = HtmlReport,
    json_path: Optional[Path] = JSON_PATH_OPTION,
    notes: int = NOTES_OPTION,
    every: bool = AllFigures,
    quiet: bool = QUIET_OPTION,
    reading: Reading = None,
):
    """Perform a piece in the simulator (both hands of a two-hand one); write what was played."""
    files = dict(report=output.with_suffix(".report.json"), json=json_path, wav=wav, soundfont=soundfont, html=html)
    files |= dict(video=video)
    shown = dict(notes=notes, every=every, quiet=quiet)
    report_path, shown["console"] = _check_files(
        song, output, reading, controller, models, json_path, html, wav, video, soundfont, gui
    )
    named = next(iter(_policy_folders(policy, controller).values()), None)  # (its hand plays: read_file)
    read = read_file(song, reading, finger=False, models=models if controller == "sac" else None, policy=named)
    hands = read.hands
    players = _players(policy, song, hands is not None, controller)
    wrist_guard, hold_guard = GUARDS[guard.value]
    if hands is not None:  # a two-hand file: both hands, in one simulation
        if gui:
            raise PianobotError(
                f"--gui shows one hand so far, and {song.name} plays with two: "
                "play one hand for it with --hand right (or --hand left), or watch both with --video"
            )
        play_both(
            song,
            output,
            hands,
            controller=controller.value,
            models=models,
            seed=seed,
            keyboard=reading.keyboard if reading.keyboard_named else None,  # (none named: each player's own keys)
            hand=read.fingers,
            options=dict(
                **players,
                phrase_notes=phrase_notes,
                wrist_guard=wrist_guard,
                hold_guard=hold_guard,
                pedal=read.pedal,
            ),
            files=files,
            shown=shown,
        )
        return
    options = dict(**players, phrase_notes=phrase_notes, wrist_guard=wrist_guard, hold_guard=hold_guard, gui=gui)
    options |= dict(pedal=read.pedal)
    play_one(song, output, finger_file(read, reading), controller, models, seed, options, files, shown)


def _check_files(song, output, reading, controller, models, json_path, html, wav, video, soundfont, gui):
    """Every file play reads and writes, and what it needs, checked before any work: (the report's
    path beside -o, the console for what is printed)."""
    from pianobot.perform.audio import check_soundfont

    check_midi_output(output, song, "the performance")
    if controller == "sac":
        check_models(models)
    report_path = output.with_suffix(".report.json")
    check_files(
        {"the input": song, "the fingering file": reading.options.fingering},
        {
            "-o": output,
            "the report beside -o": report_path,
            "--json": json_path,
            "--html": html,
            "--wav": wav,
            "--video": video,
        },
    )
    to_stdout = json_path is not None and str(json_path) == "-"
    console = err if to_stdout else out  # standard output carries the JSON
    for target in (output, report_path, video, wav, html, None if to_stdout else json_path):
        if target is not None:
            check_writable(target)
    check_html(html)
    if video is not None and video.suffix.lower() != ".mp4":
        raise PianobotError(f"--video {video}: the video is an MP4 file, name it *.mp4")
    if wav is not None and wav.suffix.lower() != ".wav":
        raise PianobotError(f"--wav {wav}: the audio is a WAV file, name it *.wav")
    if soundfont is not None:
        check_soundfont(soundfont)
    if gui and not os.environ.get("DISPLAY"):
        raise PianobotError("--gui needs a display (DISPLAY is not set): drop --gui, or use --video to watch it later")
    if controller == "sac":
        import torch

        torch.set_num_threads(1)  # batch-1 inference: more threads only spin against other work on the cores
    return report_path, console


def _players(policy: str, song: Path, two_hands: bool, controller) -> dict:
    """--policy as the plan's options: whether the general policy plays (``general``), which one
    (``general_policy``: a folder, or each hand's), and whether the scripted pianist plays what
    no policy plays (``fallback``)."""
    if policy in NAMED:
        return dict(general=policy == "general", general_policy=None, fallback=policy == "scripted")
    named = _policy_folders(policy, controller)
    if "" not in named and not two_hands:
        raise PianobotError(f"--policy {policy}: {song.name} plays one hand: name the general policy's folder alone")
    return dict(general=True, general_policy=named if "" not in named else named[""], fallback=False)


def _policy_folders(policy: str, controller) -> dict[str, Path]:
    """The folders --policy names (by hand, right=DIR,left=DIR; else one, by ''), each holding a
    trained policy; none where it names none (:data:`NAMED`)."""
    from pianobot.agent import store

    if policy != "general" and controller != "sac":
        raise PianobotError(
            f"--policy {policy}: --controller {controller.value} plays every phrase itself: drop --policy"
        )
    if policy in NAMED:
        return {}
    by_hand = "=" in policy and not Path(policy).is_dir()
    parts = [part.partition("=") for part in policy.split(",")] if by_hand else [("", "=", policy)]
    folders = {hand: folder for hand, _, folder in parts}
    if by_hand and (
        set(folders) - {"right", "left"} or len(folders) != len(parts) or not all(eq for _, eq, _ in parts)
    ):
        raise PianobotError(
            f"--policy {policy}: name each hand's general policy once, as right=DIR,left=DIR (or one of them)"
        )
    for folder in folders.values():
        if not store.is_trained(Path(folder)):
            raise PianobotError(
                f"--policy {policy}: {folder} is not a trained policy folder (one holding {store.POLICY_FILE} and "
                f"{store.MANIFEST_FILE}, e.g. one `pianobot train --task parts` wrote), nor one of {', '.join(NAMED)}"
            )
    return {hand: Path(folder) for hand, folder in folders.items()}


def play_one(
    song: Path, output: Path, read, controller, models, seed: int, options: dict, files: dict, shown: dict
) -> None:
    """`play` of a one-hand piece (``read``: a :class:`~pianobot.pianist.reading.ReadPiece`, fingered):
    planned (:func:`~pianobot.perform.plan.plan_performance`), performed as judged
    (:func:`~pianobot.perform.judge.perform_judged`), written, and reported."""
    from pianobot.cli import display
    from pianobot.music.midi_io import write_midi
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.audio import write_wav
    from pianobot.perform.judge import perform_judged
    from pianobot.perform.perform import write_video
    from pianobot.perform.plan import Player, plan_performance

    console, quiet, notes, every = shown["console"], shown["quiet"], shown["notes"], shown["every"]
    report_path, json_path, video, wav, html = (
        files["report"],
        files["json"],
        files["video"],
        files["wav"],
        files["html"],
    )
    soundfont, phrase_notes = files["soundfont"], options["phrase_notes"]
    piece = read.piece
    chosen = dict(keyboard=read.keyboard, hand=read.fingers, **options)
    plan = plan_performance(piece, controller.value, models, **chosen)
    if (
        not quiet
        and controller == "sac"
        and phrase_notes is None
        and list(plan.phrases) != split_phrases(piece, DEFAULT_MAX_NOTES)
    ):
        most = max(len(p.notes) for p in plan.phrases)
        console.print(
            f"[dim]{len(plan.phrases)} phrases of at most {most} note{'s' * (most > 1)}: the split the policies in {said(models)} were trained for[/dim]"
        )
    with progress(f"playing {said(song.name)}") as on_step:
        performance = perform_judged(
            plan,
            models,
            lambda leave_out: plan_performance(piece, controller.value, models, **chosen, leave_out=leave_out),
            seed=seed,
            video=video is not None,
            on_step=on_step,
        )
    performance = against_written_fingering(performance, read.part)
    plan = performance.plan
    write_midi(performance.played, output, name=f"pianobot ({plan.performer}): {song.stem}", pedal=performance.pedal)
    report = performance.report()  # (after the performance is written: nothing played is lost to the scoring)
    atomic_write(report_path, json.dumps(performance.to_dict(), indent=2) + "\n")
    if json_path is not None:
        write_json(json_path, performance.to_dict())
    if not quiet and (len(plan.players) > 1 or plan.players[0] is not Player.OWN):
        for player in plan.players:
            numbers = [p.index for s in plan.stretches if s.player is player for p in s.phrases]
            policy = next(s.policy for s in plan.stretches if s.player is player)
            which = f" {said(policy)}" if player is Player.GENERAL else ""
            console.print(
                f"phrase{'s' * (len(numbers) > 1)} {', '.join(map(str, numbers))}: {player.value}{which}",
                soft_wrap=True,
            )
    if not quiet:
        display.print_all(console, display.report_tables(report, every, notes))
    console.print(f"performance written to {said(output)}, report to {said(report_path)}")
    if video is not None:
        import tempfile

        with tempfile.TemporaryDirectory() as scratch:  # the sound, starting with the first frame
            sound = Path(scratch) / "sound.wav"
            method = write_wav(
                performance.played, sound, font=soundfont, delay=performance.start, pedal=performance.pedal
            )
            write_video(performance.frames, video, fps=plan.config.world.control_hz, audio=sound)
        console.print(f"video written to {said(video)}, with sound ({method})")
    if wav is not None:
        method = write_wav(performance.played, wav, font=soundfont, pedal=performance.pedal)
        console.print(f"audio written to {said(wav)} ({method})")
    if html is not None:
        from pianobot.perform.report import write_html

        title = f"{song.name}: {plan.performer}"
        write_html(html, report, title, plan=plan, seed=seed, video=video, audio=wav)
        console.print(f"report to open in a browser written to {said(html)}")


def against_written_fingering(performance, part):
    """``performance`` with the notes it is scored against fingered as the file fingers them (``part``:
    the part as read, before the planner fingered it; None: as it is): its fingering figure counts the
    file's own marks, as `score` of the file counts them, and is n/a for a file without any."""
    from dataclasses import replace

    from pianobot.music.piece import Piece

    reference = performance.rollout.reference
    if part is None or len(part.notes) != len(reference.notes):
        return performance
    marks = tuple(replace(note, finger=mark.finger) for note, mark in zip(reference.notes, part.notes))
    rollout = replace(performance.rollout, reference=Piece(marks, bpm=reference.bpm))
    return replace(performance, rollout=rollout)


def play_both(
    song: Path, output: Path, reading, *, controller, models, seed, keyboard, hand, options, files, shown
) -> None:
    """`play` of a two-hand file (``reading``: a :class:`~pianobot.perform.together.HandsReading`):
    both hands in one simulation (:func:`~pianobot.perform.together.play_hands`), one
    track per hand in ``output``, and the report of the whole piece and each hand (``hand``: both
    hands' fingers, as the reading chose them: :func:`~pianobot.pianist.reading.choose_fingers`)."""
    import warnings

    from pianobot.cli import display
    from pianobot.errors import PianobotWarning
    from pianobot.music.midi_io import write_midi
    from pianobot.perform.audio import write_wav
    from pianobot.perform.together import AGAINST, TOGETHER, play_hands

    console, quiet = shown["console"], shown["quiet"]
    if not quiet:
        model = "" if hand.model == "allegro" else f" (the {hand.model} hand; --hand-model names the hand)"
        console.print(f"both hands{model}, {TOGETHER}; {AGAINST}", soft_wrap=True)
        for name in reading.piece.hands:
            console.print(said(reading.describe(name)), soft_wrap=True)
    with (
        warnings.catch_warnings(record=True) as caught,
        progress(f"playing {said(song.name)}, both hands") as on_step,
    ):
        warnings.simplefilter("always", PianobotWarning)
        performance = play_hands(
            reading.piece,
            controller,
            models,
            seed,
            hand,
            keyboard,
            on_step=on_step,
            video=files["video"] is not None,
            **options,
        )
    changes = {line for h in performance.hands for line in h.changes}
    for warning in caught:  # what each hand was given is on the first screen; the rest are warnings
        if quiet or str(warning.message) not in changes:
            warnings.warn(warning.message)
    write_midi(performance.played, output, pedal=performance.pedal)
    report = performance.to_dict(reading)
    atomic_write(files["report"], json.dumps(report, indent=2) + "\n")
    if files["json"] is not None:
        write_json(files["json"], report)
    if not quiet:
        console.print(display.hands_table(performance))
        for h in performance.hands:
            for line in h.changes:
                console.print(f"[yellow]left out or reduced:[/yellow] {said(line)}", soft_wrap=True)
        display.print_all(console, display.report_tables(performance.report(), shown["every"], shown["notes"]))
    console.print(f"performance written to {said(output)} (one track per hand), report to {said(files['report'])}")
    if files["video"] is not None:
        import tempfile

        from pianobot.perform.perform import write_video

        start = performance.start  # (the sound starts with the first frame)
        with tempfile.TemporaryDirectory() as scratch:
            sound = Path(scratch) / "sound.wav"
            early = min(start, 0.0)  # (a lead-in shorter than the piece's first rest: the sound starts later)
            played, pedal = performance.played.shift(early), performance.pedal.shift(early)
            method = write_wav(played, sound, font=files["soundfont"], delay=max(start, 0.0), pedal=pedal)
            write_video(performance.frames, files["video"], fps=performance.fps, audio=sound)
        console.print(f"video written to {said(files['video'])}, with sound ({method})")
    if files["wav"] is not None:
        method = write_wav(performance.played, files["wav"], font=files["soundfont"], pedal=performance.pedal)
        console.print(f"audio written to {said(files['wav'])} ({method})")
    if files["html"] is not None:
        from pianobot.perform.report import write_html

        title = f"{song.name}: both hands, {performance.performer}"
        write_html(
            files["html"],
            performance.report(),
            title,
            seed=seed,
            hands=performance,
            reading=reading,
            video=files["video"],
        )
        console.print(f"report to open in a browser written to {said(files['html'])}")
