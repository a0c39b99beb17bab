"""The wrist guard (pianobot/perform/guard.py): a policy's wrist slides no faster than the scripted
pianist's while a fingertip is low over the keys, and nothing else of its action changes."""

from pathlib import Path

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, actuated_indices, idle_pose
from pianobot.music.load import LoadOptions, load_piece
from pianobot.perform.guard import WristGuard
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.pianist.tuning import PianistTuning
from pianobot.sim.hand import finger_ik
from pianobot.sim.world import WorldConfig

EXAMPLES = Path(__file__).parent.parent / "examples" / "midi"
CONFIG = EnvConfig(tactile=False)


class Constant:
    """A policy that always asks for the same action."""

    def __init__(self, action):
        self.action = np.asarray(action, dtype=np.float32)
        self.resets = 0

    def reset(self):
        self.resets += 1

    def act(self, observation):
        return self.action


def observation_with(height: float | None, config: EnvConfig = CONFIG) -> dict:
    """The hand at rest, its second finger's tip ``height`` (m) over the white keys' top, 40 mm in
    from their front (None: left at rest)."""
    world = config.world
    fingers = len(world.hand.spec.fingers)
    joints = np.tile(idle_pose(world), (fingers, 1))
    if height is not None:
        hand = world.hand
        reach = hand.palm_y - (world.keyboard.geometry.white_length - 0.040)
        flexion = finger_ik(hand.geometry, reach, hand.palm_height - height)
        assert flexion is not None
        joints[1, 1:] = flexion
    return {"joints": joints.reshape(-1).astype(np.float32)}


def test_the_wrist_is_slowed_only_while_a_fingertip_is_low():
    actions = len(actuated_indices(CONFIG))
    limit = PianistTuning().hold_slide * CONFIG.world.control_hz / CONFIG.world.hand.max_wrist_speed
    assert limit == pytest.approx(0.16)  # 8 mm a step of the top speed's 50 mm
    for wrist in (1.0, -0.9):
        asked = np.full(actions, 0.3, dtype=np.float32)
        asked[-1] = wrist
        guard = WristGuard(Constant(asked), CONFIG)
        resting = guard.act(observation_with(None))  # fingertips 10 mm up: the wrist goes as asked
        assert np.array_equal(resting, asked) and guard.capped == 0
        low = guard.act(observation_with(0.001))  # a fingertip 1 mm over the keys: it could drag one
        assert low[-1] == pytest.approx(np.sign(wrist) * limit) and guard.capped == 1
        assert np.array_equal(low[:-1], asked[:-1])  # the fingers' actions untouched
        assert asked[-1] == wrist  # the policy's own array is not written to
    slow = np.zeros(actions, dtype=np.float32)
    slow[-1] = 0.1
    guard = WristGuard(Constant(slow), CONFIG)
    assert guard.act(observation_with(0.001))[-1] == pytest.approx(0.1) and guard.capped == 0
    guard.reset()
    assert guard.policy.resets == 1


@pytest.mark.parametrize(
    "config",
    [
        EnvConfig(tactile=False, actuated=("mcp", "pip")),  # 2 joints a finger: the wrist is still the last action
        EnvConfig(tactile=False, world=WorldConfig(control="position")),  # the wrist is driven by speed in every mode
        EnvConfig(tactile=False, world=WorldConfig(control="torque")),
    ],
)
def test_the_guard_clips_the_wrist_whatever_the_joints_and_control(config):
    actions = len(actuated_indices(config))
    asked = np.full(actions, 0.5, dtype=np.float32)
    asked[-1] = 1.0
    guard = WristGuard(Constant(asked), config)
    low = guard.act(observation_with(0.001, config))
    assert low[-1] == pytest.approx(0.16) and np.array_equal(low[:-1], asked[:-1])


def test_the_scripted_pianist_plays_the_scale_unslowed_by_the_guard():
    """The guard holds a policy to its teacher's own limit: the teacher plays on unchanged."""
    piece = load_piece(EXAMPLES / "c-major-scale.mid", LoadOptions())
    guards = []

    def guarded(env):
        guards.append(WristGuard(ScriptedPianist(env.config), env.config))
        return guards[-1]

    result = perform(piece, guarded, PLAY_CONFIG)
    assert result.report().f1 == 1.0 and guards[0].capped == 0


def test_a_wrist_that_goes_to_keys_is_refused():
    config = EnvConfig(tactile=False, world=WorldConfig(discrete_wrist=True))
    with pytest.raises(ValueError, match="discrete_wrist"):
        WristGuard(Constant(np.zeros(17)), config)
