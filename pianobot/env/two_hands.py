"""Both hands in one simulation: each plays its part, seen by its player as a right hand.

:class:`HandsEnv` holds one world of two hands (:class:`~pianobot.sim.world.PianoWorld` with
``hands=("right", "left")``) over the keys both parts need, and one
:class:`~pianobot.env.piano.PianoEnv` per hand built on a :class:`~pianobot.sim.frame.HandView`
of it: each hand's observations, action and reward are made as the one-hand environment makes
them, in the hand's view (the left hand's mirrored), so every one-hand player (the scripted pianist, the
general policy, phrase policies) plays either hand unchanged. ``step`` takes an action per hand,
steps the world once with both, and gives each hand what it sees.

What the hands share: the keys (a key struck by one moves in the other's view too, and its touch
shows in the other's tactile images; each hand's reward counts only the keys it played itself)
and the space over the keyboard: the world keeps the right wrist at least
``PianoWorld.min_separation`` above the left one and the hands' links collide. Where a window
reaches past A0 or C8 (a player's 24 keys around a part near the piano's end), the world has
those keys too; no note is written on them.

Spaces are dicts keyed by hand ('right', 'left'); the reward is the sum of the hands'
(``info["rewards"]`` has each); ``info["hands"]`` holds each hand's step info, and ``info``
also the world's key events with the finger and hand of each strike, and whether the sustain
pedal was down (``info["pedal"]``). The foot works the piece's written ``pedal``; with
``pedal_action`` it is an action beside the hands' (``"pedal"``: above 0 holds it down), and the
written pedal is observed (``"pedal"``: now and the lookahead's steps ahead).

Version: :data:`pianobot.env.VERSION`, as :mod:`pianobot.env.piano`'s (v1 the first with two
hands, on v1's physics); no id is registered with gymnasium (a two-hand piece's parts need the fingering planner and the windows, above this layer:
:func:`pianobot.perform.together.play_hands` builds one).
"""

from __future__ import annotations

from dataclasses import replace

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from pianobot.env.piano import EnvConfig, PianoEnv
from pianobot.music.instrument import KeyboardSpec
from pianobot.music.pedal import Pedal
from pianobot.music.piece import HANDS, Piece
from pianobot.music.window import Window
from pianobot.sim.frame import HandView
from pianobot.sim.world import PianoWorld, WorldConfig


def world_keyboard(windows: list[Window]) -> KeyboardSpec:
    """The fewest keys of a world on which every window's keys lie: from the lowest to the highest
    of them, at most the piano's 88."""
    pitches = [w.outward(q) for w in windows for q in (w.keyboard.lowest, w.keyboard.lowest + w.keyboard.count - 1)]
    low, high = min(pitches), max(pitches)
    if high - low + 1 > 88:
        raise ValueError(
            f"the hands' keyboards span {high - low + 1} keys together, more than a piano's 88: "
            "the parts lie too far apart to be played in one simulation"
        )
    return KeyboardSpec(lowest=low, count=high - low + 1)


