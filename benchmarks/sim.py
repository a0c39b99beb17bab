"""Simulator speed: env steps/s without and with touch, where a step's time goes, tactile frames/s.

    python benchmarks/sim.py [--repeats 5] [--peer-python /path/to/python] [--no-profile]

Each figure is the median of ``--repeats`` runs on the same work:
- env steps/s: the scripted pianist's actions for examples/midi/twinkle.mid are recorded once,
  then replayed open-loop (the simulator is deterministic, so every replay makes the same
  contacts), without and with the fingertips' tactile images; once on the paper's keyboard (24
  keys, C4-B5) and once on a whole piano's (88 keys, A0-C8) with the hand put where it played;
  and two hands over 88 keys in the two-hand environment (:func:`two_hands`: each hand's
  observations, tactile images included, the left hand playing the right's mirror image);
- the profile of one control step (one replay with touch per keyboard): the step's wall time
  split into phases by timers put around the simulator's and the environment's functions for
  that replay (:class:`Phases`; a function called inside another is counted in its own phase
  only), in microseconds per control step; "other" is what no timer covers (the Python of
  ``env.step`` and ``world.step`` themselves);
- play's real-time factor: the scripted pianist performing ``--play`` (default the longest
  one-hand example, mary.mid) as ``pianobot play --controller scripted`` does after start-up;
- play's real-time factor for both hands: the scripted pianist performing both hands of
  ``--play-hands`` (default the longest two-hand example, nocturne-performed.mid) as ``pianobot
  play --controller scripted`` does after start-up (:func:`~pianobot.perform.together.play_hands`:
  each part mirrored, moved, reduced and fingered, both hands in one simulation, the
  performance scored);
- tactile frames/s: the renderer alone, on every fingertip state of that performance in which
  the fingertip touches a key (one core);
- the peer RoboPianist's env steps/s with random actions, when ``--peer-python`` names a Python
  that has robopianist installed (run in the same session, so the ratio compares like with like).

The figures are measured round by round (each once a round, the peer's among them), and the
ratios to the peer are the medians of each round's ratio.
"""

from __future__ import annotations

import argparse
import math
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

import numpy as np

import pianobot.env.piano as piano
import pianobot.sim.world as world_module
from pianobot.env.piano import EnvConfig, PianoEnv, idle_pose
from pianobot.env.two_hands import HandsEnv
from pianobot.errors import PianobotWarning
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.load import load_piece
from pianobot.music.window import Window
from pianobot.perform.perform import perform
from pianobot.perform.together import play_hands, read_hands
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.keyboard import KeyboardConfig, KeySensor, key_x
from pianobot.sim.tactile import TactileConfig, TactileRenderer

ROOT = Path(__file__).resolve().parent.parent
PAPER = KeyboardSpec()
PIANO = KeyboardSpec(lowest=21, count=88)
PLAY = ROOT / "examples" / "midi" / "mary.mid"
"""The longest one-hand example (19 s)."""
PLAY_HANDS = ROOT / "examples" / "midi" / "nocturne-performed.mid"
"""The longest two-hand example (55.5 s)."""
TWO = "env steps/s, touch, two hands, 88 keys"


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


def two_hands(piece, wrist: float) -> HandsEnv:
    """Two hands over 88 keys in the two-hand environment, reset as the recording started: the
    right hand's part on C4-B5, the left hand's its mirror image over the mirrored keys an octave
    lower (F1-E3), each hand's observations (tactile images included) made at every step."""
    config = EnvConfig(tactile=True)
    windows = {"right": Window("right", PAPER, 0), "left": Window("left", PAPER, -1)}
    env = HandsEnv({h: (w, piece) for h, w in windows.items()}, {h: config for h in windows}, keyboard=PIANO)
    env.reset(seed=0)
    starts = [env.view(h).world_wrist(wrist) for h in ("right", "left")]
    env.world.reset(starts, np.tile(idle_pose(config.world), 6))
    return env


def two_hand_rate(piece, actions, wrist) -> float:
    env = two_hands(piece, wrist)
    start = time.perf_counter()
    for action in actions:
        env.step({"right": action, "left": action})  # (the left's, in its view, is the right's)
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


def profile(piece, actions, wrist, keyboard: KeyboardSpec | None) -> dict[str, float]:
    """Microseconds per control step by phase, for one replay with touch: one hand over
    ``keyboard`` in the environment, or (None) two hands over 88 keys (:func:`two_hands`)."""
    stepper = replay_env(piece, wrist, True, keyboard) if keyboard else two_hands(piece, wrist)
    phases = Phases()
    for phase, functions in PHASES.items():
        for owner, name in functions:
            phases.time(owner, name, phase)
    try:
        start = time.perf_counter()
        for action in actions:
            stepper.step(action if keyboard else {"right": action, "left": action})
        total = time.perf_counter() - start
    finally:
        phases.restore()
        stepper.close()
    out = {phase: phases.totals[phase] for phase in PHASES}
    out["other (Python of env.step, world.step)"] = total - sum(out.values())
    out["total"] = total
    return {phase: 1e6 * seconds / len(actions) for phase, seconds in out.items()}


