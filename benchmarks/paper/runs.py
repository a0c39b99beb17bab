"""An experiment expanded into runs: one per setting, task (or piece), arm and seed, each with
the policies it trains and where its evaluation goes."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from benchmarks.paper.experiments import EVAL_FILE, Experiment, Options, Variant, experiment_named, setting_config
from pianobot.agent import store
from pianobot.errors import PianobotError
from pianobot.learn.config import TrainConfig
from pianobot.learn.jobs import PhraseJob, phrase_jobs, task_job
from pianobot.learn.train import TASK_EVAL_EPISODES
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.phrases import DEFAULT_MAX_NOTES, phrase_hash, split_phrases
from pianobot.music.piece import Piece


@dataclass(frozen=True)
class Run:
    """One trained arm for one seed: the policies it trains (one job for a task; one per phrase
    for compositional execution), and how it is evaluated."""

    experiment: str
    setting: str
    task: str
    """The task family, or (``compose``) which piece: "N phrases"."""
    variant: str
    seed: int
    config: TrainConfig
    jobs: tuple[PhraseJob, ...]
    result: Path
    """Where its evaluation (JSON) goes."""
    piece: Piece | None = None
    """``compose``: the whole piece the run plays ..."""
    phrase_notes: int = DEFAULT_MAX_NOTES
    """... split into phrases of at most this many notes (end-to-end: the whole piece, one phrase)."""

    @property
    def label(self) -> str:
        return f"{self.experiment} {self.setting} {self.task} {self.variant} seed {self.seed}"

    @property
    def group(self) -> tuple[str, str, str]:
        return self.setting, self.task, self.variant


def expand(name: str, options: Options = Options()) -> list[Run]:
    """Every run of an experiment, in the settings and seeds ``options`` asks for."""
    experiment = experiment_named(name)
    names = [variant.name for variant in experiment.variants]
    for variant in options.variants or ():
        if variant not in names:
            raise PianobotError(f"{experiment.name} has no arm {variant!r}: choose from {', '.join(names)}")
    if experiment.name == "compose":
        return _compose_runs(experiment, options)
    steps = options.steps or experiment.steps
    episodes = options.eval_episodes or TASK_EVAL_EPISODES
    root = options.store / "runs"  # shared by every experiment: equal configurations train once
    runs = []
    for setting in options.settings:
        for task in options.tasks or experiment.tasks:
            for variant in experiment.variants:
                if setting not in variant.settings or not wanted(variant, options):
                    continue
                for seed in range(options.seeds):
                    config = setting_config(setting, options, seed, steps, episodes)
                    if setting == "ours":
                        config = experiment.adjust(config)
                    config = variant.change(config)
                    job = task_job(task, config, root)
                    runs.append(
                        Run(experiment.name, setting, task, variant.name, seed, config, (job,), job.folder / EVAL_FILE)
                    )
    return runs


def wanted(variant: Variant, options: Options) -> bool:
    return options.variants is None or variant.name in options.variants


def compose_pieces(options: Options) -> list[tuple[int, Piece]]:
    """``compose``'s pieces: the first N phrases of ``options.piece`` for each N of ``options.lengths``."""
    whole = load_piece(options.piece, LoadOptions(tempo=options.tempo))
    phrases = split_phrases(whole)
    pieces = []
    for length in options.lengths:
        if not 1 <= length <= len(phrases):
            raise PianobotError(f"--lengths {length}: {options.piece} has {len(phrases)} phrases")
        notes = tuple(note for phrase in phrases[:length] for note in phrase.notes)
        pieces.append((length, Piece(notes, bpm=whole.bpm).shift(-notes[0].onset)))
    return pieces


def _compose_runs(experiment: Experiment, options: Options) -> list[Run]:
    """Compositional: one policy per phrase of the piece (``steps`` each). End-to-end: one policy
    on the whole piece, a "phrase" as long as the piece, with as many steps as all the phrase
    policies together. The phrase policies of a seed and setting share one model folder, so a
    phrase that two pieces share is trained once (the piece of one phrase is its own end-to-end run)."""
    steps = options.steps or experiment.steps
    episodes = options.eval_episodes or TrainConfig.eval_episodes
    runs = []
    for setting in options.settings:
        for seed in range(options.seeds):
            config = setting_config(setting, options, seed, steps, episodes)
            root = options.store / "compose" / setting / f"{options.piece.stem}-{store.config_hash(config)}"
            for length, piece in compose_pieces(options):
                task, about = f"{length} phrase{'s' if length > 1 else ''}", piece_label(options, length)
                parts = tuple(phrase_jobs(split_phrases(piece), config, root, piece=about))
                whole = replace(config, steps=steps * len(parts))  # the same total steps
                single = tuple(phrase_jobs(split_phrases(piece, len(piece)), whole, root, piece=about))
                notes = phrase_hash(piece.notes)  # another piece or tempo: another result
                arms = (
                    Run(experiment.name, setting, task, "compositional", seed, config, parts,
                        root / f"compositional-{length}-{notes}.json", piece),
                    Run(experiment.name, setting, task, "end-to-end", seed, whole, single,
                        root / f"end-to-end-{length}-{notes}.json", piece, len(piece)),
                )  # fmt: skip
                runs += [run for run in arms if options.variants is None or run.variant in options.variants]
    return runs


def piece_label(options: Options, length: int) -> str:
    return f"{options.piece.name}, first {length} phrases"