class HandsEnv(gym.Env):
    """Each hand of ``parts`` (hand -> (window, part)) plays its part, given in its window's keys
    (:meth:`~pianobot.music.window.Window.inward`: the left hand's mirrored) and fingered for it,
    in one world; ``configs``: each hand's environment (its keyboard is replaced by its window's;
    the hands' physics settings must agree); ``keyboard``: the world's keys (default: the fewest
    that hold both windows', :func:`world_keyboard`). Both parts run as long as the longer one."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": WorldConfig.control_hz}
    FRAME = (720, 320)
    """A rendered frame's width and height: wide, for a keyboard of up to 88 keys."""

    def __init__(
        self,
        parts: dict[str, tuple[Window, Piece]],
        configs: dict[str, EnvConfig],
        render_mode: str | None = None,
        keyboard: KeyboardSpec | None = None,
        pedal: Pedal | None = None,
        pedal_action: bool = False,
    ):
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode {render_mode!r}: choose None or 'rgb_array'")
        self.render_mode = render_mode
        if set(parts) != set(HANDS) or set(configs) != set(HANDS):
            raise ValueError(f"give a part and a configuration for each of {', '.join(HANDS)}")
        windows = [parts[h][0] for h in HANDS]
        if any(parts[h][0].hand != h for h in HANDS):
            raise ValueError("each hand's part needs that hand's window")
        worlds = {
            replace(configs[h].world, keyboard=replace(configs[h].world.keyboard, spec=KeyboardSpec()), gui=False)
            for h in HANDS
        }
        if len(worlds) > 1:
            raise ValueError("both hands' environments must share their physics (control, rates, hand, keys, solver)")
        if len({(configs[h].lead_in, configs[h].tail) for h in HANDS}) > 1:
            raise ValueError("both hands' environments must share their lead-in and tail (one timeline)")
        if any(configs[h].pedal_action for h in HANDS):
            raise ValueError("one foot works the pedal for both hands: give HandsEnv pedal_action, not a hand")
        if configs["right"].world.discrete_wrist:
            raise ValueError(
                "a discrete wrist picks among the world's keys, not a hand's view's: use a continuous wrist"
            )
        base = configs["right"].world
        world_config = replace(base, keyboard=replace(base.keyboard, spec=keyboard or world_keyboard(windows)))
        self.world = PianoWorld(world_config, hands=HANDS)
        length = max(parts[h][1].duration for h in HANDS)
        self.hands: dict[str, PianoEnv] = {}
        try:
            for index, hand in enumerate(HANDS):
                window, part = parts[hand]
                view = HandView(self.world, index, window)
                config = replace(configs[hand], world=replace(view.config, gui=False))
                self.hands[hand] = PianoEnv(piece=part, config=config, length=length, view=view, pedal=pedal)
        except Exception:
            self.world.close()
            raise
        self.pedal_action = pedal_action
        foot = {"pedal": spaces.Box(-1.0, 1.0, (1,), np.float32)} if pedal_action else {}
        written = {"pedal": spaces.Box(0.0, 1.0, (configs["right"].lookahead + 1,), np.float32)} if pedal_action else {}
        self.observation_space = spaces.Dict({**{h: env.observation_space for h, env in self.hands.items()}, **written})
        self.action_space = spaces.Dict({**{h: env.action_space for h, env in self.hands.items()}, **foot})
        self.horizon = self.hands["right"].horizon
        self.score_start = self.hands["right"].score_start

    def view(self, hand: str) -> HandView:
        return self.hands[hand].world

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Each hand starts where its environment draws it (seeded with ``seed``), moved apart
        where the two would be closer than the world allows."""
        super().reset(seed=seed)
        wrists = {h: self.view(h).world_wrist(env.draw_start(seed)) for h, env in self.hands.items()}
        right, left = self._apart(wrists["right"], wrists["left"])
        self.world.reset([right, left], np.concatenate([self.hands[h].start_pose() for h in HANDS]))
        self.holders: dict[int, str] = {}
        """World pitch -> the hand whose strike sounds it now."""
        firsts = {h: env.begin() for h, env in self.hands.items()}
        return self._with_pedal({h: obs for h, (obs, _) in firsts.items()}), {
            "pieces": {h: info["piece"] for h, (_, info) in firsts.items()}
        }

    def _apart(self, right: float, left: float) -> tuple[float, float]:
        """Wrist starts at least ``min_separation`` apart (each moved half the shortfall, within the rail)."""
        gap, width = self.world.min_separation, self.world.width
        short = gap - (right - left)
        if short > 0:
            right, left = right + short / 2, left - short / 2
            if left < 0:
                right, left = right - left, 0.0
            if right > width:
                right, left = width, left - (right - width)
        return right, left

    def _with_pedal(self, observations: dict) -> dict:
        """The hands' observations, and with the foot an action the written pedal ahead."""
        if self.pedal_action:
            right = self.hands["right"]
            observations["pedal"] = right.pedal_score[right.t : right.t + right.config.lookahead + 1].copy()
        return observations

    def step(self, action: dict):
        self.pedal_down = bool(action["pedal"][0] > 0) if self.pedal_action else self.hands["right"].foot()
        full = np.concatenate(
            [
                self.view(h).world_action(env.full_action(np.asarray(action[h], dtype=np.float64)))
                for h, env in self.hands.items()
            ]
        )
        result = self.world.step(full)
        struck = {pitch: HANDS[h] for pitch, h in result.hands.items()}
        for event in result.events:  # a strike no fingertip was touching: the nearer hand's
            if event.on and event.pitch not in struck:
                struck[event.pitch] = self._nearer(event.pitch)
        played = {**self.holders, **struck}  # who played each key that sounded in this step
        for event in result.events:
            if event.on:
                self.holders[event.pitch] = struck[event.pitch]
            else:
                self.holders.pop(event.pitch, None)
        observations, rewards, infos = {}, {}, {}
        truncated = True
        for hand, env in self.hands.items():
            env.pedal_down = self.pedal_down
            others = {pitch for pitch, by in played.items() if by != hand}
            observations[hand], rewards[hand], _, done, infos[hand] = env.absorb(self.view(hand).result(result, others))
            truncated = truncated and done
        info = {
            "hands": infos,
            "rewards": rewards,
            "events": result.events,
            "fingers": result.fingers,
            "struck_by": struck,
            "pedal": self.pedal_down,
        }
        return self._with_pedal(observations), float(sum(rewards.values())), False, truncated, info

    def _nearer(self, pitch: int) -> str:
        x = self.world.boxes[pitch - self.world.config.keyboard.spec.lowest].center[0]
        distances = [abs(self.world.hand_state(i)[0] - x) for i in range(len(HANDS))]
        return HANDS[int(np.argmin(distances))]

    def render(self) -> np.ndarray | None:
        """The whole keyboard and both hands from above the pianist (height x width x 3, uint8)
        with ``render_mode="rgb_array"``; else None and a warning, as gymnasium's environments do."""
        if self.render_mode is None:
            gym.logger.warn(
                'render() is called without a render mode: make the environment with render_mode="rgb_array"'
            )
            return None
        return self.world.render(*self.FRAME)

    def close(self):
        self.world.close()