def tactile_rate(renderer, touching) -> float:
    start = time.perf_counter()
    for state in touching:
        renderer.image(*state)
    return len(touching) / (time.perf_counter() - start)


def play_factor(path: Path) -> float:
    """Real-time factor of the scripted pianist playing ``path`` as `pianobot play --controller
    scripted` does after start-up (the environment built, the whole piece performed)."""
    piece = load_piece(path)
    start = time.perf_counter()
    perform(piece, "scripted")
    return piece.duration / (time.perf_counter() - start)


def play_hands_factor(path: Path) -> float:
    """Real-time factor of the scripted pianist playing both hands of ``path`` as `pianobot play
    --controller scripted` does after start-up: timed from after the file is read and its notes
    given to the hands, its parts prepared, performed in one simulation and scored."""
    piece = read_hands(path).piece
    with tempfile.TemporaryDirectory() as models, warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)  # what the reduction left out: not a speed matter
        start = time.perf_counter()
        play_hands(piece, "scripted", models)
        return piece.duration / (time.perf_counter() - start)


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
    parser.add_argument("--play", type=Path, default=PLAY, help="the piece of the real-time factor figure")
    parser.add_argument(
        "--play-hands",
        type=Path,
        default=PLAY_HANDS,
        help="the two-hand piece of the real-time factor figure for both hands",
    )
    args = parser.parse_args()

    import mir_eval  # noqa: F401  (the scoring's import is start-up: once, before any round)

    piece = load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    actions, wrist, touching, renderer = record(piece)
    touch = "env steps/s, touch"
    peer = "RoboPianist env steps/s (peer: two hands, 88 keys)"
    measures = {
        "env steps/s, no touch, 24 keys": lambda: env_rate(piece, actions, wrist, False),
        f"{touch}, 24 keys": lambda: env_rate(piece, actions, wrist, True),
        f"{touch}, 88 keys": lambda: env_rate(piece, actions, wrist, True, PIANO),
        TWO: lambda: two_hand_rate(piece, actions, wrist),
        "tactile frames/s under contact (60x80)": lambda: tactile_rate(renderer, touching),
        f"play's real-time factor, scripted pianist, {args.play.name}": lambda: play_factor(args.play),
        f"play's real-time factor, both hands, scripted pianist, {args.play_hands.name}": lambda: play_hands_factor(
            args.play_hands
        ),
    }
    if args.peer_python:
        measures[peer] = lambda: (peer_rates(args.peer_python, len(actions), 1) or [float("nan")])[0]
    # round by round, every figure once a round: a shared machine's load changes over minutes,
    # and the figures of one round (the peer's among them) see the same load
    figures: dict[str, list[float]] = {name: [] for name in measures}
    for _ in range(args.repeats):
        for name, measure in measures.items():
            figures[name].append(measure())
    if peer in figures and any(math.isnan(v) for v in figures[peer]):
        del figures[peer]

    print(
        f"{len(actions)} control steps per replay, {len(touching)} fingertip frames in contact, {args.repeats} repeats\n"
    )
    print("| figure | median | runs |")
    print("| --- | ---: | --- |")
    for name, values in figures.items():
        digits = 1 if "factor" in name else 0
        cells = ", ".join(f"{v:.{digits}f}" for v in values)
        print(f"| {name} | {statistics.median(values):.{digits}f} | {cells} |")
    if peer in figures:
        print()
        for name in (f"{touch}, 24 keys", f"{touch}, 88 keys", TWO):
            ratios = [ours / theirs for ours, theirs in zip(figures[name], figures[peer])]
            print(f"{name} / RoboPianist, median of the rounds' ratios: {statistics.median(ratios):.2f}x")

    if not args.no_profile:
        profiles = {f"one hand, {k.count} keys": profile(piece, actions, wrist, k) for k in (PAPER, PIANO)}
        profiles["two hands, 88 keys"] = profile(piece, actions, wrist, None)
        print("\nWhere a control step's time goes (µs per step, one replay with touch, timers on):\n")
        print("| phase | " + " | ".join(profiles) + " |")
        print("| --- | " + " | ".join("---:" for _ in profiles) + " |")
        for phase in next(iter(profiles.values())):
            cells = [f"{p[phase]:.0f} ({100 * p[phase] / p['total']:.0f} %)" for p in profiles.values()]
            print(f"| {phase} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
