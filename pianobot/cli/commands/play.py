"""The `pianobot play` command."""

from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path
from typing import Optional

import typer

from pianobot.cli.options import (
    Controller,
    Fallback,
    GeneralPolicy,
    PlayPhraseNotes,
    Reading,
    check_midi_output,
    read_song,
    reads,
)
from pianobot.cli.terminal import err, out, said
from pianobot.errors import PianobotError
from pianobot.files import atomic_write, check_writable
from pianobot.music.phrases import DEFAULT_MAX_NOTES
from pianobot.perform.controllers import CONTROLLERS
from pianobot.sim.world import WorldConfig


@reads()
def play(
    song: Path = typer.Argument(..., help="The piece to play, a .mid file with fingering."),
    output: Path = typer.Option(
        ..., "--output", "-o", help="Write what the simulated piano sounded to this .mid file."
    ),
    controller: Controller = typer.Option(
        CONTROLLERS[0],
        "--controller",
        help="Who plays: 'sac' (the trained phrase policies), 'scripted' (the hand-written pianist) or 'random'.",
    ),
    models: Path = typer.Option(Path("models"), "--models", help="Folder of the model store (for --controller sac)."),
    fallback: Optional[Fallback] = typer.Option(
        None,
        "--fallback",
        help="'scripted': play phrases that have no trained policy with the scripted pianist (when no general policy "
        "plays them: a phrase's own policy first, then the general policy, then the fallback).",
    ),
    use_general: bool = typer.Option(
        True,
        "--general/--no-general",
        help="Play phrases without a policy of their own with the general policy (the newest `pianobot train --task "
        "melody` policy in --models, or --general-policy), when there is one.",
    ),
    general_policy: Optional[Path] = GeneralPolicy,
    wrist_guard: bool = typer.Option(
        False,
        "--wrist-guard/--no-wrist-guard",
        help="While a fingertip is low over the keys, the general policy's wrist slides no faster than the scripted "
        "pianist's does while holding a key (PianistTuning.hold_slide, 8 mm a step), so that a late release drags a "
        "finger across the keys less often (no effect on a policy trained with a discrete wrist).",
    ),
    phrase_notes: Optional[int] = PlayPhraseNotes,
    seed: int = typer.Option(
        0, "--seed", help="Seed of the simulation (the hand's start position) and of the random controller."
    ),
    video: Optional[Path] = typer.Option(None, "--video", help="Also record the performance to this .mp4 file."),
    wav: Optional[Path] = typer.Option(None, "--wav", help="Also synthesise what was played to this .wav file."),
    soundfont: Optional[Path] = typer.Option(
        None,
        "--soundfont",
        help="A General MIDI .sf2 soundfont for --wav and --video's sound (FluidSynth; default: an installed one, "
        "else sine waves).",
    ),
    gui: bool = typer.Option(False, "--gui", help="Show the simulation in a PyBullet window (needs a display)."),
    reading: Reading = None,
):
    """Perform a piece in the simulator; write the played notes (velocities, fingers) and a velocity-error report."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    from pianobot.agent.general import describe, find_general
    from pianobot.agent.policy import policy_configs
    from pianobot.cli import display
    from pianobot.music.midi_io import write_midi
    from pianobot.music.phrases import split_phrases
    from pianobot.perform.audio import check_soundfont, write_wav
    from pianobot.perform.compose import (
        GENERAL_SOURCE,
        CompositionalController,
        general_for,
        missing_phrases,
        shared_env_config,
        trained_split,
    )
    from pianobot.perform.guard import WristGuard
    from pianobot.perform.perform import PLAY_CONFIG, perform, write_video
    from pianobot.sim.hand import HandConfig
    from pianobot.sim.keyboard import KeyboardConfig

    check_midi_output(output, song, "the performance")
    report_path = output.with_suffix(".report.json")
    for target in (output, report_path, video, wav):
        if target is not None:
            check_writable(target)
    if video is not None and video.suffix.lower() != ".mp4":
        raise PianobotError(f"--video {video}: the video is an MP4 file, name it *.mp4")
    if wav is not None and wav.suffix.lower() != ".wav":
        raise PianobotError(f"--wav {wav}: the audio is a WAV file, name it *.wav")
    if soundfont is not None:
        check_soundfont(soundfont)
    if gui and not os.environ.get("DISPLAY"):
        raise PianobotError("--gui needs a display (DISPLAY is not set): drop --gui, or use --video to watch it later")
    if general_policy is not None and not use_general:
        raise PianobotError(f"--general-policy {general_policy} and --no-general ask for opposite things: give one")
    if general_policy is not None:
        find_general(models, path=general_policy)  # a folder that holds no policy: said before any work
    keyboard, hand = reading.keyboard, reading.hand
    piece = read_song(song, reading.options, keyboard, hand)
    world = WorldConfig(keyboard=KeyboardConfig(spec=keyboard), hand=HandConfig(spec=hand), gui=gui)
    config = replace(PLAY_CONFIG, world=world)
    sources: dict = {}
    guards: list = []  # the wrist guard the general policy played through (one, shared by its sections)
    general = None  # the general policy's folder, when it plays a phrase
    who = controller.value
    if controller == "sac":
        import torch

        torch.set_num_threads(1)  # batch-1 inference: more threads only spin against other work on the cores
        phrases = trained_split(models, piece, phrase_notes)
        missing = missing_phrases(models, phrases)
        if phrase_notes is None and phrases != split_phrases(piece, DEFAULT_MAX_NOTES):
            most = max(len(p.notes) for p in phrases)
            out.print(
                f"[dim]{len(phrases)} phrases of at most {most} note{'s' * (most > 1)}: the split the policies in {said(models)} were trained for[/dim]"
            )
        trained = shared_env_config(models, phrases)  # the environment of the phrases' own policies
        if missing and use_general:  # a phrase's own policy, else the general policy, else the fallback
            general = general_for(models, trained, general_policy)
        if missing and general is None and not fallback:
            first = missing[0]
            raise PianobotError(
                f"phrase {first.index} ({' '.join(n.name for n in first.notes)}) of {song.name} has no trained policy in {models}: "
                f"train it with `pianobot train {song}` (same reading options), train a general policy with "
                f"`pianobot train --task melody`, add --fallback scripted, or play with --controller scripted"
            )
        if trained is None and general is not None:
            trained = policy_configs(general)[0]
        if trained is not None:
            config = replace(trained, world=replace(trained.world, gui=gui))
            if trained.world.keyboard.spec != keyboard or trained.world.hand.spec != hand:
                raise PianobotError(
                    f"the policies in {models} were trained for another keyboard or hand: use the same --lowest-note/--keys/--thumb"
                )
        if missing and general is None and config.world.control == "torque":
            raise PianobotError("--fallback scripted needs policies trained with --control velocity or position")

        def who(env):
            composed = CompositionalController(env, phrases, models, fallback is not None, general, wrist_guard)
            sources.update({p.index: s.source for s in composed.sections for p in s.phrases})
            guards.extend(s.controller for s in composed.sections if isinstance(s.controller, WristGuard))
            return composed

    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TimeRemainingColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,  # (a bar in a log is noise, and its last line break an empty line)
    ) as bar:
        task = bar.add_task(f"playing {said(song.name)}", total=None)
        result = perform(
            piece,
            who,
            config,
            seed=seed,
            video=video is not None,
            on_step=lambda done, total: bar.update(task, completed=done, total=total),
        )
    report = result.report()
    write_midi(result.played, output, name=f"pianobot {controller}: {song.stem}")
    extra = {"phrases": {str(k): v for k, v in sources.items()}} if sources else {}
    by_general = [k for k, v in sources.items() if v.startswith(GENERAL_SOURCE)]
    if by_general:
        extra["general_policy"] = describe(general)
        extra["wrist_guard"] = {"on": bool(guards), "slowed_steps": guards[0].capped if guards else 0}
    atomic_write(
        report_path, json.dumps({"controller": controller, "seed": seed, **extra, **report.to_dict()}, indent=2) + "\n"
    )
    if by_general:
        out.print(
            f"[yellow]phrases {', '.join(map(str, by_general))} had no policy of their own and were played by the "
            f"general policy {said(general)}[/yellow]",
            soft_wrap=True,  # (one line, the path whole)
        )
    fallbacks = [k for k, v in sources.items() if "fallback" in v]
    if fallbacks:
        out.print(
            f"[yellow]phrases {', '.join(map(str, fallbacks))} had no trained policy and were played by the scripted pianist[/yellow]"
        )
    display.print_all(out, display.report_tables(report))
    out.print(f"performance written to {said(output)}, report to {said(report_path)}")
    if video is not None:
        import tempfile

        with tempfile.TemporaryDirectory() as scratch:  # the sound, starting with the first frame
            method = write_wav(result.played, Path(scratch) / "sound.wav", font=soundfont, delay=result.start)
            write_video(result.frames, video, fps=config.world.control_hz, audio=Path(scratch) / "sound.wav")
        out.print(f"video written to {said(video)}, with sound ({method})")
    if wav is not None:
        method = write_wav(result.played, wav, font=soundfont)
        out.print(f"audio written to {said(wav)} ({method})")
