"""Simulator speed: env steps/s without and with touch, where a step's time goes, tactile frames/s.

    python benchmarks/sim.py [--repeats 5] [--peer-python /path/to/python] [--no-profile] [--hand-model M ...]

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

Every figure but the tactile renderer's and the peer's is measured for each ``--hand-model``
(default: every model, the Allegro-like hand and the pianist's hand), its default fingers
playing; a hand whose fingers the piece's own fingering does not name plays the planner's
fingering for them (:func:`~pianobot.pianist.fingering.plan_fingering`). With more than one model,
the profile also says what one finger costs a control step: the pianist's hand with its three
middle fingers (2, 3, 4) beside all five, both playing the planner's fingering.

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
from functools import partial
from pathlib import Path

import numpy as np

import pianobot.env.piano as piano
import pianobot.sim.world as world_module
from pianobot.env.piano import EnvConfig, PianoEnv, idle_pose
from pianobot.env.two_hands import HandsEnv
from pianobot.errors import PianobotWarning
from pianobot.music.instrument import HandSpec, KeyboardSpec
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.window import Window
from pianobot.perform.plan import perform_plan, plan_performance
from pianobot.perform.together import play_hands, read_hands
from pianobot.pianist.fingering import plan_fingering
from pianobot.pianist.reading import read_piece
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.hand import HAND_MODELS, default_fingers, hand_config
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


def with_hand(config: EnvConfig, spec: HandSpec) -> EnvConfig:
    """``config`` with the hand ``spec`` names."""
    return replace(config, world=replace(config.world, hand=hand_config(spec)))


def fingered(piece, spec: HandSpec, keyboard: KeyboardSpec = PAPER):
    """``piece`` as its file fingers it where that names only ``spec``'s fingers, else as the
    fingering planner fingers it for that hand."""
    if all(n.finger in spec.fingers for n in piece.notes):
        return piece
    return plan_fingering(piece.without_fingering(), KeyboardConfig(spec=keyboard), hand_config(spec)).piece


def record(piece, spec: HandSpec = HandSpec()):
    """The scripted pianist's actions, the wrist's start, and every fingertip state with contact."""
    config = with_hand(EnvConfig(tactile=False), spec)
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


def replay_env(piece, wrist: float, tactile: bool, keyboard: KeyboardSpec, spec: HandSpec = HandSpec()) -> PianoEnv:
    """An env reset with the hand where the recording started it, over ``keyboard``."""
    base = with_hand(EnvConfig(tactile=tactile), spec)
    config = replace(base, world=replace(base.world, keyboard=KeyboardConfig(spec=keyboard)))
    env = PianoEnv(piece=piece, config=config)
    env.reset(seed=0)
    shift = key_x(config.world.keyboard, PAPER.lowest) - key_x(KeyboardConfig(), PAPER.lowest)
    env.world.reset(wrist + shift, np.tile(idle_pose(config.world), env.n_fingers))
    return env


def env_rate(
    piece, actions, wrist, tactile: bool, keyboard: KeyboardSpec = PAPER, spec: HandSpec = HandSpec()
) -> float:
    env = replay_env(piece, wrist, tactile, keyboard, spec)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    rate = len(actions) / (time.perf_counter() - start)
    env.close()
    return rate


def two_hands(piece, wrist: float, spec: HandSpec = HandSpec()) -> HandsEnv:
    """Two hands over 88 keys in the two-hand environment, reset as the recording started: the
    right hand's part on C4-B5, the left hand's its mirror image over the mirrored keys an octave
    lower (F1-E3), each hand's observations (tactile images included) made at every step."""
    config = with_hand(EnvConfig(tactile=True), spec)
    windows = {"right": Window("right", PAPER, 0), "left": Window("left", PAPER, -1)}
    env = HandsEnv({h: (w, piece) for h, w in windows.items()}, {h: config for h in windows}, keyboard=PIANO)
    env.reset(seed=0)
    starts = [env.view(h).world_wrist(wrist) for h in ("right", "left")]
    env.world.reset(starts, np.tile(idle_pose(config.world), 2 * len(spec.fingers)))
    return env


def two_hand_rate(piece, actions, wrist, spec: HandSpec = HandSpec()) -> float:
    env = two_hands(piece, wrist, spec)
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


def profile(piece, actions, wrist, keyboard: KeyboardSpec | None, spec: HandSpec = HandSpec()) -> dict[str, float]:
    """Microseconds per control step by phase, for one replay with touch: one hand over
    ``keyboard`` in the environment, or (None) two hands over 88 keys (:func:`two_hands`)."""
    stepper = replay_env(piece, wrist, True, keyboard, spec) if keyboard else two_hands(piece, wrist, spec)
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


def play_factor(path: Path, spec: HandSpec = HandSpec()) -> float:
    """Real-time factor of the scripted pianist playing ``path`` with the hand ``spec`` names as
    `pianobot play --controller scripted` does after start-up: timed from after the file is read
    and fingered (:func:`~pianobot.pianist.reading.read_piece`, as `play` reads it), the environment
    built and the whole piece performed."""
    read = read_piece(path, LoadOptions(), fingers=spec, both=False, quiet=True, model=spec.model)
    plan = plan_performance(read.piece, "scripted", keyboard=read.keyboard, hand=read.fingers)
    start = time.perf_counter()
    perform_plan(plan)
    return read.piece.duration / (time.perf_counter() - start)


