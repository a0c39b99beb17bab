"""How precise must a policy be? The scripted pianist with Gaussian noise on its actions.

    python benchmarks/precision.py [examples/midi/three-note.mid] [--sigmas 0 0.02 0.05 0.1] [--starts 4]
                                   [--control velocity|position]

A learned policy imitates the scripted pianist (behaviour cloning) and acts on top of it (SAC);
its action is never exactly the teacher's. This measures what a given action error costs: the
noise-free teacher's actions plus N(0, sigma) on every joint, on the finger joints only, or on
the wrist only, over several hand starts of the piece's first phrase (the starts evaluation
uses). Prints a Markdown table of mean note F1, per-step F1 and mean onset error.

``--control`` picks the finger joints' action space: joint speeds (velocity) or joint angle
targets (position); the same sigma is the same share of each action's full scale.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np

from pianobot.learn.config import TrainConfig
from pianobot.learn.train import EVAL_SEED, make_env
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions, load_part
from pianobot.music.phrases import split_phrases
from pianobot.perform.rollout import rollout
from pianobot.pianist.scripted import ScriptedPianist

PARTS = ("all", "fingers", "wrist")


class NoisyPianist:
    """The scripted pianist's actions plus N(0, sigma) on every joint, the fingers' or the wrist's."""

    def __init__(self, pianist: ScriptedPianist, sigma: float, part: str, seed: int):
        self.pianist, self.sigma, self.part = pianist, sigma, part
        self.rng = np.random.default_rng(seed)

    def reset(self) -> None:
        self.pianist.reset()

    def act(self, observation: dict) -> np.ndarray:
        action = self.pianist.act(observation)
        noise = self.sigma * self.rng.standard_normal(action.shape)
        if self.part == "fingers":
            noise[-1] = 0.0  # the last action is the wrist's
        elif self.part == "wrist":
            noise[:-1] = 0.0
        return np.clip(action + noise, -1.0, 1.0)


def play(env, pianist: ScriptedPianist, sigma: float, part: str, start: int) -> tuple[float, float, float | None]:
    """One noisy performance: (note F1, step F1, mean onset error of the matched notes, or None)."""
    report = rollout(env, NoisyPianist(pianist, sigma, part, seed=start), seed=EVAL_SEED + start).report()
    return report.f1, report.step_f1, report.onset_error_mean


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("song", nargs="?", default="examples/midi/three-note.mid")
    parser.add_argument("--sigmas", type=float, nargs="+", default=[0.0, 0.02, 0.05, 0.1])
    parser.add_argument("--starts", type=int, default=4, help="hand starts per setting")
    parser.add_argument("--control", choices=["velocity", "position"], default="velocity")
    args = parser.parse_args()

    env_config = TrainConfig().env
    env_config = replace(env_config, world=replace(env_config.world, control=args.control))
    piece = load_part(Path(args.song), LoadOptions(), HandSpec())
    env = make_env(split_phrases(piece)[0].piece(), env_config)
    pianist = ScriptedPianist(env_config)
    print(
        f"{Path(args.song).name}, first phrase, {args.starts} hand starts, {args.control} control; "
        "action noise N(0, sigma) on [-1, 1] actions\n"
    )
    print(
        "| noise on | sigma | note F1 (mean) | note F1 per start | step F1 | mean onset error of matched notes (ms) |"
    )
    print("| --- | ---: | ---: | --- | ---: | ---: |")
    for sigma in args.sigmas:
        for part in PARTS if sigma > 0 else ("all",):
            runs = [play(env, pianist, sigma, part, start) for start in range(args.starts)]
            f1s = [r[0] for r in runs]
            onsets = [r[2] for r in runs if r[2] is not None]
            onset = f"{1000 * np.mean(onsets):.0f}" if onsets else "n/a"
            per_start = " ".join(f"{f:.2f}" for f in f1s)
            print(
                f"| {part} | {sigma:g} | {np.mean(f1s):.2f} | {per_start} | {np.mean([r[1] for r in runs]):.2f} | {onset} |",
                flush=True,
            )
    env.close()


if __name__ == "__main__":
    main()
