"""Position control (issue 20 item 5): actions are joint angle targets, -1 and 1 at the joints' limits."""

from dataclasses import replace

import numpy as np
import pytest

from pianobot.env.piano import EnvConfig, PianoEnv, idle_pose
from pianobot.music.tasks import make_task
from pianobot.perform.perform import perform
from pianobot.pianist.scripted import ScriptedPianist
from pianobot.sim.hand import joint_limits
from pianobot.sim.world import WorldConfig

POSITION = EnvConfig(tactile=False, world=WorldConfig(control="position"))


def _normalised(angles: np.ndarray, config: WorldConfig) -> np.ndarray:
    low, high = joint_limits(config.hand)
    return (angles - low) / (high - low) * 2.0 - 1.0


def test_a_joint_reaches_its_target_within_one_control_step_and_stays():
    env = PianoEnv(piece=make_task("one-note", np.random.default_rng(0)), config=POSITION)
    env.reset(seed=0)
    start = np.tile(idle_pose(POSITION.world), env.n_fingers)
    target = start.copy()
    target[0::4] += 0.15  # every finger's abduction, away from the keys' surfaces
    action = np.append(_normalised(target, POSITION.world), 0.0)
    for _ in range(3):
        env.step(action)
        q = env.world.hand_state()[2]
        assert np.allclose(q[0::4], target[0::4], atol=0.01)  # reached in the first step, and held
    env.close()


def test_frozen_joints_keep_their_starting_angles():
    config = replace(POSITION, actuated=("mcp", "pip"))
    env = PianoEnv(piece=make_task("one-note", np.random.default_rng(0)), config=config)
    env.reset(seed=0)
    start = np.tile(idle_pose(config.world), env.n_fingers)
    for _ in range(5):
        env.step(np.zeros(env.action_space.shape))  # mid-range targets for MCP and PIP only
    q = env.world.hand_state()[2]
    frozen = [i for i in range(len(q)) if i % 4 in (0, 3)]  # abduction and DIP
    assert np.allclose(q[frozen], start[frozen], atol=0.02)
    env.close()


@pytest.mark.parametrize("task", ["three-note", "chord"])
def test_the_scripted_pianist_plays_in_position_control(task):
    piece = make_task(task, np.random.default_rng(3))
    report = perform(piece, "scripted", config=POSITION, seed=1).report()
    assert report.f1 >= 0.95 and report.velocity_mae <= 10


def test_torque_control_has_no_scripted_pianist():
    with pytest.raises(ValueError, match="velocity' or 'position'"):
        ScriptedPianist(EnvConfig(tactile=False, world=WorldConfig(control="torque")))


def test_the_teacher_explores_in_position_control_but_not_in_torque_control():
    from pianobot.learn.config import TrainConfig

    TrainConfig(explore="scripted", env=POSITION)  # accepted
    torque = replace(POSITION, world=WorldConfig(control="torque"))
    with pytest.raises(ValueError, match="velocity or position control"):
        TrainConfig(explore="scripted", env=torque)
