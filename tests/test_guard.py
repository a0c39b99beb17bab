"""The guards (pianobot/perform/guard.py). The wrist guard: a policy's wrist slides no faster than
the scripted pianist's while a fingertip is low over the keys, and nothing else of its action
changes. The hold guard: a finger that holds a note moves as the scripted pianist moves it."""

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, actuated_indices, idle_pose
from pianobot.music.instrument import HandSpec
from pianobot.music.load import LoadOptions, load_piece
from pianobot.music.piece import Note, Piece
from pianobot.music.tensor import FINGER, NOTE
from pianobot.perform.guard import QUIET_STEPS, HoldGuard, WristGuard
from pianobot.perform.perform import PLAY_CONFIG, perform
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.pianist.tuning import PianistTuning
from pianobot.sim.hand import finger_ik, hand_config
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
    (
        Note(0.0, 60, 1.0, 80, 2),
        Note(1.0, 62, 2.0, 80, 2),  # the same finger again: it must let C4 go in time to strike D4
        Note(2.0, 64, 3.0, 80, 3),
        Note(2.5, 67, 3.0, 80, 4),  # struck while E4 is held
    ),
    bpm=60,
)


def joints_of(config: EnvConfig, slot: int) -> np.ndarray:
    """Where finger ``slot``'s actuated joints are in the action."""
    return np.flatnonzero(actuated_indices(config)[:-1] // 4 == slot)


class LetsGo:
    """The scripted pianist, but a finger that holds a note lifts at once (a policy that lets go
    early); it records every step's observation."""

    def __init__(self, config, lift: float = 1.0):
        self.inner = ScriptedPianist(config)
        self.config = config
        self.lift = lift
        """How fast a holding finger lifts (a share of the joints' top speed)."""
        self.observations: list[dict] = []

    def reset(self):
        self.inner.reset()

    def act(self, observation):
        action = np.array(self.inner.act(observation), dtype=np.float32)
        for slot in np.flatnonzero(observation["targets"][:, -1] > 0):
            action[joints_of(self.config, slot)[1]] = -self.lift  # the MCP joint up (at full speed, by default)
        self.observations.append(observation)
        return action


def _notes(rollout):
    return [(n.pitch, n.onset, n.offset) for n in rollout.played.notes]


def test_through_the_hold_guard_a_policy_that_lets_go_plays_as_its_teacher():
    """Alone the policy taps its notes for two control steps (and misses the same finger's next
    one); through the hold guard the holding fingers are the teacher's, and the performance is the
    scripted pianist's own, note for note: C4 let go in time for the same finger's D4, E4 held
    while G4 is struck."""
    made = []

    def guarded(env):
        made.append(HoldGuard(LetsGo(env.config), env.config))
        return made[-1]

    alone = perform(LEGATO, lambda env: LetsGo(env.config), PLAY_CONFIG)
    assert max(n.offset - n.onset for n in alone.played.notes) < 0.1
    teacher = perform(LEGATO, "scripted", PLAY_CONFIG)
    held = perform(LEGATO, guarded, PLAY_CONFIG)
    assert held.report().f1 == 1.0 and _notes(held) == _notes(teacher)
    assert min(n.offset - n.onset for n in held.played.notes) > 0.45 and made[0].held > 40


@pytest.mark.parametrize("actuated", [None, ("mcp", "pip")])
def test_the_hold_guard_changes_only_the_holding_fingers_joints(actuated):
    """On every step the guard's action is the policy's but for the actuated joints of the fingers
    that hold a note, and the wrist while they hold and no note starts within QUIET_STEPS: those are
    what the scripted pianist that played every step itself would do, told the keys let up as the
    guard's teacher is told them."""
    config = PLAY_CONFIG if actuated is None else replace(PLAY_CONFIG, actuated=actuated)
    recorder = LetsGo(config)
    perform(LEGATO, lambda env: recorder, config)
    asked = np.linspace(-0.9, 0.9, len(actuated_indices(config))).astype(np.float32)
    guard, teacher = HoldGuard(Constant(asked), config), ScriptedPianist(config)
    act, told = guard.teacher.act, []
    guard.teacher.act = lambda observation: told.append(guard.teacher.released) or act(observation)
    holds, quiet, busy = 0, 0, 0
    for observation in recorder.observations:
        guarded = guard.act(observation)
        if np.any(observation["targets"][:, -1] > 0):
            teacher.released = told[-1]
        taught = teacher.act(observation)  # (it sees every step: it knows which notes began earlier)
        holding = np.flatnonzero(observation["targets"][:, -1] > 0)
        expected = asked.copy()
        for slot in holding:
            expected[joints_of(config, slot)] = taught[joints_of(config, slot)]
        rows_to_next = [
            round((1 - t[3]) * len(observation["score"])) for t in observation["targets"] if t[3] > 0
        ]  # control steps until each finger's next note starts
        if holding.size and min(rows_to_next, default=len(observation["score"])) > QUIET_STEPS:
            expected[-1] = taught[-1]
            quiet += 1
        elif holding.size:
            busy += 1
        assert np.array_equal(guarded, expected)
        holds += len(holding)
    assert holds == guard.held > 40
    assert quiet == guard.wrist > 10 and busy > 5  # (E4 held after G4 is struck; C4 and E4 before a strike)


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


PIANIST = replace(
    PLAY_CONFIG, world=replace(PLAY_CONFIG.world, hand=hand_config(HandSpec((1, 2, 3, 4, 5), model="pianist")))
)


def _told(config: EnvConfig, lift: float = 1.0, piece: Piece = LEGATO) -> tuple[list[frozenset], list[dict]]:
    """What the hold guard's teacher is told it let go, each step it is asked, with a policy that lifts
    every holding finger at ``lift`` of its top speed; and that policy's observations."""
    recorder = LetsGo(config, lift)
    perform(piece, lambda env: recorder, config)
    guard = HoldGuard(Constant(np.zeros(len(actuated_indices(config)), np.float32)), config)
    act, told = guard.teacher.act, []
    guard.teacher.act = lambda observation: told.append(guard.teacher.released) or act(observation)
    for observation in recorder.observations:
        guard.act(observation)
    return told, recorder.observations


def test_the_pianist_s_hold_guard_leaves_up_a_held_key_its_finger_let_up_until_the_note_ends():
    """A held key whose fingertip has risen let_up_height (8 mm) over it has sounded its end: the
    teacher is told it was let go (pressing it again would sound it twice), and stays told until that
    note ends; a fingertip that rose less is not (remembering every key let go even for a step kept
    keys up that the policy's wrist had drawn out of reach only briefly: per-step F1 0.869 -> 0.809
    on the validation duets)."""
    # G4 held past E4, then struck again: in the step it is struck again no note is held
    repeated = Piece(LEGATO.notes[:3] + (Note(2.5, 67, 3.25, 80, 4), Note(3.25, 67, 3.75, 80, 4)), bpm=60)
    told, observations = _told(PIANIST, lift=0.1, piece=repeated)  # (slowly: its tips pass through 0-8 mm)
    teacher = ScriptedPianist(PIANIST)  # (its geometry, to tell where each fingertip is)
    assert teacher.tuning.let_up_height == 0.008
    fingers = PIANIST.world.hand.spec.fingers
    expected, seen, before, low_holds = [], set(), {}, 0
    for observation in observations:
        row, joints = observation["score"][0], observation["joints"].reshape(len(fingers), -1)
        holding = {}
        for slot in np.flatnonzero(observation["targets"][:, -1] > 0):
            keys = np.flatnonzero((row[:, NOTE] > 0.5) & (row[:, FINGER + slot] > 0.5))
            holding[slot] = int(keys[-1])
        if not holding:  # (no note held: every let-up note has ended)
            seen, before = set(), {}
            continue
        seen = {(slot, key) for slot, key in seen if holding.get(slot) == key}
        for slot, key in holding.items():
            height = teacher.motion.tip(joints[slot]).height - teacher.layout.key_top[key]
            if before.get(slot) == key and height > 0.008:
                seen.add((slot, key))
            low_holds += 0 < height <= 0.008
        before = holding
        expected.append(frozenset((fingers[slot], key) for slot, key in seen))
    assert told == expected
    assert any(told) and low_holds > 0  # (both kinds happen here)
    assert not told[0]  # (nothing is let up before a finger held its key)


def test_the_allegro_hand_s_hold_guard_remembers_no_note_it_let_go():
    """The scripted pianist remembers the notes it let go before their end (it does not press them
    again); the Allegro-like hand's guard's teacher never does (its figures stay as they were), though
    its fingers here rise far over their keys and its calls do let notes go (C4 for the same finger's D4)."""
    told, _ = _told(PLAY_CONFIG)
    assert told and not any(told)
    assert ScriptedPianist(PLAY_CONFIG).tuning.let_up_height == math.inf


def test_the_pianist_s_hold_guard_lets_go_before_a_repeat_as_the_packaged_policy_s_teacher_did():
    """Alone, the pianist's scripted pianist strikes a key again from just over where it let its
    note go (``repeat_rise``), so it holds the note before nearer its end, and holds keys a step longer
    before a lone strike that needs the wrist elsewhere (``lone_strike_wrist_steps``); the hold guard's
    teacher lets go as the teacher the packaged policy learnt from did, since the policy strikes those
    notes: with ``repeat_rise`` it played the corpus's validation excerpts at 0.845 against 0.868, with
    ``lone_strike_wrist_steps`` 0.879 against 0.885. It also holds keys at full depth to their notes'
    ends (``end_rise`` off), as that teacher did (docs/history.md)."""
    import math

    alone = ScriptedPianist(PIANIST).tuning
    assert alone.repeat_rise < math.inf and alone.lone_strike_wrist_steps == 1 and alone.end_rise < math.inf
    guard = HoldGuard(Constant(np.zeros(len(actuated_indices(PIANIST)), np.float32)), PIANIST)
    taught = guard.teacher.tuning
    assert taught.repeat_rise == math.inf and taught.lone_strike_wrist_steps == 0 and taught.end_rise == math.inf
    assert replace(taught, repeat_rise=0.0) == replace(
        alone, repeat_rise=0.0, lone_strike_wrist_steps=0, end_rise=math.inf
    )
