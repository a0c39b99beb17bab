"""Simulator speed: env steps/s without and with tactile images, and tactile frames/s.

    python benchmarks/sim.py [--repeats 5] [--peer-python /path/to/python]

Each figure is the median of ``--repeats`` runs on the same work:
- env steps/s: the scripted pianist's actions for examples/midi/twinkle.mid are recorded once,
  then replayed open-loop (the simulator is deterministic, so every replay makes the same
  contacts), without and with the three fingertips' tactile images;
- tactile frames/s: the renderer alone, on every fingertip state of that performance in which
  the fingertip touches a key (one core);
- the peer RoboPianist's env steps/s with random actions, when ``--peer-python`` names a Python
  that has robopianist installed (run in the same session, so the ratio compares like with like).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.load import load_piece
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.tactile import TactileConfig, TactileRenderer

ROOT = Path(__file__).resolve().parent.parent


def record(piece):
    """The scripted pianist's actions, and every fingertip state with contact, for one performance."""
    config = EnvConfig(tactile=False)
    env = PianoEnv(piece=piece, config=config)
    pianist = ScriptedPianist(config)
    observation, _ = env.reset(seed=0)
    actions, touching = [], []
    while True:
        action = pianist.act(observation)
        actions.append(action)
        observation, _, _, truncated, _ = env.step(action)
        forces = env.world.tip_forces()
        angles, _ = env.world.key_state()
        for finger, link in env.world.tip_links.items():
            if forces[finger] > 0:
                position, rotation = env.world.link_pose(link)
                touching.append((position, rotation, angles.copy(), forces[finger]))
        if truncated:
            break
    renderer = TactileRenderer(TactileConfig(), config.world.hand.geometry, env.world.boxes)
    env.close()
    return actions, touching, renderer


def env_rate(piece, actions, tactile: bool) -> float:
    env = PianoEnv(piece=piece, config=EnvConfig(tactile=tactile))
    env.reset(seed=0)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    rate = len(actions) / (time.perf_counter() - start)
    env.close()
    return rate


def tactile_rate(renderer, touching) -> float:
    start = time.perf_counter()
    for state in touching:
        renderer.image(*state)
    return len(touching) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--peer-python", help="a Python with robopianist installed")
    args = parser.parse_args()

    piece = load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    actions, touching, renderer = record(piece)
    figures = {
        "env steps/s, no tactile": [env_rate(piece, actions, False) for _ in range(args.repeats)],
        "env steps/s, tactile (3 fingertips)": [env_rate(piece, actions, True) for _ in range(args.repeats)],
        "tactile frames/s under contact (60x80)": [tactile_rate(renderer, touching) for _ in range(args.repeats)],
    }
    if args.peer_python:
        run = subprocess.run(
            [args.peer_python, str(ROOT / "benchmarks" / "peer_robopianist.py"), str(len(actions)), str(args.repeats)],
            capture_output=True,
            text=True,
            env={"MUJOCO_GL": "egl", "PATH": "/usr/bin:/bin"},
        )
        if run.returncode == 0:
            figures["RoboPianist env steps/s (peer)"] = [float(x) for x in run.stdout.split()]
        else:
            print(f"peer RoboPianist did not run: {run.stderr.strip().splitlines()[-1:]}", file=sys.stderr)

    print(
        f"{len(actions)} control steps per replay, {len(touching)} fingertip frames in contact, {args.repeats} repeats\n"
    )
    print("| figure | median | runs |")
    print("| --- | ---: | --- |")
    for name, values in figures.items():
        print(f"| {name} | {statistics.median(values):.0f} | {', '.join(f'{v:.0f}' for v in values)} |")
    if "RoboPianist env steps/s (peer)" in figures:
        ratio = statistics.median(figures["env steps/s, tactile (3 fingertips)"]) / statistics.median(
            figures["RoboPianist env steps/s (peer)"]
        )
        print(f"\npianobot with tactile images / RoboPianist: {ratio:.2f}x")


if __name__ == "__main__":
    main()