def play_hands_factor(path: Path, spec: HandSpec = HandSpec()) -> float:
    """Real-time factor of the scripted pianist playing both hands of ``path`` as `pianobot play
    --controller scripted` does after start-up: timed from after the file is read and its notes
    given to the hands, its parts prepared, performed in one simulation and scored."""
    piece = read_hands(path, LoadOptions(), spec).piece
    with tempfile.TemporaryDirectory() as models, warnings.catch_warnings():
        warnings.simplefilter("ignore", PianobotWarning)  # what the reduction left out: not a speed matter
        start = time.perf_counter()
        play_hands(piece, "scripted", models, hand=spec)
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
    parser.add_argument(
        "--hand-model",
        nargs="+",
        choices=tuple(HAND_MODELS),
        default=list(HAND_MODELS),
        help="the hand models measured, each with its default fingers (default: every one)",
    )
    args = parser.parse_args()

    import mir_eval  # noqa: F401  (the scoring's import is start-up: once, before any round)

    twinkle = load_piece(ROOT / "examples" / "midi" / "twinkle.mid")
    hands = {model: default_fingers(model) for model in args.hand_model}
    pieces = {model: fingered(twinkle, spec) for model, spec in hands.items()}
    recordings = {model: record(pieces[model], spec) for model, spec in hands.items()}
    touch = "env steps/s, touch"
    peer = "RoboPianist env steps/s (peer: two hands, 88 keys)"
    measures: dict[tuple[str, str], object] = {}
    for model, spec in hands.items():
        piece, (actions, wrist, _, _) = pieces[model], recordings[model]
        measures.update(
            {
                ("env steps/s, no touch, 24 keys", model): partial(env_rate, piece, actions, wrist, False, PAPER, spec),
                (f"{touch}, 24 keys", model): partial(env_rate, piece, actions, wrist, True, PAPER, spec),
                (f"{touch}, 88 keys", model): partial(env_rate, piece, actions, wrist, True, PIANO, spec),
                (TWO, model): partial(two_hand_rate, piece, actions, wrist, spec),
                (f"play's real-time factor, scripted pianist, {args.play.name}", model): partial(
                    play_factor, args.play, spec
                ),
                (f"play's real-time factor, both hands, scripted pianist, {args.play_hands.name}", model): partial(
                    play_hands_factor, args.play_hands, spec
                ),
            }
        )
    first = next(iter(hands))
    _, _, touching, renderer = recordings[first]
    measures["tactile frames/s under contact (60x80)", first] = partial(tactile_rate, renderer, touching)
    if args.peer_python:
        steps = len(recordings[first][0])
        measures[peer, "peer"] = lambda: (peer_rates(args.peer_python, steps, 1) or [float("nan")])[0]
    # round by round, every figure once a round: a shared machine's load changes over minutes,
    # and the figures of one round (the peer's among them) see the same load
    figures: dict[tuple[str, str], list[float]] = {name: [] for name in measures}
    for _ in range(args.repeats):
        for name, measure in measures.items():
            figures[name].append(measure())
    if (peer, "peer") in figures and any(math.isnan(v) for v in figures[peer, "peer"]):
        del figures[peer, "peer"]

    steps = {model: len(recording[0]) for model, recording in recordings.items()}
    print(f"control steps per replay: {steps}; {len(touching)} fingertip frames in contact; {args.repeats} repeats\n")
    print("| figure | hand | median | runs |")
    print("| --- | --- | ---: | --- |")
    for (name, model), values in figures.items():
        digits = 1 if "factor" in name else 0
        cells = ", ".join(f"{v:.{digits}f}" for v in values)
        print(f"| {name} | {model} | {statistics.median(values):.{digits}f} | {cells} |")
    if (peer, "peer") in figures:
        print()
        for model in hands:
            for name in (f"{touch}, 24 keys", f"{touch}, 88 keys", TWO):
                ratios = [ours / theirs for ours, theirs in zip(figures[name, model], figures[peer, "peer"])]
                print(f"{name}, {model} / RoboPianist, median of the rounds' ratios: {statistics.median(ratios):.2f}x")
    if len(hands) > 1:
        print()
        for name in (f"{touch}, 88 keys", TWO):
            models = list(hands)
            ratios = [b / a for a, b in zip(figures[name, models[0]], figures[name, models[1]])]
            print(f"{name}, {models[1]} / {models[0]}, median of the rounds' ratios: {statistics.median(ratios):.2f}x")

    if not args.no_profile:
        profiles = {}
        for model, spec in hands.items():
            piece, (actions, wrist, _, _) = pieces[model], recordings[model]
            profiles[f"{model}, one hand, 88 keys"] = profile(piece, actions, wrist, PIANO, spec)
            profiles[f"{model}, two hands, 88 keys"] = profile(piece, actions, wrist, None, spec)
        if len(hands) > 1 and "pianist" in hands:  # what a finger costs: three of the pianist's fingers beside five
            three = HandSpec(fingers=(2, 3, 4), model="pianist")
            piece = fingered(twinkle, three)
            actions, wrist, _, _ = record(piece, three)
            profiles["pianist, fingers 2-4, one hand, 88 keys"] = profile(piece, actions, wrist, PIANO, three)
        print("\nWhere a control step's time goes (µs per step, one replay with touch, timers on):\n")
        print("| phase | " + " | ".join(profiles) + " |")
        print("| --- | " + " | ".join("---:" for _ in profiles) + " |")
        for phase in next(iter(profiles.values())):
            cells = [f"{p[phase]:.0f} ({100 * p[phase] / p['total']:.0f} %)" for p in profiles.values()]
            print(f"| {phase} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
