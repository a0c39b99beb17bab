"""Compositional execution against one end-to-end policy (the paper's long-horizon figure), and play speed.

    python benchmarks/compose.py --piece examples/midi/twinkle.mid --steps 20000 --seeds 0 \
        [--workers 2] [--store /tmp/pianobot-compose] [--models models] [--no-tactile]

Compositional: one SAC policy per phrase (``--steps`` each), played one after another in one
continuous simulation as `pianobot play --controller sac` does. End-to-end: one SAC policy
trained on the whole piece with the same total number of environment steps (``--steps`` times
the number of phrases). Both are trained with the default configuration otherwise, checkpointed
in ``--store`` (rerunning the same command resumes), then each plays the piece from three hand
starts. Also measured: the real-time factor of playing (simulated seconds per wall-clock
second) for the compositional controller and for the scripted pianist, in the same run.
Prints Markdown tables for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

import torch

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.policy import load_policy
from pianobot.env.piano import EnvConfig
from pianobot.learn.config import TrainConfig
from pianobot.learn.jobs import phrase_jobs, plan_jobs, run_jobs
from pianobot.learn.train import train_policy
from pianobot.music.load import load_piece
from pianobot.music.phrases import split_phrases
from pianobot.perform.compose import CompositionalController
from pianobot.perform.perform import perform
from pianobot.perform.plan import assign

PLAY_SEEDS = (0, 1, 2)


def play(piece, factory, config: EnvConfig) -> tuple[list[float], list[float], float]:
    """Note F1 and velocity MAE per hand start, and the real-time factor."""
    f1s, maes, factors = [], [], []
    for seed in PLAY_SEEDS:
        started = time.perf_counter()
        result = perform(piece, factory, config, seed=seed)
        factors.append(result.steps / config.world.control_hz / (time.perf_counter() - started))
        report = result.report()
        f1s.append(report.f1)
        maes.append(report.velocity_mae if report.velocity_mae is not None else float("nan"))
    return f1s, maes, statistics.median(factors)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--piece", default="examples/midi/twinkle.mid")
    parser.add_argument("--steps", type=int, default=20_000, help="environment steps per phrase")
    parser.add_argument("--exploration-steps", type=int, default=SACConfig.exploration_steps)
    parser.add_argument("--seeds", nargs="+", type=int, default=[0])
    parser.add_argument("--tactile", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--store", default="/tmp/pianobot-compose", help="where the end-to-end policy is stored")
    parser.add_argument(
        "--models",
        default=None,
        help="model store of the phrase policies (default: STORE/seedN/phrases); "
        "policies `pianobot train` stored there with the same configuration are reused",
    )
    args = parser.parse_args()
    torch.set_num_threads(1)

    piece = load_piece(args.piece)
    phrases = split_phrases(piece)
    total = args.steps * len(phrases)
    print(
        f"{args.piece}: {len(piece)} notes in {len(phrases)} phrases; {args.steps} steps per phrase, {total} end-to-end\n"
    )
    rows = []
    for seed in args.seeds:
        env = EnvConfig(tactile=args.tactile)
        config = TrainConfig(
            steps=args.steps, seed=seed, sac=SACConfig(exploration_steps=args.exploration_steps), env=env
        )
        root = Path(args.store) / f"seed{seed}"
        models = Path(args.models) if args.models else root / "phrases"
        todo, _ = plan_jobs(phrase_jobs(phrases, config, models, piece=Path(args.piece).name), force=False)
        started = time.perf_counter()
        run_jobs(todo, config, args.workers, lambda key, progress: None)
        compositional_minutes = (time.perf_counter() - started) / 60

        whole = replace(config, steps=total)
        folder = store.model_dir(root / "whole", "whole-piece", whole)
        started = time.perf_counter()
        if not store.is_trained(folder):
            train_policy(
                piece.shift(-piece.notes[0].onset), whole, folder, about={"key": "whole-piece", "piece": args.piece}
            )
        end_to_end_minutes = (time.perf_counter() - started) / 60

        composed = play(piece, lambda e, models=models: CompositionalController(e, assign(phrases, models)), env)
        single = play(
            piece, lambda e, folder=folder: load_policy(folder, e), env
        )  # the whole piece's window, as trained
        scripted = play(piece, "scripted", env)
        for name, (f1s, maes, factor), minutes in (
            ("compositional", composed, compositional_minutes),
            ("end-to-end", single, end_to_end_minutes),
            ("scripted pianist", scripted, 0.0),
        ):
            rows.append((name, seed, f1s, maes, factor, minutes))

    print(
        "| controller | seed | note F1 (hand starts 0, 1, 2) | mean F1 | velocity MAE | real-time factor | training minutes |"
    )
    print("| --- | ---: | --- | ---: | ---: | ---: | ---: |")
    for name, seed, f1s, maes, factor, minutes in rows:
        print(
            f"| {name} | {seed} | {', '.join(f'{f:.3f}' for f in f1s)} | {statistics.mean(f1s):.3f} | "
            f"{statistics.mean(maes):.1f} | {factor:.1f}x | {minutes:.1f} |"
        )


if __name__ == "__main__":
    main()
