"""Learning curves: evaluation note F1 against environment steps, per task and seed.

    python benchmarks/learn.py --tasks one-note three-note --seeds 0 1 2 --steps 100000 \
        [--explore prior] [--no-tactile] [--control position] [--workers 2] [--plot docs/learning.png] [--store /tmp/learn]
    python benchmarks/learn.py ... --report    # no training: the runs so far, finished or not
    python benchmarks/learn.py ... --report --check   # and what unfinished runs' best policies play

Trains with `pianobot.learn.train.train_policy` (checkpointed: rerunning the same command resumes),
evaluating every ``--eval-every`` steps on ``--eval-episodes`` fixed instances (hand starts
and notes). A run stopped by ``--until-f1`` stopped on the first evaluation that reached it, a
figure that flatters; so the kept policy then plays ``--check-episodes`` instances it was never
evaluated on, and that F1 is the one to quote. Prints a Markdown table of the final figures and
the wall-clock time per policy, and draws the curves.
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from pianobot.agent import store
from pianobot.agent.config import SACConfig
from pianobot.agent.policy import load_policy, make_agent
from pianobot.env.piano import EnvConfig
from pianobot.learn.config import TrainConfig, config_from_manifest
from pianobot.learn.train import TASK_EVAL_EPISODES, best_policy_tensors, evaluate, make_env, train_policy
from pianobot.sim.world_config import CONTROL_MODES, WorldConfig

CHECK_SEED = 20_000
"""Seeds of the held-out check's instances (the training evaluations use 10000, 10001, ...)."""
CHECK_FILE = "check.json"
"""The held-out check's figures, written beside the policy."""


def run_folder(task: str, seed: int, args) -> tuple[TrainConfig, Path]:
    """The run's configuration and the folder its checkpoint and policy go to."""
    config = TrainConfig(
        steps=args.steps,
        seed=seed,
        explore=args.explore,
        eval_every=args.eval_every,
        eval_episodes=args.eval_episodes,
        checkpoint_every=args.eval_every,
        until_f1=args.until_f1,
        sac=SACConfig(exploration_steps=args.exploration_steps),
        env=EnvConfig(
            tactile=args.tactile,
            actuated=tuple(args.joints.split(",")),
            world=WorldConfig(control=args.control),
        ),
    )
    return config, store.model_dir(Path(args.store), f"task-{task}-seed{seed}", config)


def run(task: str, seed: int, args) -> tuple[str, int, dict]:
    import torch

    torch.set_num_threads(1)
    config, folder = run_folder(task, seed, args)
    manifest = (
        store.read_manifest(folder)
        if store.is_trained(folder)
        else train_policy(task, config, folder, about={"key": f"task-{task}", "piece": f"task {task}"})
    )
    held = check(task, folder, manifest, args.check_episodes)
    (folder / CHECK_FILE).write_text(json.dumps(held) + "\n")
    return task, seed, {**manifest, "check": held}


def check(task: str, folder: Path, manifest: dict, episodes: int) -> dict:
    """The kept policy on ``episodes`` fresh instances of the task."""
    env_config = config_from_manifest(manifest).env
    agent = load_policy(folder, make_env(task, env_config))
    return {"episodes": episodes, **evaluate(agent, task, env_config, episodes, first_seed=CHECK_SEED)}


def check_so_far(task: str, seed: int, args) -> dict | None:
    """The best policy an unfinished run has kept so far (in its checkpoint), on the same fresh
    instances as :func:`check`; None if it has none yet. Reads the checkpoint a running run
    writes (atomically) and changes nothing."""
    config, folder = run_folder(task, seed, args)
    found = store.load_checkpoint(folder)
    if found is None or found[1].get("best") is None:
        return None
    tensors, state, _ = found
    env_config = config.env
    agent = make_agent(make_env(task, env_config), config.sac)
    agent.load_tensors(best_policy_tensors(tensors), with_training_state=False)
    figures = evaluate(agent, task, env_config, args.check_episodes, first_seed=CHECK_SEED)
    return {"episodes": args.check_episodes, "step": state["best"]["step"], **figures}


