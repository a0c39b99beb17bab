"""Fine-tuning from the general policy: wall time per phrase until its evaluation reaches note F1 >= 0.95, on unseen phrases.

    python benchmarks/finetune.py [--general DIR] [--learner sac|dagger] [--steps N] [--round-steps N]
                                  [--melodies 20] [--seed 2027] [--workers 2] [--json out.json]

The phrases: those of the example songs that have no policy of their own (mary, ode-to-joy,
c-major-scale, split as ``pianobot train`` splits them), and ``--melodies`` phrases of the
``melody`` task family drawn with generators seeded ``[--seed, index]`` (training draws from the
environment's generator, seeded from the run's seed). Each phrase is trained as ``pianobot train
song.mid`` trains a phrase, from the general policy (evaluated first, at step 0, on the 3
evaluation hand starts), stopping at the first evaluation at note F1 >= ``--until-f1`` (0.95) or
after ``--steps``, with one torch thread, ``--workers`` phrases at a time (one per core).

What it measures is the training run's own evaluation, nothing more. Per phrase it prints the
note F1 of the step-0 evaluation and of the kept policy's evaluation, wall time and steps, then
the median wall time, counting a phrase whose kept evaluation never reached the target as slower
than any that did. The kept policy is the best evaluated, the step-0 one included, so its F1
is never below the start's; and "reached" is judged on the same evaluation hand starts that
chose it. Neither says how the phrase plays from other hand starts or in its piece: that is
``pianobot train``'s last step (``pianobot/learn/accept.py``: the whole piece from ``play``'s
hand starts 0-2), which this benchmark does not run.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np

from pianobot.agent.general import find_general
from pianobot.agent.policy import policy_configs
from pianobot.agent.tasks import draw_melody
from pianobot.learn.config import DaggerConfig, TrainConfig
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.phrases import DEFAULT_MAX_NOTES, split_phrases
from pianobot.music.piece import Piece
from pianobot.pianist.fingering import ensure_fingering

SONGS = ("mary", "ode-to-joy", "c-major-scale")
"""Example songs without committed policies."""


def phrases(examples: Path, melodies: int, seed: int, env) -> list[tuple[str, Piece]]:
    out = []
    for song in SONGS:
        piece = ensure_fingering(load_piece(examples / f"{song}.mid", LoadOptions()), KeyboardSpec(), HandSpec())[0]
        seen = set()
        for phrase in split_phrases(piece, DEFAULT_MAX_NOTES):
            if phrase.hash not in seen:  # a repeated phrase is trained once
                seen.add(phrase.hash)
                out.append((f"{song} phrase {phrase.index}", phrase.piece()))
    out += [(f"melody #{i}", draw_melody(np.random.default_rng([seed, i]), env)) for i in range(melodies)]
    return out


def fine_tune(name: str, piece: Piece, config: TrainConfig, general: Path, folder: Path) -> dict:
    import torch

    from pianobot.learn.jobs import learner

    torch.set_num_threads(1)
    began = time.perf_counter()
    manifest = learner(config)(piece, config, folder, start=general)
    seconds = time.perf_counter() - began
    return {
        "phrase": name,
        "notes": len(piece),
        "start_f1": manifest["evaluations"][0]["f1"],
        "kept_f1": manifest["evaluation"]["f1"],  # the best evaluated, step 0 included
        "reached": manifest["evaluation"]["f1"] >= config.stop_f1,
        "seconds": round(seconds, 1),
        "steps": manifest["steps"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--general", type=Path, help="the general policy's folder (default: the newest in --models)")
    parser.add_argument("--models", type=Path, default=Path("models"))
    parser.add_argument("--examples", type=Path, default=Path("examples/midi"))
    parser.add_argument("--learner", default="sac", choices=("sac", "dagger"))
    parser.add_argument("--steps", type=int, default=TrainConfig.steps, help="most steps per phrase")
    parser.add_argument("--round-steps", type=int, default=DaggerConfig.round_steps, help="DAgger's steps per round")
    parser.add_argument("--until-f1", type=float, default=0.95)
    parser.add_argument("--melodies", type=int, default=20)
    parser.add_argument("--seed", type=int, default=2027)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json")
    args = parser.parse_args()
    general = find_general(args.models, path=args.general)
    if general is None:
        raise SystemExit(f"no general policy in {args.models}")
    env, sac = policy_configs(general)
    config = TrainConfig(
        steps=args.steps,
        learner=args.learner,
        until_f1=args.until_f1,
        sac=sac,
        env=env,
        dagger=replace(DaggerConfig(), round_steps=args.round_steps),
    )
    todo = phrases(args.examples, args.melodies, args.seed, env)
    with tempfile.TemporaryDirectory() as scratch, ProcessPoolExecutor(args.workers) as pool:
        futures = [
            pool.submit(fine_tune, name, piece, config, general, Path(scratch) / str(i))
            for i, (name, piece) in enumerate(todo)
        ]
        rows = [f.result() for f in futures]
    print(f"general policy {general}, learner {args.learner}, at most {args.steps} steps, target F1 {args.until_f1}")
    print(
        "note F1 on the evaluation hand starts: at step 0, and the kept policy's (the best evaluated, step 0 included)\n"
    )
    print("| phrase | notes | F1 at step 0 | F1 kept | wall time (s) | steps |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        mark = "" if r["reached"] else " (not reached)"
        print(
            f"| {r['phrase']} | {r['notes']} | {r['start_f1']:.3f} | {r['kept_f1']:.3f} | {r['seconds']:.0f}{mark} | {r['steps']} |"
        )
    times = sorted(r["seconds"] if r["reached"] else float("inf") for r in rows)
    median = np.median(times)
    median = f"{median:.0f} s" if np.isfinite(median) else "not reached: more than half never got there"
    reached = sum(r["reached"] for r in rows)
    at_start = sum(r["start_f1"] >= args.until_f1 for r in rows)
    print(
        f"\n{len(rows)} phrases: the kept policy's evaluation reached F1 >= {args.until_f1} on the hand starts that "
        f"chose it for {reached} ({at_start} at step 0); median wall time {median}. Not judged here: other hand "
        "starts, or the phrase in its piece (pianobot train does that)"
    )
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"general": str(general), "learner": args.learner, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
