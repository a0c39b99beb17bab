"""Training steps per second with `--envs N`: environments stepped in worker processes.

    python benchmarks/envs.py [--envs 1 2] [--repeats 3] [--explore-steps 1200] [--learn-steps 300]

Trains a policy for examples/midi/three-note.mid with the default configuration (tactile
images, scripted exploration, one update per step) in two short runs per ``--envs`` value and
repeat: one that only explores (the scripted teacher plus noise, no updates) and one that
learns (``--learn-steps`` steps after 300 of exploration, timed from the first update on).
Prints the median of ``--repeats`` environment steps per second for each phase. One torch thread.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import torch

from pianobot.agent.config import SACConfig
from pianobot.learn.config import TrainConfig
from pianobot.learn.train import Progress, train_policy
from pianobot.music.load import load_piece
from pianobot.music.phrases import split_phrases

ROOT = Path(__file__).resolve().parent.parent
LEARN_AFTER = 300


def rate(envs: int, steps: int, exploration: int, start: int) -> float:
    """Environment steps per second of one run, from its first progress report after ``start``
    steps to its last before the final evaluation."""
    (phrase,) = split_phrases(load_piece(ROOT / "examples" / "midi" / "three-note.mid"))
    sac = SACConfig(exploration_steps=exploration)
    config = TrainConfig(steps=steps, envs=envs, eval_every=10**9, checkpoint_every=10**9, device="cpu", sac=sac)
    marks: list[tuple[float, int]] = []

    def report(progress: Progress) -> None:
        if not progress.finished:
            marks.append((time.perf_counter(), progress.step))

    with tempfile.TemporaryDirectory() as folder:
        train_policy(phrase.piece(), config, Path(folder), report)
    timed = [(t, s) for t, s in marks if s > start]
    (t0, s0), (t1, s1) = timed[0], timed[-1]
    return (s1 - s0) / (t1 - t0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--explore-steps", type=int, default=1200)
    parser.add_argument("--learn-steps", type=int, default=300)
    args = parser.parse_args()
    torch.set_num_threads(1)
    print("| --envs | exploring, steps/s | learning, steps/s |")
    print("| ---: | ---: | ---: |")
    for envs in args.envs:
        explore = [rate(envs, args.explore_steps, args.explore_steps - 1, 100) for _ in range(args.repeats)]
        learn = [rate(envs, LEARN_AFTER + args.learn_steps, LEARN_AFTER, LEARN_AFTER) for _ in range(args.repeats)]
        print(
            f"| {envs} | {statistics.median(explore):.0f} ({', '.join(f'{r:.0f}' for r in explore)}) "
            f"| {statistics.median(learn):.1f} ({', '.join(f'{r:.1f}' for r in learn)}) |",
            flush=True,
        )


if __name__ == "__main__":
    main()
