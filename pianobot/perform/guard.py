"""Guards: the scripted pianist's hand on a learnt policy's, where the policy is known to slip.

The hold guard (:class:`HoldGuard`): a finger that holds a written note moves as the scripted
pianist (the policy's teacher) would move it, and every other joint as the policy asks. A policy
cloned from the teacher loses most of a hand's part with held notes there: while one voice holds
a key and another moves, the holding finger slides onto the key beside it or strikes its own
again (docs/benchmarks.md, "Two hands"). The teacher keeps a held key down, wherever the policy
takes the wrist, for as long as the score says, and lets it go when its own plan would; the
policy still strikes every note and moves the wrist, but for one stretch: while a finger holds
and no finger's next note starts within :data:`QUIET_STEPS`, the teacher moves the wrist too
(alone over a long held chord, the policy's wrist drifted towards the next one and dragged the
holding fingers onto the keys beside theirs). The policy has the wrist back in time for every
strike. With the pianist's hand, a held key the teacher has let up (its fingertip
:attr:`~pianobot.pianist.tuning.PianistTuning.let_up_height` over it) stays up until its note ends:
pressed again, it would sound twice; a key let go less far is pressed on, so a key the policy's
wrist drew out of reach only briefly is held again (docs/history.md). The Allegro-like hand's guard
presses every held key on. Before a repeat of a held key the guard's teacher lets it go as the
packaged policies' teacher did when they learnt, rising to the ready height over the key
(:attr:`~pianobot.pianist.tuning.PianistTuning.repeat_rise` off), for the policy strikes the repeat
and learnt to strike it from there; the scripted pianist, playing alone, lets go later and strikes it
again from just over where the key let its note go (docs/history.md). Likewise it lets held keys go for a
strike alone at its onset once the wrist must begin to slide for it
(:attr:`~pianobot.pianist.tuning.PianistTuning.lone_strike_wrist_steps` 0), where the scripted pianist
alone holds them a step longer (through the guard, the packaged policy played the corpus's validation
excerpts at 0.879 that way, against 0.885), and it holds a key at full depth to its note's end
(:attr:`~pianobot.pianist.tuning.PianistTuning.end_rise` off), where the scripted pianist lets it rise a
little in the last step (through the guard, the packaged policy's per-step F1 and offsets rose with it,
its note F1 moved by 0.002 or less on the validation sets, and one two-hand example fell below 0.97:
docs/history.md). ``pianobot play`` plays a general policy of
the families in :data:`HOLD_GUARD_FAMILIES` through it (the packaged left hand's policy), and
any general policy with ``--hold-guard``; ``--no-hold-guard`` plays each alone. A phrase's own
policy plays unguarded.

The wrist guard (:class:`WristGuard`): a learnt policy's wrist slides no faster than its teacher's while a fingertip is low.

A policy cloned from the scripted pianist learns its switch from "hold the key and ease the wrist
along" to "let go, rise, then rush to the next position" blurred by a control step: it starts the
rush while its finger is still on the key and drags the finger across the neighbouring keys,
which sound. The scripted pianist slides the wrist at most
:attr:`~pianobot.pianist.tuning.PianistTuning.hold_slide` a step while a finger holds a key, and
not at all while a finger that let go is still low over the keys
(:meth:`~pianobot.pianist.motion.Motion.low`); only during a strike may it go faster, which it
rarely does (docs/benchmarks.md, "What the wrist guard and one section change"). The guard
holds a policy to ``hold_slide`` whenever a fingertip is low, from the joint angles in the
observation alone, and leaves every other action as the policy chose it. It makes a drag less
likely, not impossible: a fingertip low over the keys may still slide 8 mm a step.

``pianobot play --wrist-guard`` plays the general policy through it (a phrase's own policy,
trained on its phrase until perfect, plays unguarded). It is off by default: the committed
general policy plays as well without it (docs/benchmarks.md), and unguarded it plays as
training evaluated it; a general policy that drags keys while the hand shifts plays better with it.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from pianobot.agent import store
from pianobot.env.piano import EnvConfig, actuated_indices, finger_counts
from pianobot.music.tensor import FINGER, NOTE
from pianobot.perform.rollout import Controller
from pianobot.pianist.layout import KeyLayout
from pianobot.pianist.motion import Motion
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.pianist.tuning import PianistTuning, tuning_for

QUIET_STEPS = PianistTuning.prepare_steps + PianistTuning.settle_steps
"""While a finger holds and no finger's next note starts within this many control steps, the hold
guard's teacher moves the wrist: the least time the teacher gives a finger to get ready for a
strike (it lifts, moves over the key and settles). Chosen on validation sets (docs/benchmarks.md,
"Two hands")."""
HOLD_GUARD_FAMILIES = ("parts",)
"""Task families whose general policies play through the hold guard unless told otherwise: the
``parts`` policy, which learnt from the teacher that holds its notes, plays better through it, the
``melody`` policy, which learnt from the teacher before it held its notes, better alone (chosen on
validation sets: docs/benchmarks.md, "Two hands")."""


class HoldGuard:
    """Wraps ``policy`` (a :class:`~pianobot.perform.rollout.Controller`): the joints of every finger
    that holds a written note now (its finger target's last column, how much longer to hold, is
    above 0) take the scripted pianist's action, and so does the wrist while no finger's next note
    starts within :data:`QUIET_STEPS` (its target's column "how soon"); the rest of the action is the
    policy's.

    The hold is read from the observation's finger targets (``target_onsets``), which say it for
    the section's own window, the note before it included; the teacher is told exactly that (the
    holding fingers' notes began earlier, any other note sounding now begins now), so it plans the
    hand as it would have, had it played the piece itself, and holds, never strikes, a key it is
    handed."""

    def __init__(self, policy: Controller, config: EnvConfig, tuning: PianistTuning | None = None):
        if not self.fits(config):
            raise ValueError(
                "the hold guard reads which finger holds a note from the finger targets and drives joint speeds or "
                "angles: it needs target_observations, target_onsets and control 'velocity' or 'position'"
            )
        self.policy = policy
        # (as the packaged policies' teacher did when they learnt)
        tuning = replace(
            tuning or tuning_for(config.world.hand), repeat_rise=math.inf, lone_strike_wrist_steps=0, end_rise=math.inf
        )
        self.teacher = ScriptedPianist(config, tuning)
        joints = actuated_indices(config)[:-1]  # (then the wrist's, then with the pedal an action the foot's)
        self.wrist_at = len(joints)
        counts, _ = finger_counts(config)
        slot_of = np.repeat(np.arange(len(counts)), counts)  # every joint's finger slot, in command order
        self.joints_of = [np.flatnonzero(slot_of[joints] == i) for i in range(len(counts))]
        """Finger (its slot) -> where its actuated joints are in the action."""
        self.held = 0
        """Finger-steps the teacher moved, since the guard was made."""
        self.wrist = 0
        """Control steps in which the teacher moved the wrist, since the guard was made."""
        self.holding: dict[int, int] = {}
        """Finger (its slot) -> the key it held in the previous step."""
        self.lifted: set[tuple[int, int]] = set()
        """(slot, key) of the held notes whose key was let up: left up until the note ends."""

    def _let_up(self, observation: dict, row: np.ndarray, holding: np.ndarray) -> frozenset[tuple[int, int]]:
        """(finger, key) of the held notes whose fingertip has risen ``let_up_height`` over the key's top
        since the finger held it (the teacher is told they were let go, and leaves them up)."""
        if self.teacher.tuning.let_up_height == math.inf:
            return frozenset()
        joints = np.asarray(observation["joints"], dtype=float).reshape(len(self.joints_of), -1)
        held = {}
        for slot in holding:
            keys = np.flatnonzero((row[:, NOTE] > 0.5) & (row[:, FINGER + slot] > 0.5))
            if keys.size:
                held[int(slot)] = int(keys[-1])
        self.lifted = {(slot, key) for slot, key in self.lifted if held.get(slot) == key}  # (until the note ends)
        layout, motion = self.teacher.layout, self.teacher.motion
        for slot, key in held.items():
            if (
                self.holding.get(slot) == key
                and motion.tip(joints[slot]).height > layout.key_top[key] + self.teacher.tuning.let_up_height
            ):
                self.lifted.add((slot, key))
        self.holding = held
        return frozenset((self.teacher.fingers[slot], key) for slot, key in self.lifted)

    def _before(self, row: np.ndarray, holding: np.ndarray) -> np.ndarray:
        """The score row the teacher is told came before ``row``: the notes the ``holding`` fingers hold
        began earlier, and every other finger's note in ``row`` (if any) begins now. That is the
        truth wherever the guard takes over (the finger targets say which notes began earlier)."""
        before = row.copy()
        striking = [slot for slot in range(len(self.joints_of)) if slot not in holding]
        before[:, [FINGER + slot for slot in striking]] = 0.0
        return before

    @staticmethod
    def fits(config: EnvConfig) -> bool:
        """Whether a policy of ``config`` can be guarded: it observes its finger targets with their
        holds, and its fingers are driven by speed or angle, as the scripted pianist drives them."""
        return config.target_observations and config.target_onsets and config.world.control != "torque"

    def reset(self) -> None:
        self.policy.reset()
        self.teacher.reset()
        self.holding, self.lifted = {}, set()

    def act(self, observation: dict) -> np.ndarray:
        action = np.array(self.policy.act(observation), dtype=np.float32)  # a copy: the policy's own is left alone
        holding = np.flatnonzero(observation["targets"][:, -1] > 0)
        if holding.size:
            row = observation["score"][0]
            self.teacher.previous_row = self._before(row, holding)
            self.teacher.released = self._let_up(observation, row, holding)
            taught = self.teacher.act(observation)
            for slot in holding:
                action[self.joints_of[slot]] = taught[self.joints_of[slot]]
            self.held += holding.size
            steps = len(observation["score"])  # (the targets' "how soon": 1 now, falling by 1/steps a step)
            if not np.any(observation["targets"][:, 3] >= 1.0 - QUIET_STEPS / steps):
                action[self.wrist_at] = taught[self.wrist_at]
                self.wrist += 1
        else:  # (no note held: every let-up note has ended, a repeat of one included)
            self.holding, self.lifted = {}, set()
        return action


class WristGuard:
    """Wraps ``policy`` (a :class:`~pianobot.perform.rollout.Controller`): while any fingertip is
    low over the keys, the wrist's action is clipped to ``tuning.hold_slide`` a control step."""

    def __init__(self, policy: Controller, config: EnvConfig, tuning: PianistTuning | None = None):
        world = config.world
        if world.discrete_wrist:
            raise ValueError("the wrist guard limits the wrist's speed: it needs discrete_wrist=False")
        self.policy = policy
        tuning = tuning or tuning_for(world.hand)
        self.motion = Motion(world, KeyLayout(world), tuning)
        self.fingers = len(world.hand.spec.fingers)
        self.limit = tuning.hold_slide * world.control_hz / world.hand.max_wrist_speed
        """The wrist's largest action while a fingertip is low (its action is a share of the top speed)."""
        self.wrist_at = len(actuated_indices(config)) - 1
        self.capped = 0
        """Control steps in which the guard slowed the wrist, since the guard was made."""

    def reset(self) -> None:
        self.policy.reset()

    def act(self, observation: dict) -> np.ndarray:
        action = np.array(self.policy.act(observation), dtype=np.float32)  # a copy: the policy's own is left alone
        joints = np.asarray(observation["joints"], dtype=float).reshape(self.fingers, -1)
        wrist = self.wrist_at
        if abs(action[wrist]) > self.limit and any(self.motion.low(q) for q in joints):
            action[wrist] = np.sign(action[wrist]) * self.limit
            self.capped += 1
        return action


def guarded_family(general: Path | None) -> bool:
    """Whether the general policy in ``general`` was trained on a task family whose policies play
    through the hold guard unless told otherwise (:data:`~pianobot.perform.guard.HOLD_GUARD_FAMILIES`)."""
    return general is not None and store.read_manifest(Path(general)).get("target") in HOLD_GUARD_FAMILIES