def progress(task: str, seed: int, args) -> dict | None:
    """What a run has so far, without training: its manifest once finished (with the check when
    the full command wrote it), else its last checkpoint's evaluations; None if not started."""
    _, folder = run_folder(task, seed, args)
    if store.is_trained(folder):
        held = folder / CHECK_FILE
        return {
            **store.read_manifest(folder),
            "finished": True,
            **({"check": json.loads(held.read_text())} if held.exists() else {}),
        }
    state = store.checkpoint_state(folder)
    return None if state is None else {**state, "finished": False}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tasks", nargs="+", default=["one-note", "three-note"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--exploration-steps", type=int, default=SACConfig.exploration_steps)
    parser.add_argument("--eval-every", type=int, default=5_000)
    parser.add_argument("--eval-episodes", type=int, default=TASK_EVAL_EPISODES)
    parser.add_argument("--explore", default=TrainConfig.explore)
    parser.add_argument(
        "--check-episodes", type=int, default=30, help="fresh instances the kept policy plays at the end"
    )
    parser.add_argument("--until-f1", type=float, default=None, help="stop a run once an evaluation reaches this F1")
    parser.add_argument("--tactile", action=argparse.BooleanOptionalAction, default=True)
    parser.add_argument("--control", choices=CONTROL_MODES, default=WorldConfig.control, help="finger joint control")
    parser.add_argument("--joints", default=",".join(EnvConfig.actuated), help="finger joints the policy moves")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--store", default="/tmp/pianobot-learn")
    parser.add_argument("--plot", default=None)
    parser.add_argument("--report", action="store_true", help="train nothing: print and plot what the runs have so far")
    parser.add_argument(
        "--check",
        action="store_true",
        help="with --report: unfinished runs' best policies so far play the new instances too",
    )
    args = parser.parse_args()

    jobs = [(task, seed) for task in args.tasks for seed in args.seeds]
    if args.report:
        report(args, jobs)
        return
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        results = list(pool.map(run, *zip(*jobs), [args] * len(jobs)))

    print(
        f"steps {args.steps}, exploration {args.explore} for {args.exploration_steps} steps, tactile {args.tactile}\n"
    )
    print(
        f"| task | seed | last note F1 | kept note F1 (step) | kept, on {args.check_episodes} new instances: note F1 | velocity MAE | minutes |"
    )
    print("| --- | ---: | ---: | --- | ---: | ---: | ---: |")
    for task, seed, manifest in results:
        last, kept, held = (
            manifest["evaluations"][-1],
            manifest["evaluation"],
            manifest["check"],
        )  # training keeps the best evaluated policy
        mae = "n/a" if held["velocity_mae"] is None else f"{held['velocity_mae']:.1f}"
        print(
            f"| {task} | {seed} | {last['f1']:.3f} | {kept['f1']:.3f} ({kept['step']}) | {held['f1']:.3f} | {mae} | {manifest['seconds'] / 60:.1f} |"
        )

    if args.plot:
        plot(args, results)
    Path(args.store).mkdir(parents=True, exist_ok=True)
    (Path(args.store) / "results.json").write_text(
        json.dumps([{"task": t, "seed": s, **m} for t, s, m in results], default=str)
    )


def report(args, jobs: list[tuple[str, int]]) -> None:
    """The runs' evaluations so far, finished or not (``--report``)."""
    results = []
    print("| task | seed | state | evaluation note F1 at each evaluation | best (step) | on new instances | minutes |")
    print("| --- | ---: | --- | --- | --- | ---: | ---: |")
    for task, seed in jobs:
        found = progress(task, seed, args)
        if found is None:
            print(f"| {task} | {seed} | not started | | | | |")
            continue
        results.append((task, seed, found))
        curve = " / ".join(f"{e['f1']:.2f}" for e in found["evaluations"])
        best = found.get("evaluation") or found.get(
            "best"
        )  # the kept policy's figures (training's choice, ties broken on return)
        kept = "" if best is None else f"{best['f1']:.2f} ({best['step'] // 1000}k)"
        held = f"{found['check']['f1']:.2f}" if "check" in found else ""
        if not found["finished"] and args.check and (so_far := check_so_far(task, seed, args)) is not None:
            held = f"{so_far['f1']:.2f} (best so far, {so_far['step'] // 1000}k)"
        state = "finished" if found["finished"] else f"at {found['step'] // 1000}k steps"
        print(f"| {task} | {seed} | {state} | {curve} | {kept} | {held} | {found['seconds'] / 60:.1f} |")
    if args.plot and results:
        plot(args, results)


def plot(args, results: list[tuple[str, int, dict]]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    colours = dict(zip(args.tasks, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    labelled = set()
    for task, _, manifest in results:
        points = manifest["evaluations"]
        ax.plot(
            [p["step"] for p in points],
            [p["f1"] for p in points],
            color=colours[task],
            alpha=0.8,
            marker=".",
            label=None if task in labelled else task,
        )
        labelled.add(task)
    ax.axhline(0.9, color="grey", linestyle=":", linewidth=1)
    ax.set_xlabel("environment steps")
    ax.set_ylabel(f"evaluation note F1 ({args.eval_episodes} instances)")
    ax.set_ylim(-0.02, 1.02)
    ax.legend()
    ax.set_title(
        f"SAC, exploration '{args.explore}', tactile {'on' if args.tactile else 'off'}, seeds {', '.join(map(str, args.seeds))}"
    )
    fig.tight_layout()
    fig.savefig(args.plot, dpi=100)
    print(f"\nplot: {args.plot}")


if __name__ == "__main__":
    main()
