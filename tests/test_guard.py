"""The guards (pianobot/perform/guard.py). The wrist guard: a policy's wrist slides no faster than
the scripted pianist's while a fingertip is low over the keys, and nothing else of its action
changes. The hold guard: a finger that holds a note moves as the scripted pianist moves it."""

from pathlib import Path

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, actuated_indices, idle_pose
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.piece import Note, Piece
from pianobot.perform.guard import HoldGuard, WristGuard
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


# -- the hold guard ------------------------------------------------------------------------------
LEGATO = Piece(
    (Note(0.0, 60, 1.0, 80, 2), Note(1.0, 62, 2.0, 80, 3), Note(2.0, 64, 3.0, 80, 4)), bpm=60
)  # three one-second notes, each finger in turn


class LetsGo:
    """The scripted pianist, but a finger that holds a note lifts at once (a policy that lets go early)."""

    def __init__(self, config):
        self.inner = ScriptedPianist(config)
        self.fingers = len(config.world.hand.spec.fingers)
        self.steps: list[tuple[dict, np.ndarray]] = []  # (observation, action) of every step

    def reset(self):
        self.inner.reset()

    def act(self, observation):
        action = np.array(self.inner.act(observation), dtype=np.float32)
        for slot in np.flatnonzero(observation["targets"][:, -1] > 0):
            action[4 * slot + 1] = -1.0  # the MCP joint up at full speed
        self.steps.append((observation, action.copy()))
        return action


def test_the_hold_guard_keeps_down_a_note_the_policy_lets_go():
    """Alone the policy taps each one-second note for two control steps; through the hold guard
    every note sounds for as long as it is written, struck when the policy struck it."""
    lengths = {}
    for guarded in (False, True):
        made = []

        def controller(env, guarded=guarded, made=made):
            made.append(HoldGuard(LetsGo(env.config), env.config) if guarded else LetsGo(env.config))
            return made[-1]

        played = perform(LEGATO, controller, PLAY_CONFIG)
        assert played.report().f1 == 1.0
        lengths[guarded] = [n.offset - n.onset for n in played.played.notes]
    assert max(lengths[False]) < 0.1
    assert min(lengths[True]) > 0.95 and made[0].held > 3 * 15  # each note held for most of its 20 steps


def test_the_hold_guard_changes_only_the_holding_fingers_joints():
    """On every step the guard's action is the policy's but for the joints of the fingers that hold a
    note, which are the scripted pianist's (told that the notes sounding now began earlier)."""
    made = []

    def controller(env):
        made.append(HoldGuard(LetsGo(env.config), env.config))
        return made[-1]

    perform(LEGATO, controller, PLAY_CONFIG)
    guard, teacher = made[0], ScriptedPianist(PLAY_CONFIG)
    holds = 0
    for observation, asked in guard.policy.steps:
        teacher.previous_row = observation["score"][0]
        taught = teacher.act(observation)
        holding = set(np.flatnonzero(observation["targets"][:, -1] > 0))
        guard.policy.act = lambda _, asked=asked: asked  # (replays the policy's action of this step)
        acted = guard.act(observation)
        for slot in range(3):
            joints = slice(4 * slot, 4 * slot + 4)
            assert np.array_equal(acted[joints], taught[joints] if slot in holding else asked[joints])
        assert acted[-1] == asked[-1]  # the wrist is the policy's
        holds += bool(holding)
    assert holds > 40


def test_the_hold_guard_needs_finger_targets_and_speed_or_angle_control():
    assert HoldGuard.fits(CONFIG) and HoldGuard.fits(EnvConfig(tactile=False, world=WorldConfig(control="position")))
    for config in (
        EnvConfig(tactile=False, world=WorldConfig(control="torque")),
        EnvConfig(tactile=False, target_onsets=False),
        EnvConfig(tactile=False, target_observations=False),
    ):
        assert not HoldGuard.fits(config)
        with pytest.raises(ValueError, match="target_observations, target_onsets"):
            HoldGuard(Constant(np.zeros(13)), config)
