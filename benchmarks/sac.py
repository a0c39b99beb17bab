"""SAC gradient updates per second: pianobot's agent against Stable-Baselines3's SAC, same run.

    python benchmarks/sac.py [--repeats 5] [--updates 60] [--threads 1]
    python benchmarks/sac.py --compile      # ours with and without torch.compile instead

Both learn on the same environment (examples/midi/three-note.mid, state only and with tactile
images of 3 fingertips; Stable-Baselines3 without the score window when ours does not read it,
so that both see the same inputs) with batch size 256, from a replay buffer filled by 1000 random steps.
Each figure is the median of ``--repeats`` timings of ``--updates`` updates. Stable-Baselines3
is a benchmark-only dependency (`pip install stable-baselines3`).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
import torch

from pianobot.agent.buffer import ReplayBuffer
from pianobot.agent.config import SACConfig
from pianobot.agent.sac import SAC, score_size, vector_size
from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.load import load_piece

ROOT = Path(__file__).resolve().parent.parent
FILL = 1000


def make_env(tactile: bool) -> PianoEnv:
    return PianoEnv(piece=load_piece(ROOT / "examples" / "midi" / "three-note.mid"), config=EnvConfig(tactile=tactile))


def compile_agent(agent: SAC) -> SAC:
    """torch.compile (inductor) on every network pass an update makes: encoders, Q heads, actor."""
    for critic in (agent.critic, agent.target):
        critic.encoder.forward = torch.compile(critic.encoder.forward)
        critic.q = torch.compile(critic.q)
    agent.actor.forward = torch.compile(agent.actor.forward)
    return agent


def ours(tactile: bool, updates: int, repeats: int, compiled: bool = False) -> list[float]:
    env = make_env(tactile)
    space = env.observation_space
    shape = space["tactile"].shape if tactile else None
    config = SACConfig()
    agent = SAC(vector_size(space, config.score_input), score_size(space, config.score_input), shape, 13, config)
    if compiled:
        agent = compile_agent(agent)
    buffer = ReplayBuffer(FILL, vector_size(space, config.score_input), shape, 13)
    rng = np.random.default_rng(0)
    observation, _ = env.reset(seed=0)
    for _ in range(FILL):
        action = rng.uniform(-1, 1, 13).astype(np.float32)
        vector, images = agent.split(observation)
        observation, reward, terminated, truncated, _ = env.step(action)
        buffer.add(vector, images, action, reward, terminated, *agent.split(observation))
        if truncated:
            observation, _ = env.reset()
    for _ in range(5):
        agent.update(buffer.sample(256, rng))
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(updates):
            agent.update(buffer.sample(256, rng))
        rates.append(updates / (time.perf_counter() - start))
    return rates


PAPER_DEPTH = [256, 256, 256, 256]
"""Stable-Baselines3 hidden layers as deep as our networks: the paper's 2-layer encoder MLP then
2-layer heads (its default is [256, 256], half the work per network)."""


def stable_baselines(tactile: bool, updates: int, repeats: int, net_arch: list[int] | None = None) -> list[float]:
    from gymnasium.wrappers import FilterObservation
    from stable_baselines3 import SAC as SB3SAC

    env = make_env(tactile)
    if not SACConfig().score_input:  # the same inputs as ours: without the score window when ours skips it
        env = FilterObservation(env, [k for k in env.observation_space.spaces if k != "score"])
    kwargs = {} if net_arch is None else {"policy_kwargs": {"net_arch": net_arch}}
    model = SB3SAC(
        "MultiInputPolicy",
        env,
        **kwargs,
        batch_size=256,
        learning_starts=FILL,
        buffer_size=FILL + 10,
        device="cpu",
        seed=0,
    )
    model.learn(FILL)  # fills the buffer with random steps
    model.train(gradient_steps=5, batch_size=256)
    rates = []
    for _ in range(repeats):
        start = time.perf_counter()
        model.train(gradient_steps=updates, batch_size=256)
        rates.append(updates / (time.perf_counter() - start))
    return rates


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--updates", type=int, default=60)
    parser.add_argument("--threads", type=int, default=1, help="torch threads for both")
    parser.add_argument(
        "--compile", action="store_true", help="compare ours with torch.compile instead of Stable-Baselines3"
    )
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    if args.compile:
        compare_compile(args)
        return
    print(
        f"torch {torch.__version__}, {args.threads} thread(s), batch 256, {args.updates} updates x {args.repeats} repeats\n"
    )
    print(
        "| configuration | pianobot updates/s | Stable-Baselines3 updates/s, its default net | ratio | Stable-Baselines3, 4 x 256 like ours | ratio |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: |")

    def cell(rates: list[float]) -> str:
        return f"{statistics.median(rates):.1f} ({', '.join(f'{x:.1f}' for x in rates)})"

    for tactile in (False, True):
        mine = ours(tactile, args.updates, args.repeats)
        default = stable_baselines(tactile, args.updates, args.repeats)
        deep = stable_baselines(tactile, args.updates, args.repeats, PAPER_DEPTH)
        a = statistics.median(mine)
        label = "tactile (3 fingertips, 15x20)" if tactile else "state only"
        print(
            f"| {label} | {cell(mine)} | {cell(default)} | {a / statistics.median(default):.2f}x | {cell(deep)} | {a / statistics.median(deep):.2f}x |"
        )


def compare_compile(args) -> None:
    print(
        f"torch {torch.__version__}, {args.threads} thread(s), batch 256, {args.updates} updates x {args.repeats} repeats\n"
    )
    print("| configuration | eager updates/s | torch.compile updates/s | ratio |")
    print("| --- | ---: | ---: | ---: |")
    for tactile in (False, True):
        eager = ours(tactile, args.updates, args.repeats)
        compiled = ours(tactile, args.updates, args.repeats, compiled=True)  # compiles during its warm-up updates
        a, b = statistics.median(eager), statistics.median(compiled)
        label = "tactile (3 fingertips, 15x20)" if tactile else "state only"
        print(
            f"| {label} | {a:.1f} ({', '.join(f'{x:.1f}' for x in eager)}) | {b:.1f} ({', '.join(f'{x:.1f}' for x in compiled)}) | {b / a:.2f}x |"
        )


if __name__ == "__main__":
    main()
