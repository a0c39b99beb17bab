"""A phrase policy trained on an earlier simulator, trained again on today's (:data:`pianobot.env.VERSION`).

:func:`train_again` fine-tunes the policy with the learner and configuration its manifest
records, from its own weights (actor, encoder, and Q heads where it kept them), until an
evaluation plays the phrase perfectly from every evaluation hand start (``finetune_until_f1``,
1.0) or the recorded step budget is spent. The run is an ordinary fine-tuning run
(:mod:`pianobot.learn.train`): it evaluates its start first and stores a policy only where one
beat it. What happens to the old folder:

- a policy was trained: it is stored in the folder of its configuration (the phrase hash and
  the hash of the recorded configuration with ``until_f1`` cleared, since the run stops at
  perfect play), its manifest naming the old policy as its ``start``; the old folder goes;
- the start already played perfectly on today's simulator (its evaluation before any step): the
  old weights stay where they are, and their manifest records today's ``simulator`` with the
  evaluation that found it (``again``: the figures and when);
- nothing trained beat an imperfect start: nothing changes (the policy stays one of the earlier
  simulator, which ``play`` judges beside the general policy).

Run it as ``python -m pianobot.learn.again models/<folder> ...`` (``--steps`` caps the budget;
``--dagger-rounds N`` imitates the scripted pianist instead, as ``pianobot train --learner dagger`` does);
:func:`pianobot.perform.plan.plan_performance` plays a policy from an earlier simulator only
where it plays its stretch better than the general policy.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from dataclasses import replace
from datetime import datetime, timezone
from pathlib import Path

from pianobot.agent import store
from pianobot.agent.policy import policy_target
from pianobot.env import VERSION
from pianobot.errors import PianobotError
from pianobot.files import atomic_write
from pianobot.learn.config import config_from_manifest
from pianobot.learn.jobs import learner
from pianobot.music.piece import Piece


def train_again(
    folder: Path, steps: int | None = None, report=lambda progress: None, dagger_rounds: int | None = None
) -> Path:
    """Train the phrase policy in ``folder`` again on today's simulator (the module's notes);
    ``steps``: at most this many environment steps (default: the recorded budget);
    ``dagger_rounds``: learn by imitating the scripted pianist (DAgger, rounds of this many steps)
    instead of the recorded learner. Returns the folder that now holds the phrase's policy."""
    folder = Path(folder)
    manifest = store.read_manifest(folder)
    if manifest["simulator"] == VERSION:
        raise PianobotError(f"{folder} was trained on this simulator (v{VERSION}) already")
    target = policy_target(folder)
    if not isinstance(target, Piece):
        raise PianobotError(f"{folder} holds a task family's policy: train the family again with pianobot train --task")
    config = config_from_manifest(manifest)
    imitate = {}
    if dagger_rounds is not None:
        imitate = {"learner": "dagger", "dagger": replace(config.dagger, round_steps=dagger_rounds)}
    config = replace(
        config,
        until_f1=None,
        from_general=True,
        finetune_until_f1=1.0,
        envs=1,
        finish=False,
        steps=steps or config.steps,
        **imitate,
    )
    into = store.model_dir(folder.parent, manifest["key"], config)
    if into == folder:
        raise PianobotError(f"{folder} already stops at perfect play: train it again with pianobot train --force")
    about = {k: manifest[k] for k in ("key", "piece", "phrases") if k in manifest}
    result = learner(config)(target, config, into, report, about=about, start=folder)
    if result["kept"] == "trained":
        shutil.rmtree(folder)
        return into
    if into.exists():  # (a run that trained and kept its start leaves its manifest and log: the old folder stays)
        shutil.rmtree(into)
    if result["steps"] or result["evaluation"]["f1"] < config.finetune_until_f1:
        return folder
    again = {
        "evaluation": result["evaluation"],
        "saved": datetime.now(timezone.utc).isoformat(timespec="seconds"),
    }
    raw = json.loads((folder / store.MANIFEST_FILE).read_text())
    raw.update(simulator=VERSION, again=again)
    atomic_write(folder / store.MANIFEST_FILE, json.dumps(raw, indent=2, default=str) + "\n")
    return folder


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m pianobot.learn.again", description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path, help="phrase policy folders of a model store")
    parser.add_argument("--steps", type=int, default=None, help="at most this many steps each")
    parser.add_argument(
        "--dagger-rounds",
        type=int,
        default=None,
        help="imitate the scripted pianist (DAgger), rounds of this many steps",
    )
    args = parser.parse_args(argv)
    import torch

    torch.set_num_threads(1)

    def report(progress) -> None:
        if progress.eval_f1 is not None:
            print(f"  step {progress.step}: evaluation note F1 {progress.eval_f1:.3f}", flush=True)

    for folder in args.folders:
        print(f"{folder}: training again on simulator v{VERSION}", flush=True)
        try:
            now = train_again(folder, args.steps, report, args.dagger_rounds)
        except (PianobotError, ValueError) as e:
            print(f"{folder}: {e}", file=sys.stderr)
            continue
        if now != folder:
            print(f"{folder}: trained again, now {now}", flush=True)
        elif store.simulator(folder) == VERSION:
            print(f"{folder}: played its phrase perfectly on v{VERSION} before any step: kept as it was", flush=True)
        else:
            print(f"{folder}: nothing trained beat it: left on v{store.simulator(folder)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
