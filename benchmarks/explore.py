"""What the exploration before learning plays (docs/paper.md, "9. Why plain SAC does not learn
here"): episodes of a task family played by an exploration (learn/explore.py) with no learning,
beside the idle hand and the scripted pianist, in the paper setting's environment (linear reward
with the fingering gate, no closeness bonus, the score window; without touch, which no
exploration reads).

    python -m benchmarks.explore [--task one-note] [--episodes 200] [--joints abd,mcp,pip,dip]
                                 [--explore prior] [--seed 0]

The players: the idle hand, each ``--explore``, and (with every joint moved) the ``scripted``
exploration, the scripted pianist with noise (ours). Prints one Markdown row per player: the mean (and spread) of the episode's training reward, the
share of episodes that sound a note of the score at its time (note F1 above 0), the mean note
F1, and the notes sounded per episode. The task instances are seeds 1000, 1001, ...
"""

from __future__ import annotations

import argparse

import numpy as np

from pianobot.agent.tasks import make_env
from pianobot.env.piano import JOINT_KINDS, EnvConfig
from pianobot.env.rewards import RewardConfig
from pianobot.learn.explore import EXPLORATIONS, Explorer
from pianobot.perform.rollout import rollout


class Exploring:
    """An exploration as a controller (``reset``, ``act``); ``idle`` holds every joint still."""

    def __init__(self, kind: str, size: int, config: EnvConfig, seed: int):
        self.kind, self.size = kind, size
        self.explorer = None if kind == "idle" else Explorer(kind, size, config, np.random.default_rng(seed))

    def reset(self) -> None:
        if self.explorer is not None:
            self.explorer.reset()

    def act(self, observation: dict) -> np.ndarray:
        if self.explorer is None:
            return np.zeros(self.size, np.float32)
        return self.explorer.act(observation)


def play(task: str, kind: str, episodes: int, joints: tuple[str, ...], seed: int) -> dict:
    config = EnvConfig(
        reward=RewardConfig(closeness_weight=0.0), target_observations=False, tactile=False, actuated=joints
    )
    env = make_env(task, config)
    player = Exploring(kind, env.action_space.shape[0], config, seed)
    returns, f1s, sounded = [], [], []
    for episode in range(episodes):
        played = rollout(env, player, seed=1000 + episode)
        returns.append(played.total_reward)
        f1s.append(played.report().f1)
        sounded.append(len(played.played.notes))
    env.close()
    return {
        "return": float(np.mean(returns)),
        "spread": float(np.std(returns)),
        "hit": float(np.mean(np.array(f1s) > 0)),
        "f1": float(np.mean(f1s)),
        "sounded": float(np.mean(sounded)),
        "actions": env.action_space.shape[0],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--task", default="one-note")
    parser.add_argument("--episodes", type=int, default=200)
    parser.add_argument("--joints", default=",".join(JOINT_KINDS), help="the finger joints the actions move")
    parser.add_argument("--explore", nargs="+", default=["prior"], choices=EXPLORATIONS)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    joints = tuple(args.joints.split(","))
    print(f"{args.task}, {args.episodes} episodes, finger joints {', '.join(joints)}")
    print()
    print(
        "| player | actions | training reward per episode | episodes with a note of the score | note F1 | notes sounded per episode |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    if joints != JOINT_KINDS and "scripted" in args.explore:
        parser.error("--explore scripted moves every finger joint: leave out --joints")
    players = ("idle", *args.explore) + (("scripted",) if joints == JOINT_KINDS else ())  # (it moves every joint)
    for kind in dict.fromkeys(players):
        figures = play(args.task, kind, args.episodes, joints, args.seed)
        print(
            f"| {kind} | {figures['actions']} | {figures['return']:.2f} ± {figures['spread']:.2f} | "
            f"{figures['hit']:.0%} | {figures['f1']:.3f} | {figures['sounded']:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
