"""Simulator speed: env steps/s without and with touch, where a step's time goes, tactile frames/s.

    python benchmarks/sim.py [--repeats 5] [--peer-python /path/to/python] [--no-profile]

Each figure is the median of ``--repeats`` runs on the same work:
- env steps/s: the scripted pianist's actions for examples/midi/twinkle.mid are recorded once,
  then replayed open-loop (the simulator is deterministic, so every replay makes the same
  contacts), without and with the fingertips' tactile images; once on the paper's keyboard (24
  keys, C4-B5) and once on a whole piano's (88 keys, A0-C8) with the hand put where it played;
- the profile of one control step (one replay with touch per keyboard): the step's wall time
  split into phases by timers put around the simulator's and the environment's functions for
  that replay (:class:`Phases`; a function called inside another is counted in its own phase
  only), in microseconds per control step; "other" is what no timer covers (the Python of
  ``env.step`` and ``world.step`` themselves);
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
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import numpy as np

import pianobot.env.piano as piano
import pianobot.sim.world as world_module
from pianobot.env.piano import EnvConfig, PianoEnv, idle_pose
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.load import load_piece
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.keyboard import KeyboardConfig, KeySensor, key_x
from pianobot.sim.tactile import TactileConfig, TactileRenderer

ROOT = Path(__file__).resolve().parent.parent
PAPER = KeyboardSpec()
PIANO = KeyboardSpec(lowest=21, count=88)


def record(piece):
    """The scripted pianist's actions, the wrist's start, and every fingertip state with contact."""
    config = EnvConfig(tactile=False)
    env = PianoEnv(piece=piece, config=config)
    pianist = ScriptedPianist(config)
    observation, _ = env.reset(seed=0)
    wrist = env.world.hand_state()[0]
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
    return actions, wrist, touching, renderer


def replay_env(piece, wrist: float, tactile: bool, keyboard: KeyboardSpec) -> PianoEnv:
    """An env reset with the hand where the recording started it, over ``keyboard``."""
    base = EnvConfig(tactile=tactile)
    config = replace(base, world=replace(base.world, keyboard=KeyboardConfig(spec=keyboard)))
    env = PianoEnv(piece=piece, config=config)
    env.reset(seed=0)
    shift = key_x(config.world.keyboard, PAPER.lowest) - key_x(KeyboardConfig(), PAPER.lowest)
    env.world.reset(wrist + shift, np.tile(idle_pose(config.world), env.n_fingers))
    return env


def env_rate(piece, actions, wrist, tactile: bool, keyboard: KeyboardSpec = PAPER) -> float:
    env = replay_env(piece, wrist, tactile, keyboard)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    rate = len(actions) / (time.perf_counter() - start)
    env.close()
    return rate


class Phases:
    """Wall time by phase: timers put around functions (exclusive: time spent in another timed
    function called inside is counted there, not twice)."""

    def __init__(self):
        self.totals: dict[str, float] = defaultdict(float)
        self._inner: list[float] = []
        self._undo: list[tuple[object, str, object]] = []

    def time(self, owner, name: str, phase: str) -> None:
        original = getattr(owner, name)

        def timed(*args, **kwargs):
            start = time.perf_counter()
            self._inner.append(0.0)
            try:
                return original(*args, **kwargs)
            finally:
                spent = time.perf_counter() - start
                self.totals[phase] += spent - self._inner.pop()
                if self._inner:
                    self._inner[-1] += spent

        self._undo.append((owner, name, original))
        setattr(owner, name, timed)

    def restore(self) -> None:
        for owner, name, original in reversed(self._undo):
            setattr(owner, name, original)
        self._undo.clear()


PHASES = {
    "physics (stepSimulation: contacts, solver)": [(world_module.p, "stepSimulation")],
    "finger motors": [(world_module.PianoWorld, "_apply_action"), (world_module.PianoWorld, "_drive_fingers")],
    "keys (springs, sensor, state reads)": [
        (world_module.PianoWorld, "_update_keys"),
        (world_module.PianoWorld, "key_state"),
        (world_module.PianoWorld, "touching"),
        (world_module.PianoWorld, "_colour_keys"),
        (KeySensor, "update"),
    ],
    "tactile images": [(PianoEnv, "_tactile_image")],
    "observation": [(PianoEnv, "_observe")],
    "reward": [(piano, "reward_terms"), (PianoEnv, "_fingertip_distances")],
}


def profile(piece, actions, wrist, keyboard: KeyboardSpec) -> dict[str, float]:
    """Microseconds per control step by phase, for one replay with touch."""
    env = replay_env(piece, wrist, True, keyboard)
    phases = Phases()
    for phase, functions in PHASES.items():
        for owner, name in functions:
            phases.time(owner, name, phase)
    try:
        start = time.perf_counter()
        for action in actions:
            env.step(action)
        total = time.perf_counter() - start
    finally:
        phases.restore()
        env.close()
    out = {phase: phases.totals[phase] for phase in PHASES}
    out["other (Python of env.step, world.step)"] = total - sum(out.values())
    out["total"] = total
    return {phase: 1e6 * seconds / len(actions) for phase, seconds in out.items()}


def tactile_rate(renderer, touching) -> float:
    start = time.perf_counter()
    for state in touching:
        renderer.image(*state)
    return len(touching) / (time.perf_counter() - start)


def peer_rates(python: str, steps: int, repeats: int) -> list[float] | None:
    run = subprocess.run(
        [python, str(ROOT / "benchmarks" / "peer_robopianist.py"), str(steps), str(repeats)],
        capture_output=True,
        text=True,
        env={"MUJOCO_GL": "egl", "PATH": "/usr/bin:/bin"},
    )
    if run.returncode != 0:
        print(f"peer RoboPianist did not run: {run.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
        return None
    return [float(x) for x in run.stdout.split()]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--peer-python", help="a Python with robopianist installed")
    parser.add_argument("--no-profile", action="store_true", help="skip the profile of a step")
    args = parser.parse_args()

    piece = load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    actions, wrist, touching, renderer = record(piece)
    touch = "env steps/s, touch"
    figures = {
        "env steps/s, no touch, 24 keys": [env_rate(piece, actions, wrist, False) for _ in range(args.repeats)],
        f"{touch}, 24 keys": [env_rate(piece, actions, wrist, True) for _ in range(args.repeats)],
        f"{touch}, 88 keys": [env_rate(piece, actions, wrist, True, PIANO) for _ in range(args.repeats)],
        "tactile frames/s under contact (60x80)": [tactile_rate(renderer, touching) for _ in range(args.repeats)],
    }
    peer = "RoboPianist env steps/s (peer: two hands, 88 keys)"
    if args.peer_python:
        rates = peer_rates(args.peer_python, len(actions), args.repeats)
        if rates:
            figures[peer] = rates

    print(
        f"{len(actions)} control steps per replay, {len(touching)} fingertip frames in contact, {args.repeats} repeats\n"
    )
    print("| figure | median | runs |")
    print("| --- | ---: | --- |")
    for name, values in figures.items():
        print(f"| {name} | {statistics.median(values):.0f} | {', '.join(f'{v:.0f}' for v in values)} |")
    if peer in figures:
        for keys in ("24 keys", "88 keys"):
            ratio = statistics.median(figures[f"{touch}, {keys}"]) / statistics.median(figures[peer])
            print(f"\npianobot with touch, one hand over {keys} / RoboPianist: {ratio:.2f}x")

    if not args.no_profile:
        profiles = {k.describe(): profile(piece, actions, wrist, k) for k in (PAPER, PIANO)}
        print("\nWhere a control step's time goes (µs per step, one replay with touch, timers on):\n")
        print("| phase | " + " | ".join(profiles) + " |")
        print("| --- | " + " | ".join("---:" for _ in profiles) + " |")
        for phase in next(iter(profiles.values())):
            cells = [f"{p[phase]:.0f} ({100 * p[phase] / p['total']:.0f} %)" for p in profiles.values()]
            print(f"| {phase} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
